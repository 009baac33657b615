#include "import_store.hpp"

#include <openssl/evp.h>
#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "chart_tiers.hpp"
#include "course_from_positions.hpp"
#include "detect.hpp"
#include "sample_fields.hpp"
#include "sqlite_stmt.hpp"

namespace telltale::shore::import {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS imports (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  boat_id TEXT NOT NULL,
  format TEXT NOT NULL DEFAULT '',
  device TEXT NOT NULL DEFAULT '',
  file_name TEXT NOT NULL,
  sha256 TEXT NOT NULL DEFAULT '',
  bytes INTEGER NOT NULL DEFAULT 0,
  state TEXT NOT NULL,
  points INTEGER NOT NULL DEFAULT 0,
  samples_added INTEGER NOT NULL DEFAULT 0,
  fixes_added INTEGER NOT NULL DEFAULT 0,
  wind_added INTEGER NOT NULL DEFAULT 0,
  events INTEGER NOT NULL DEFAULT 0,
  skipped INTEGER NOT NULL DEFAULT 0,
  start_ns INTEGER NOT NULL DEFAULT 0,
  end_ns INTEGER NOT NULL DEFAULT 0,
  error TEXT NOT NULL DEFAULT '',
  partial TEXT NOT NULL DEFAULT '',
  duplicate_of INTEGER NOT NULL DEFAULT 0,
  created_ns INTEGER NOT NULL
);
CREATE INDEX IF NOT EXISTS imports_by_content ON imports (sha256, boat_id);
CREATE TABLE IF NOT EXISTS import_sessions (
  import_id INTEGER NOT NULL,
  session_id INTEGER NOT NULL,
  PRIMARY KEY (import_id, session_id)
) WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS import_sessions_by_session ON import_sessions (session_id);
CREATE TABLE IF NOT EXISTS import_events (
  import_id INTEGER NOT NULL,
  boat_id TEXT NOT NULL,
  t_utc_ns INTEGER NOT NULL,
  kind TEXT NOT NULL,
  detail TEXT NOT NULL
);
)sql";

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// Thrown inside the transaction to roll it back with the parser's message.
struct ParseFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Writes the parser's points and events into the open transaction.
class StoreSink : public ImportSink {
 public:
  StoreSink(sqlite3* db, std::int64_t import_id, const std::string& boat_id, std::uint64_t gap_ns,
            std::istream& in, const std::function<void(std::uint64_t)>& progress)
      : db_(db),
        import_id_(import_id),
        boat_(boat_id),
        gap_ns_(gap_ns),
        in_(in),
        progress_(progress),
        attitude_(db,
                  "INSERT OR IGNORE INTO attitude (boat_id, t_utc_ns, seq, heel_deg, pitch_deg, "
                  "heading_deg, boot_id) VALUES (?1, ?2, 0, ?3, ?4, ?5, 0)"),
        fix_(db,
             "INSERT OR IGNORE INTO fixes (boat_id, t_utc_ns, seq, gnss_utc_ns, lat_deg, lon_deg, "
             "sog_m_s, cog_deg, fix, satellites, hdop, boot_id) "
             "VALUES (?1, ?2, 0, ?2, ?3, ?4, ?5, ?6, '3d', 0, NULL, 0)"),
        wind_(db, insert_sql("wind", kWindFields).c_str()),
        event_(db,
               "INSERT INTO import_events (import_id, boat_id, t_utc_ns, kind, detail) "
               "VALUES (?1, ?2, ?3, ?4, ?5)") {
    attitude_.bind(1, boat_);
    fix_.bind(1, boat_);
    wind_.bind(1, boat_);
    event_.bind(1, import_id_).bind(2, boat_);
  }

  void point(const ImportPoint& p) override {
    std::uint64_t added = 0;
    if (std::isfinite(p.heel_deg) && std::isfinite(p.pitch_deg)) {
      attitude_.bind_u(2, p.t_utc_ns).bind(3, p.heel_deg).bind(4, p.pitch_deg).bind(5, p.heading_deg);
      added = static_cast<std::uint64_t>(attitude_.run());
      samples_added += added;
      if (added != 0) {
        tiers_.add(boat_, p.t_utc_ns, p.heel_deg, p.pitch_deg, p.heading_deg);
        // Bounded memory for a file of any length: merging early gives the same tiers.
        if (tiers_.buckets() >= kTierFoldBuckets) tiers_.write(db_);
      }
    }
    if (std::isfinite(p.lat_deg) && std::isfinite(p.lon_deg)) {
      fix_.bind_u(2, p.t_utc_ns).bind(3, p.lat_deg).bind(4, p.lon_deg).bind(5, p.sog_m_s).bind(6, p.cog_deg);
      fixes_added += static_cast<std::uint64_t>(fix_.run());
    }
    extend(p.t_utc_ns, added);
    if (++points_ % 4096 == 0 && progress_) progress_(static_cast<std::uint64_t>(in_.tellg()));
  }
  void wind(const ImportWind& w) override {
    WindSample row;
    row.from_deg = w.from_deg;
    row.speed_m_s = w.speed_m_s;
    row.source = w.source;
    wind_.bind_u(2, w.t_utc_ns);
    bind_fields(wind_.get(), 3, kWindFields, row);
    wind_added += static_cast<std::uint64_t>(wind_.run());
  }
  void event(const ImportEvent& e) override {
    event_.bind_u(3, e.t_utc_ns).bind(4, e.kind).bind(5, e.detail);
    event_.run();
  }
  void device(std::string_view d) override { device_name = std::string(d.substr(0, 200)); }

  /// Writes the last chart tier buckets, then joins each span of the file to the boat's sessions
  /// and links them to the import.
  std::vector<std::int64_t> sessions() {
    tiers_.write(db_);
    std::vector<std::int64_t> out;
    const std::uint64_t received = now_ns();
    for (const Span& sp : spans_) {
      Stmt q(db_,
            "SELECT id, start_ns, end_ns, samples FROM sessions WHERE boat_id = ?1 AND "
            "start_ns <= ?3 + ?4 AND end_ns + ?4 >= ?2 ORDER BY id");
      q.bind(1, boat_).bind_u(2, sp.start).bind_u(3, sp.end).bind_u(4, gap_ns_);
      std::int64_t keep = 0;
      std::uint64_t start = sp.start, end = sp.end;
      std::int64_t samples = static_cast<std::int64_t>(sp.added);
      std::vector<std::int64_t> gone;
      while (q.step()) {
        if (keep == 0) {
          keep = q.i64(0);
        } else {
          gone.push_back(q.i64(0));
        }
        start = std::min(start, q.u64(1));
        end = std::max(end, q.u64(2));
        samples += q.i64(3);
      }
      if (keep == 0) {
        Stmt ins(db_,
                "INSERT INTO sessions (boat_id, start_ns, end_ns, samples, received_ns) "
                "VALUES (?1, ?2, ?3, ?4, ?5)");
        ins.bind(1, boat_).bind_u(2, start).bind_u(3, end).bind(4, samples).bind_u(5, received);
        ins.run();
        keep = sqlite3_last_insert_rowid(db_);
      } else {
        Stmt up(db_,
               "UPDATE sessions SET start_ns = ?2, end_ns = ?3, samples = ?4, "
               "received_ns = MAX(received_ns, ?5) WHERE id = ?1");
        up.bind(1, keep).bind_u(2, start).bind_u(3, end).bind(4, samples).bind_u(5, received);
        up.run();
        for (std::int64_t g : gone) {
          // Sessions this span bridged: one session now; earlier imports follow it.
          Stmt move(db_, "UPDATE OR IGNORE import_sessions SET session_id = ?2 WHERE session_id = ?1");
          move.bind(1, g).bind(2, keep);
          move.run();
          Stmt drop_links(db_, "DELETE FROM import_sessions WHERE session_id = ?1");
          drop_links.bind(1, g);
          drop_links.run();
          Stmt drop(db_, "DELETE FROM sessions WHERE id = ?1");
          drop.bind(1, g);
          drop.run();
          std::erase(out, g);
        }
      }
      Stmt link(db_, "INSERT OR IGNORE INTO import_sessions (import_id, session_id) VALUES (?1, ?2)");
      link.bind(1, import_id_).bind(2, keep);
      link.run();
      if (std::find(out.begin(), out.end(), keep) == out.end()) out.push_back(keep);
    }
    return out;
  }

  std::uint64_t samples_added = 0, fixes_added = 0, wind_added = 0;
  std::uint64_t start_ns = 0, end_ns = 0;
  std::string device_name;

 private:
  struct Span {
    std::uint64_t start, end, added;
  };
  void extend(std::uint64_t t, std::uint64_t added) {
    start_ns = start_ns == 0 ? t : std::min(start_ns, t);
    end_ns = std::max(end_ns, t);
    if (!spans_.empty()) {
      Span& s = spans_.back();
      if (t + gap_ns_ >= s.start && t <= s.end + gap_ns_) {
        s.start = std::min(s.start, t);
        s.end = std::max(s.end, t);
        s.added += added;
        return;
      }
    }
    // A pause longer than the gap (or a jump back in time): a new span. Spans are few (one per
    // pause), and the session step joins any that overlap.
    spans_.push_back({t, t, added});
  }

  sqlite3* db_;
  std::int64_t import_id_;
  std::string boat_;
  std::uint64_t gap_ns_;
  std::istream& in_;
  const std::function<void(std::uint64_t)>& progress_;
  Stmt attitude_, fix_, wind_, event_;
  std::uint64_t points_ = 0;
  std::vector<Span> spans_;
  /// Folded buckets merged early: 4096 is ~68 minutes of data at any sample rate (3840 one-second
  /// buckets and 240 sixteen-second ones); at ~250 B per map node, ~1 MB (an estimate).
  static constexpr std::size_t kTierFoldBuckets = 4096;
  TierFold tiers_;
};

}  // namespace

std::string sha256_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  if (!ctx || EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(ctx);
    throw std::runtime_error("SHA-256 unavailable");
  }
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (in.gcount() > 0) EVP_DigestUpdate(ctx, buf.data(), static_cast<std::size_t>(in.gcount()));
  }
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  EVP_DigestFinal_ex(ctx, md, &n);
  EVP_MD_CTX_free(ctx);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned i = 0; i < n; ++i) {
    out.push_back(kHex[md[i] >> 4]);
    out.push_back(kHex[md[i] & 15]);
  }
  return out;
}

ImportStore::ImportStore(Store& store) : store_(store) {
  store_.write_transaction([](sqlite3* db) {
    exec(db, kSchema);
    // A database from before imports stored wind: the count's column, added as kSchema has it.
    Stmt has(db, "SELECT COUNT(*) FROM pragma_table_info('imports') WHERE name = 'wind_added'");
    if (has.step() && has.i64(0) == 0)
      exec(db, "ALTER TABLE imports ADD COLUMN wind_added INTEGER NOT NULL DEFAULT 0");
  });
}

std::int64_t ImportStore::begin(const std::string& boat_id, const std::string& file_name,
                                std::uint64_t bytes) {
  std::int64_t id = 0;
  store_.write_transaction([&](sqlite3* db) {
    Stmt ins(db,
            "INSERT INTO imports (boat_id, file_name, bytes, state, created_ns) "
            "VALUES (?1, ?2, ?3, 'running', ?4)");
    ins.bind(1, boat_id).bind(2, file_name).bind_u(3, bytes).bind_u(4, now_ns());
    ins.run();
    id = sqlite3_last_insert_rowid(db);
  });
  return id;
}

void ImportStore::fail_unfinished() {
  store_.write_transaction([](sqlite3* db) {
    exec(db,
         "UPDATE imports SET state = 'failed', error = 'the shore stopped before the import "
         "finished: nothing of it was stored; upload the file again' WHERE state = 'running'");
  });
}

void ImportStore::finish(const ImportRecord& r) {
  store_.write_transaction([&](sqlite3* db) {
    Stmt up(db,
            "UPDATE imports SET format = ?2, device = ?3, sha256 = ?4, state = ?5, points = ?6, "
            "samples_added = ?7, fixes_added = ?8, events = ?9, skipped = ?10, start_ns = ?11, "
            "end_ns = ?12, error = ?13, partial = ?14, duplicate_of = ?15, wind_added = ?16 "
            "WHERE id = ?1");
    up.bind(1, r.id).bind(2, r.format).bind(3, r.device).bind(4, r.sha256).bind(5, r.state).bind_u(6, r.points);
    up.bind_u(7, r.samples_added).bind_u(8, r.fixes_added).bind_u(9, r.events).bind_u(10, r.skipped);
    up.bind_u(11, r.start_ns).bind_u(12, r.end_ns).bind(13, r.error).bind(14, r.partial).bind(15, r.duplicate_of);
    up.bind_u(16, r.wind_added);
    up.run();
  });
}

ImportRecord ImportStore::run(std::int64_t id, const ImportRequest& req,
                              const std::function<void(std::uint64_t)>& progress) {
  ImportRecord r;
  r.id = id;
  r.boat_id = req.boat_id;
  r.file_name = req.file_name;
  try {
    r.sha256 = sha256_file(req.path);
    std::ifstream in(req.path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read the uploaded file");
    in.seekg(0, std::ios::end);
    r.bytes = static_cast<std::uint64_t>(in.tellg());
    in.seekg(0);
    std::optional<Format> format = req.format;
    if (!format) {
      std::string head(kDetectBytes, '\0');
      in.read(head.data(), static_cast<std::streamsize>(head.size()));
      head.resize(static_cast<std::size_t>(in.gcount()));
      in.clear();
      in.seekg(0);
      format = detect_format(head);
      if (!format)
        throw ParseFailure(
            "the file is none of the formats Telltale reads (vakaros_csv, vkx, vtk, nmea, gpx); "
            "give format= if it is one of them");
    }
    r.format = format_name(*format);
    const auto gap_ns = static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(store_.session_gap()).count());
    store_.write_transaction([&](sqlite3* db) {
      // The same content for the same boat: nothing to do (checked in the transaction, so two
      // uploads of one file at once store it once).
      Stmt dup(db,
              "SELECT id FROM imports WHERE sha256 = ?1 AND boat_id = ?2 AND state = 'done' AND "
              "duplicate_of = 0 AND id <> ?3 ORDER BY id LIMIT 1");
      dup.bind(1, r.sha256).bind(2, r.boat_id).bind(3, id);
      if (dup.step()) {
        r.duplicate_of = dup.i64(0);
        Stmt same(db, "SELECT points, device, partial, start_ns, end_ns FROM imports WHERE id = ?1");
        same.bind(1, r.duplicate_of);
        if (same.step()) {
          r.points = same.u64(0);
          r.device = same.text(1);
          r.partial = same.text(2);
          r.start_ns = same.u64(3);
          r.end_ns = same.u64(4);
        }
        Stmt links(db,
                  "INSERT OR IGNORE INTO import_sessions (import_id, session_id) SELECT ?1, "
                  "session_id FROM import_sessions WHERE import_id = ?2");
        links.bind(1, id).bind(2, r.duplicate_of);
        links.run();
        return;
      }
      StoreSink sink(db, id, r.boat_id, gap_ns, in, progress);
      // Positions without speed and course (a watch's GPX) get both from the positions.
      CourseFromPositions derived(sink);
      const ParseResult pr = parse_log(*format, in, req.options, derived);
      if (pr.status != ParseStatus::kError) derived.finish();
      if (pr.status == ParseStatus::kError) throw ParseFailure(pr.message);
      if (pr.status == ParseStatus::kPartial) r.partial = pr.message;
      r.points = pr.points;
      r.events = pr.events;
      r.skipped = pr.skipped;
      r.samples_added = sink.samples_added;
      r.fixes_added = sink.fixes_added;
      r.wind_added = sink.wind_added;
      r.start_ns = sink.start_ns;
      r.end_ns = sink.end_ns;
      r.device = sink.device_name;
      r.sessions = sink.sessions();
    });
    if (r.duplicate_of != 0) {
      if (auto first = get(r.duplicate_of)) r.sessions = first->sessions;
    }
    r.state = "done";
  } catch (const ParseFailure& e) {
    r.state = "failed";
    r.error = std::string(r.format.empty() ? "" : r.format + ": ") + e.what();
  } catch (const std::exception& e) {
    r.state = "failed";
    r.error = e.what();
  }
  r.bytes_read = r.bytes;
  if (progress) progress(r.bytes);
  finish(r);
  return r;
}

std::optional<ImportRecord> ImportStore::get(std::int64_t id) {
  std::optional<ImportRecord> out;
  store_.read([&](sqlite3* db) {
    Stmt q(
        db,
        "SELECT boat_id, state, format, device, file_name, sha256, bytes, points, samples_added, "
        "fixes_added, events, skipped, start_ns, end_ns, error, partial, duplicate_of, wind_added "
        "FROM imports WHERE id = ?1");
    q.bind(1, id);
    if (!q.step()) return;
    ImportRecord r;
    r.id = id;
    r.boat_id = q.text(0);
    r.state = q.text(1);
    r.format = q.text(2);
    r.device = q.text(3);
    r.file_name = q.text(4);
    r.sha256 = q.text(5);
    r.bytes = q.u64(6);
    r.bytes_read = r.state == "running" ? 0 : r.bytes;
    r.points = q.u64(7);
    r.samples_added = q.u64(8);
    r.fixes_added = q.u64(9);
    r.events = q.u64(10);
    r.skipped = q.u64(11);
    r.start_ns = q.u64(12);
    r.end_ns = q.u64(13);
    r.error = q.text(14);
    r.partial = q.text(15);
    r.duplicate_of = q.i64(16);
    r.wind_added = q.u64(17);
    Stmt s(db, "SELECT session_id FROM import_sessions WHERE import_id = ?1 ORDER BY session_id");
    s.bind(1, id);
    while (s.step()) r.sessions.push_back(s.i64(0));
    out = std::move(r);
  });
  return out;
}

std::vector<ImportRecord> ImportStore::list(const std::optional<std::string>& boat_id,
                                            std::optional<std::int64_t> session, std::size_t limit) {
  std::vector<std::int64_t> ids;
  store_.read([&](sqlite3* db) {
    Stmt q(db,
          "SELECT id FROM imports WHERE (?1 IS NULL OR boat_id = ?1) AND (?2 IS NULL OR id IN "
          "(SELECT import_id FROM import_sessions WHERE session_id = ?2)) ORDER BY id DESC "
          "LIMIT ?3");
    if (boat_id) q.bind(1, *boat_id);
    if (session) q.bind(2, *session);
    q.bind(3, static_cast<std::int64_t>(limit));
    while (q.step()) ids.push_back(q.i64(0));
  });
  std::vector<ImportRecord> out;
  for (const std::int64_t id : ids)
    if (auto r = get(id)) out.push_back(std::move(*r));
  return out;
}

}  // namespace telltale::shore::import

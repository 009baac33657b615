#include "chart_tiers.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include "sqlite_stmt.hpp"
#include "store.hpp"

namespace telltale::shore {
namespace {

static_assert(std::tuple_size_v<decltype(kTierWidths_s)> == 2,
              "TierFold keeps one cached bucket per tier width");

constexpr std::uint64_t kSecondNs = 1000000000ULL;

/// What a tier row holds: which sample each extreme slot keeps, compared strictly.
constexpr std::array<std::pair<const char*, const char*>, 4> kExtremes = {
    {{"heel", "<"}, {"heel", ">"}, {"pitch", "<"}, {"pitch", ">"}}};

/// The ON CONFLICT clause that merges a new (partial) bucket, `excluded`, into the stored one.
/// SQLite evaluates every SET expression on the row as it was, so each CASE compares with the
/// old extreme.
std::string merge_clause() {
  std::string sql = " ON CONFLICT (boat_id, width_s, bucket) DO UPDATE SET n = n + excluded.n";
  for (std::size_t e = 0; e < kExtremes.size(); ++e) {
    const std::string p = "e" + std::to_string(e) + "_";
    const std::string wins = std::string("excluded.") + p + kExtremes[e].first + " " +
                             kExtremes[e].second + " " + p + kExtremes[e].first;
    for (const char* col : {"t", "heel", "pitch", "hdg"})
      sql += ", " + p + col + " = CASE WHEN " + wins + " THEN excluded." + p + col + " ELSE " + p +
             col + " END";
  }
  return sql;
}

bool replaces(std::size_t slot, double candidate, double kept) {
  return slot % 2 == 0 ? candidate < kept : candidate > kept;
}

}  // namespace

void create_tier_table(sqlite3* db) {
  exec(db, R"sql(
CREATE TABLE IF NOT EXISTS attitude_tier (
  boat_id TEXT NOT NULL,
  width_s INTEGER NOT NULL,
  bucket INTEGER NOT NULL,
  n INTEGER NOT NULL,
  e0_t INTEGER, e0_heel REAL, e0_pitch REAL, e0_hdg REAL,
  e1_t INTEGER, e1_heel REAL, e1_pitch REAL, e1_hdg REAL,
  e2_t INTEGER, e2_heel REAL, e2_pitch REAL, e2_hdg REAL,
  e3_t INTEGER, e3_heel REAL, e3_pitch REAL, e3_hdg REAL,
  PRIMARY KEY (boat_id, width_s, bucket)
) WITHOUT ROWID;
)sql");
}

void rebuild_tiers(sqlite3* db, const std::string& boat_id, std::uint64_t from_ns,
                   std::uint64_t to_ns) {
  const std::uint64_t widest_ns = kTierWidths_s.back() * kSecondNs;
  const std::uint64_t lo = from_ns / widest_ns * widest_ns;
  const std::uint64_t hi = std::min<std::uint64_t>(to_ns / widest_ns * widest_ns + widest_ns - 1,
                                                   std::numeric_limits<std::int64_t>::max());
  const std::string match = boat_id.empty() ? "?1 = ''" : "boat_id = ?1";
  for (const auto w : kTierWidths_s) {
    const std::string w_s = std::to_string(w);
    const std::string w_ns = std::to_string(w * kSecondNs);
    Stmt del(db, ("DELETE FROM attitude_tier WHERE " + match +
                  " AND width_s = ?2 AND bucket BETWEEN ?3 AND ?4")
                     .c_str());
    del.bind(1, boat_id)
        .bind_u(2, w)
        .bind_u(3, lo / (w * kSecondNs))
        .bind_u(4, hi / (w * kSecondNs));
    del.step();
    // Every sample as a bucket of one, merged in time order ("WHERE" ends the SELECT so that
    // SQLite does not read ON CONFLICT as part of a join).
    std::string sql =
        "INSERT INTO attitude_tier SELECT a.boat_id, " + w_s + ", a.t_utc_ns / " + w_ns + ", 1";
    for (std::size_t e = 0; e < kExtremes.size(); ++e)
      sql += ", a.t_utc_ns, a.heel_deg, a.pitch_deg, a.heading_deg";
    sql += " FROM attitude a WHERE (" + match + ") AND a.t_utc_ns BETWEEN ?2 AND ?3 " +
           "ORDER BY a.boat_id, a.t_utc_ns" + merge_clause();
    Stmt add(db, sql.c_str());
    add.bind(1, boat_id).bind_u(2, lo).bind_u(3, hi);
    add.step();
  }
}

void TierFold::add(const std::string& boat_id, std::uint64_t t_utc_ns, double heel_deg,
                   double pitch_deg, double heading_deg) {
  const Extreme x{t_utc_ns, heel_deg, pitch_deg, heading_deg};
  for (std::size_t i = 0; i < kTierWidths_s.size(); ++i) {
    const std::uint64_t w = kTierWidths_s[i];
    const std::uint64_t bucket = t_utc_ns / (w * kSecondNs);
    auto it = last_[i];
    if (it == open_.end() || std::get<2>(it->first) != bucket ||
        std::get<0>(it->first) != boat_id) {
      it = open_.try_emplace(Key{boat_id, w, bucket}).first;
      last_[i] = it;
    }
    Bucket& b = it->second;
    if (b.n++ == 0) {
      b.e.fill(x);
      continue;
    }
    for (std::size_t s = 0; s < b.e.size(); ++s) {
      const bool by_heel = s < 2;
      if (replaces(s, by_heel ? heel_deg : pitch_deg, by_heel ? b.e[s].heel_deg : b.e[s].pitch_deg))
        b.e[s] = x;
    }
  }
}

void TierFold::write(sqlite3* db) {
  if (open_.empty()) return;
  std::string sql = "INSERT INTO attitude_tier VALUES (?1, ?2, ?3, ?4";
  for (int p = 5; p <= 20; ++p) sql += ", ?" + std::to_string(p);
  Stmt up(db, (sql + ")" + merge_clause()).c_str());
  for (const auto& [key, b] : open_) {
    up.bind(1, std::get<0>(key)).bind_u(2, std::get<1>(key)).bind_u(3, std::get<2>(key));
    up.bind(4, b.n);
    for (std::size_t s = 0; s < b.e.size(); ++s) {
      const int c = 5 + 4 * static_cast<int>(s);
      up.bind_u(c, b.e[s].t_utc_ns)
          .bind(c + 1, b.e[s].heel_deg)
          .bind(c + 2, b.e[s].pitch_deg)
          .bind(c + 3, b.e[s].heading_deg);
    }
    up.run();
  }
  clear();
}

void TierFold::clear() {
  open_.clear();
  last_.fill(open_.end());
}

}  // namespace telltale::shore

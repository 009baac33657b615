#include "session_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <concepts>
#include <cstring>
#include <map>
#include <stdexcept>

namespace telltale::boat {
namespace {

std::uint32_t crc32(const unsigned char* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

template <class T>
void put(unsigned char*& p, T v) {
  std::memcpy(p, &v, sizeof v);  // the boards this runs on are little-endian (x86-64, ARM)
  p += sizeof v;
}
template <class T>
T get(const unsigned char*& p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  p += sizeof v;
  return v;
}

std::string file_prefix(const std::string& boat_id, std::uint64_t boot_id) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(boot_id));
  return boat_id + "-" + hex + "-";
}

/// The kinds' file suffixes: the disk budget covers them all.
constexpr const char* kLogSuffixes[] = {AttitudeCodec::kSuffix, FixCodec::kSuffix};

bool is_log_file(const std::filesystem::path& p) {
  const auto ext = p.extension();
  for (const char* s : kLogSuffixes)
    if (ext == s) return true;
  return false;
}

/// `<boat>-<16 hex>-<12 digits><suffix>` of this boat: its boot id, or nothing (another boat
/// whose id starts with this one's has a '-' where the hex digits are).
std::optional<std::uint64_t> boot_of(const std::string& name, const std::string& boat_id,
                                     const std::string& suffix) {
  const std::size_t tail = 1 + 16 + 1 + 12 + suffix.size();
  if (name.size() != boat_id.size() + tail || name.rfind(boat_id + "-", 0) != 0 ||
      !name.ends_with(suffix) || name[boat_id.size() + 17] != '-')
    return std::nullopt;
  const std::string hex = name.substr(boat_id.size() + 1, 16);
  if (hex.find_first_not_of("0123456789abcdef") != std::string::npos) return std::nullopt;
  return std::stoull(hex, nullptr, 16);
}

std::filesystem::path delivered_marker(const std::filesystem::path& dir, const std::string& boat_id,
                                       std::uint64_t boot_id, const std::string& marker) {
  std::string prefix = file_prefix(boat_id, boot_id);
  prefix.pop_back();
  return dir / (prefix + marker);
}

/// First sequence number encoded in a log file name of the kind with `suffix`, or nothing.
std::optional<std::uint64_t> first_seq_of(const std::filesystem::path& p, const std::string& prefix,
                                          const std::string& suffix) {
  const std::string name = p.filename().string();
  if (name.rfind(prefix, 0) != 0 || p.extension() != suffix ||
      name.size() <= prefix.size() + suffix.size())
    return std::nullopt;
  try {
    return std::stoull(name.substr(prefix.size(), name.size() - prefix.size() - suffix.size()));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

template <class Codec>
void encode_frame(const typename Codec::Record& r, unsigned char* out) {
  std::memset(out, 0, kLogRecordBytes);
  Codec::encode(r, out + kLogHeaderBytes);
  unsigned char* h = out;
  put(h, Codec::kMagic);
  put(h, crc32(out + kLogHeaderBytes, kLogRecordBytes - kLogHeaderBytes));
}

template <class Codec>
std::optional<typename Codec::Record> decode_frame(const unsigned char* in) {
  const unsigned char* h = in;
  if (get<std::uint32_t>(h) != Codec::kMagic) return std::nullopt;
  if (get<std::uint32_t>(h) != crc32(in + kLogHeaderBytes, kLogRecordBytes - kLogHeaderBytes))
    return std::nullopt;
  return Codec::decode(in + kLogHeaderBytes);
}

/// Records in `bytes` with first <= seq <= last, in file order. Where the bytes at a record
/// boundary are not a valid record (torn by a crash or a full disk), it moves on byte by byte to
/// the next valid magic + CRC: nothing intact after a torn record is skipped. `clean` is set
/// false if it had to.
template <class Codec>
std::vector<typename Codec::Record> scan_records(const unsigned char* bytes, std::size_t n,
                                                 std::uint64_t first, std::uint64_t last,
                                                 bool& clean) {
  std::vector<typename Codec::Record> out;
  std::size_t pos = 0;
  while (pos + kLogRecordBytes <= n) {
    const auto r = decode_frame<Codec>(bytes + pos);
    if (!r) {
      clean = false;
      ++pos;
      continue;
    }
    if (r->seq > last) break;
    if (r->seq >= first) out.push_back(*r);
    pos += kLogRecordBytes;
  }
  return out;
}

/// The whole file (only for a damaged one: an intact file is read at its grid offsets).
std::vector<unsigned char> read_all(const std::filesystem::path& p) {
  std::vector<unsigned char> out;
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) return out;
  unsigned char buf[65536];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.insert(out.end(), buf, buf + n);
  std::fclose(f);
  return out;
}

/// True if the file is on the record grid: a whole number of records, the last of which holds
/// the seq its position says (checked by reading that one record).
template <class Codec>
bool intact(const std::filesystem::path& p, std::uint64_t first_seq, std::uint64_t size) {
  if (size % kLogRecordBytes != 0) return false;
  if (size == 0) return true;
  std::optional<typename Codec::Record> tail;
  if (std::FILE* f = std::fopen(p.c_str(), "rb")) {
    unsigned char buf[kLogRecordBytes];
    if (std::fseek(f, static_cast<long>(size - kLogRecordBytes), SEEK_SET) == 0 &&
        std::fread(buf, 1, sizeof buf, f) == sizeof buf)
      tail = decode_frame<Codec>(buf);
    std::fclose(f);
  }
  return tail && tail->seq == first_seq + size / kLogRecordBytes - 1;
}

}  // namespace

namespace {

// Each kind's body is its members in one order, written once here: encode and decode both walk
// it, so a member added to a record is one line (and a frame that grows past 96 bytes is a
// compile error, below).
template <class R, class F>
constexpr void members(R& r, F&& f) requires std::same_as<std::remove_const_t<R>, LogRecord> {
  f(r.seq);
  f(r.t_utc_ns);
  f(r.heel_deg);
  f(r.pitch_deg);
  f(r.heading_deg);
  f(r.heel_rate_deg_s);
  f(r.pitch_rate_deg_s);
  f(r.yaw_rate_deg_s);
  f(r.accel_weight);
  f(r.quality);
  for (auto& l : r.leds) f(l);
  f(r.led_count);
  f(r.level);
}

template <class R, class F>
constexpr void members(R& r, F&& f) requires std::same_as<std::remove_const_t<R>, FixRecord> {
  f(r.seq);
  f(r.t_utc_ns);
  f(r.gnss_utc_ns);
  f(r.lat_deg);
  f(r.lon_deg);
  f(r.sog_m_s);
  f(r.cog_deg);
  f(r.fix);
  f(r.satellites);
  f(r.hdop);
}

template <class Record>
constexpr std::size_t body_bytes() {
  std::size_t n = 0;
  Record r{};
  members(r, [&](const auto& v) { n += sizeof v; });
  return n;
}
static_assert(body_bytes<LogRecord>() <= kLogRecordBytes - kLogHeaderBytes,
              "a sample fits a frame");
static_assert(body_bytes<FixRecord>() <= kLogRecordBytes - kLogHeaderBytes, "a fix fits a frame");

template <class Record>
void encode_members(const Record& r, unsigned char* body) {
  members(r, [&](const auto& v) { put(body, v); });
}

template <class Record>
Record decode_members(const unsigned char* body) {
  Record r;
  members(r, [&](auto& v) { v = get<std::remove_reference_t<decltype(v)>>(body); });
  return r;
}

}  // namespace

void AttitudeCodec::encode(const Record& r, unsigned char* body) { encode_members(r, body); }
LogRecord AttitudeCodec::decode(const unsigned char* body) { return decode_members<Record>(body); }
void FixCodec::encode(const Record& r, unsigned char* body) { encode_members(r, body); }
FixRecord FixCodec::decode(const unsigned char* body) { return decode_members<Record>(body); }

void encode_record(const LogRecord& r, unsigned char* out) { encode_frame<AttitudeCodec>(r, out); }
void encode_record(const FixRecord& r, unsigned char* out) { encode_frame<FixCodec>(r, out); }
std::optional<LogRecord> decode_record(const unsigned char* in) {
  return decode_frame<AttitudeCodec>(in);
}
std::optional<FixRecord> decode_fix_record(const unsigned char* in) {
  return decode_frame<FixCodec>(in);
}

template <class Codec>
BasicSessionLog<Codec>::BasicSessionLog(SessionLogConfig config) : config_(std::move(config)) {
  std::error_code ec;
  std::filesystem::create_directories(config_.dir, ec);
  if (ec)
    throw std::runtime_error("cannot create log directory " + config_.dir.string() + ": " +
                             ec.message());
  // The directory may exist and still refuse files (a read-only mount, permissions): find out
  // now, before the node says it is ready. A full disk is not a refusal: the log holds records
  // until it has room again.
  const auto probe = config_.dir / ("." + file_prefix(config_.boat_id, config_.boot_id) + "probe-" +
                                    std::string(Codec::kSuffix).substr(1));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int err = errno;
    if (err != ENOSPC && err != EDQUOT)
      throw std::runtime_error("cannot write the session log in " + config_.dir.string() + ": " +
                               std::strerror(err));
    fail(err);
  } else {
    ::close(fd);
    ::unlink(probe.c_str());
  }
}

template <class Codec>
BasicSessionLog<Codec>::~BasicSessionLog() {
  (void)write_pending();
  if (fd_ >= 0) ::close(fd_);
}

template <class Codec>
void BasicSessionLog<Codec>::fail(int err) {
  ++write_errors_;
  last_error_ = std::strerror(err);
}

template <class Codec>
SessionLogHealth BasicSessionLog<Codec>::health() const {
  return {pending_.size() / kLogRecordBytes, dropped_, write_errors_, last_error_};
}

template <class Codec>
bool BasicSessionLog<Codec>::open_next(std::uint64_t first_seq) {
  if (fd_ >= 0) ::close(fd_);
  char seq[24];
  std::snprintf(seq, sizeof seq, "%012llu", static_cast<unsigned long long>(first_seq));
  current_ = config_.dir / (file_prefix(config_.boat_id, config_.boot_id) + seq + Codec::kSuffix);
  // A file of this name can only be an earlier attempt that holds no record (a roll lands on a
  // seq no file holds yet): start it afresh.
  fd_ = ::open(current_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  file_first_seq_ = first_seq;
  in_file_ = 0;
  if (fd_ < 0) {
    fail(errno);
    return false;
  }
  enforce_limit();
  return true;
}

template <class Codec>
bool BasicSessionLog<Codec>::append(const Record& record) {
  const std::uint64_t held = pending_.size() / kLogRecordBytes;
  if (held > 0 && record.seq != pending_first_seq_ + held) {
    // Not the next seq (the caller broke the contract): what is held cannot share a file grid
    // with it. Write it if the disk takes it, else give it up.
    if (!write_pending()) {
      dropped_ += held;
      pending_.clear();
    }
  }
  if (pending_.empty()) pending_first_seq_ = record.seq;
  const std::size_t at = pending_.size();
  pending_.resize(at + kLogRecordBytes);
  encode_frame<Codec>(record, pending_.data() + at);
  if (pending_.size() > std::max(config_.max_pending_bytes, kLogRecordBytes)) {
    // Writes have failed for long: the oldest held record goes (the file rolls past the hole).
    pending_.erase(pending_.begin(),
                   pending_.begin() + static_cast<std::ptrdiff_t>(kLogRecordBytes));
    ++pending_first_seq_;
    ++dropped_;
  }
  // Batches of about 4 KB, like the stdio buffer this replaces; while writes fail, every append
  // tries again (a cheap failed syscall at the publish rate).
  if (pending_.size() >= 4096 || !last_error_.empty()) return write_pending();
  return true;
}

template <class Codec>
bool BasicSessionLog<Codec>::flush() {
  return write_pending();
}

template <class Codec>
bool BasicSessionLog<Codec>::write_pending() {
  while (!pending_.empty()) {
    if (fd_ < 0 || in_file_ >= config_.records_per_file ||
        pending_first_seq_ != file_first_seq_ + in_file_) {
      if (!open_next(pending_first_seq_)) return false;
    }
    const std::uint64_t room = config_.records_per_file - in_file_;
    const std::size_t want =
        std::min<std::size_t>(pending_.size(), static_cast<std::size_t>(room) * kLogRecordBytes);
    const auto base = static_cast<off_t>(in_file_ * kLogRecordBytes);
    std::size_t done = 0;
    int err = 0;
    while (done < want) {
      const ssize_t n =
          ::pwrite(fd_, pending_.data() + done, want - done, base + static_cast<off_t>(done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        err = n < 0 ? errno : ENOSPC;
        break;
      }
      done += static_cast<std::size_t>(n);
    }
    // Whole records written count; a torn tail is cut off so the file stays on the grid (and the
    // next attempt writes at the grid offset anyway, over whatever is left).
    const std::size_t whole = done / kLogRecordBytes * kLogRecordBytes;
    if (whole != done) {
      const int cut = ::ftruncate(fd_, base + static_cast<off_t>(whole));
      (void)cut;  // if it fails, the next attempt writes over the torn bytes at the grid offset
    }
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(whole));
    in_file_ += whole / kLogRecordBytes;
    pending_first_seq_ += whole / kLogRecordBytes;
    if (err != 0) {
      fail(err);
      return false;
    }
  }
  last_error_.clear();
  return true;
}

template <class Codec>
void BasicSessionLog<Codec>::enforce_limit() {
  struct Entry {
    std::filesystem::path path;
    std::filesystem::file_time_type mtime;
    std::uintmax_t size;
  };
  std::vector<Entry> files;
  std::uintmax_t total = 0;
  std::error_code ec;
  // One budget over every kind. The file this run writes of each kind (its latest of that
  // suffix) is never deleted: the other kind's log has it open, and records written to a
  // deleted file are lost without an error.
  const std::string own = file_prefix(config_.boat_id, config_.boot_id);
  std::map<std::string, std::pair<std::uint64_t, std::filesystem::path>> writing;  // by suffix
  for (const auto& e : std::filesystem::directory_iterator(config_.dir, ec)) {
    if (!is_log_file(e.path())) continue;
    const auto size = e.file_size(ec);
    files.push_back({e.path(), e.last_write_time(ec), size});
    total += size;
    const std::string suffix = e.path().extension().string();
    if (const auto first = first_seq_of(e.path(), own, suffix)) {
      auto& w = writing[suffix];
      if (w.second.empty() || *first >= w.first) w = {*first, e.path()};
    }
  }
  // Room for the file just opened to fill up.
  total += config_.records_per_file * kLogRecordBytes;
  std::sort(files.begin(), files.end(),
            [](const Entry& a, const Entry& b) { return a.mtime < b.mtime; });
  for (const auto& f : files) {
    if (total <= config_.max_bytes) break;
    if (f.path == current_ || std::any_of(writing.begin(), writing.end(),
                                          [&](const auto& w) { return w.second.second == f.path; }))
      continue;
    std::filesystem::remove(f.path, ec);
    if (!ec) {
      total -= f.size;
      bytes_deleted_ += f.size;
    }
  }
}

template <class Codec>
BasicSessionLogReader<Codec>::BasicSessionLogReader(std::filesystem::path dir, std::string boat_id,
                                                    std::uint64_t boot_id)
    : dir_(std::move(dir)), prefix_(file_prefix(boat_id, boot_id)) {}

template <class Codec>
std::vector<typename Codec::Record> BasicSessionLogReader<Codec>::read(std::uint64_t first_seq,
                                                                       std::uint64_t last_seq) {
  std::vector<Record> out;
  if (first_seq > last_seq) return out;
  std::vector<std::pair<std::uint64_t, std::filesystem::path>> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec))
    if (auto s = first_seq_of(e.path(), prefix_, Codec::kSuffix)) files.emplace_back(*s, e.path());
  std::sort(files.begin(), files.end());
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::uint64_t start = files[i].first;
    const std::uint64_t next = i + 1 < files.size() ? files[i + 1].first : UINT64_MAX;
    if (next <= first_seq || start > last_seq) continue;
    const auto& path = files[i].second;
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) continue;
    std::vector<Record> got;
    bool clean = true;
    if (intact<Codec>(path, start, size)) {
      // Seq s sits at (s - start) records: read just the range.
      const std::uint64_t from = std::max(first_seq, start);
      const std::uint64_t records = size / kLogRecordBytes;
      if (from - start >= records) continue;
      const std::uint64_t to = std::min(last_seq, start + records - 1);
      std::vector<unsigned char> bytes((to - from + 1) * kLogRecordBytes);
      std::size_t n = 0;
      if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
        if (std::fseek(f, static_cast<long>((from - start) * kLogRecordBytes), SEEK_SET) == 0)
          n = std::fread(bytes.data(), 1, bytes.size(), f);
        std::fclose(f);
      }
      got = scan_records<Codec>(bytes.data(), n, first_seq, last_seq, clean);
    } else {
      // Off the grid (a torn record, lost records): scan all of it.
      const auto all = read_all(path);
      got = scan_records<Codec>(all.data(), all.size(), first_seq, last_seq, clean);
    }
    out.insert(out.end(), got.begin(), got.end());
  }
  return out;
}

template <class Codec>
std::uint64_t BasicSessionLogReader<Codec>::last_seq() const {
  std::uint64_t last = 0;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec)) {
    const auto first = first_seq_of(e.path(), prefix_, Codec::kSuffix);
    if (!first) continue;
    const auto size = e.file_size(ec);
    const auto records = size / kLogRecordBytes;
    if (ec || records == 0) continue;
    if (intact<Codec>(e.path(), *first, size)) {
      last = std::max(last, *first + records - 1);
      continue;
    }
    const auto all = read_all(e.path());
    bool clean = true;
    const auto got = scan_records<Codec>(all.data(), all.size(), 0, UINT64_MAX, clean);
    if (!got.empty()) last = std::max(last, got.back().seq);
  }
  return last;
}

template <class Codec>
std::vector<std::uint64_t> undelivered_runs(const std::filesystem::path& dir,
                                            const std::string& boat_id, std::uint64_t current_boot,
                                            std::chrono::hours max_age) {
  struct Run {
    std::filesystem::file_time_type newest =
        std::filesystem::file_time_type::min();  // not {}: file_clock's epoch is in 2174
    bool delivered = false;
    bool has_log = false;
  };
  std::map<std::uint64_t, Run> runs;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (const auto boot = boot_of(name, boat_id, Codec::kSuffix)) {
      Run& r = runs[*boot];
      r.has_log = true;
      r.newest = std::max(r.newest, e.last_write_time(ec));
    }
  }
  for (auto& [boot, r] : runs)
    r.delivered =
        std::filesystem::exists(delivered_marker(dir, boat_id, boot, Codec::kDelivered), ec);
  // Markers whose run is gone (disk policy) would pile up.
  const std::string marker = Codec::kDelivered;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!name.ends_with(marker) || name.size() != boat_id.size() + 17 + marker.size() ||
        name.rfind(boat_id + "-", 0) != 0)
      continue;
    const std::string hex = name.substr(boat_id.size() + 1, 16);
    if (hex.find_first_not_of("0123456789abcdef") != std::string::npos) continue;
    if (!runs.count(std::stoull(hex, nullptr, 16))) std::filesystem::remove(e.path(), ec);
  }
  const auto oldest = std::filesystem::file_time_type::clock::now() - max_age;
  std::vector<std::pair<std::filesystem::file_time_type, std::uint64_t>> order;
  for (const auto& [boot, r] : runs)
    if (boot != current_boot && r.has_log && !r.delivered && r.newest >= oldest)
      order.emplace_back(r.newest, boot);
  std::sort(order.begin(), order.end());
  std::vector<std::uint64_t> out;
  for (const auto& [t, boot] : order) out.push_back(boot);
  return out;
}

template <class Codec>
void mark_delivered(const std::filesystem::path& dir, const std::string& boat_id,
                    std::uint64_t boot_id) {
  if (std::FILE* f =
          std::fopen(delivered_marker(dir, boat_id, boot_id, Codec::kDelivered).c_str(), "w"))
    std::fclose(f);
}

template class BasicSessionLog<AttitudeCodec>;
template class BasicSessionLog<FixCodec>;
template class BasicSessionLogReader<AttitudeCodec>;
template class BasicSessionLogReader<FixCodec>;
template std::vector<std::uint64_t> undelivered_runs<AttitudeCodec>(const std::filesystem::path&,
                                                                    const std::string&,
                                                                    std::uint64_t,
                                                                    std::chrono::hours);
template std::vector<std::uint64_t> undelivered_runs<FixCodec>(const std::filesystem::path&,
                                                               const std::string&, std::uint64_t,
                                                               std::chrono::hours);
template void mark_delivered<AttitudeCodec>(const std::filesystem::path&, const std::string&,
                                            std::uint64_t);
template void mark_delivered<FixCodec>(const std::filesystem::path&, const std::string&,
                                       std::uint64_t);

}  // namespace telltale::boat

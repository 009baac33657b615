#include "session_log.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>

namespace telltale::boat {
namespace {

constexpr std::uint32_t kMagic = 0x544c4c54;  // "TLLT"

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

/// `<boat>-<16 hex>-<12 digits>.tlog` of this boat: its boot id, or nothing (another boat whose
/// id starts with this one's has a '-' where the hex digits are).
std::optional<std::uint64_t> boot_of(const std::string& name, const std::string& boat_id) {
  constexpr std::size_t kTail = 1 + 16 + 1 + 12 + 5;
  if (name.size() != boat_id.size() + kTail || name.rfind(boat_id + "-", 0) != 0 ||
      !name.ends_with(".tlog") || name[boat_id.size() + 17] != '-')
    return std::nullopt;
  const std::string hex = name.substr(boat_id.size() + 1, 16);
  if (hex.find_first_not_of("0123456789abcdef") != std::string::npos) return std::nullopt;
  return std::stoull(hex, nullptr, 16);
}

std::filesystem::path delivered_marker(const std::filesystem::path& dir, const std::string& boat_id,
                                       std::uint64_t boot_id) {
  std::string prefix = file_prefix(boat_id, boot_id);
  prefix.back() = '.';
  return dir / (prefix + "delivered");
}

/// First sequence number encoded in a log file name, or nothing.
std::optional<std::uint64_t> first_seq_of(const std::filesystem::path& p,
                                          const std::string& prefix) {
  const std::string name = p.filename().string();
  if (name.rfind(prefix, 0) != 0 || p.extension() != ".tlog") return std::nullopt;
  try {
    return std::stoull(name.substr(prefix.size(), name.size() - prefix.size() - 5));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

}  // namespace

void encode_record(const LogRecord& r, unsigned char* out) {
  std::memset(out, 0, kLogRecordBytes);
  unsigned char* p = out + 8;  // magic and CRC last
  put(p, r.seq);
  put(p, r.t_utc_ns);
  put(p, r.heel_deg);
  put(p, r.pitch_deg);
  put(p, r.heading_deg);
  put(p, r.heel_rate_deg_s);
  put(p, r.pitch_rate_deg_s);
  put(p, r.yaw_rate_deg_s);
  put(p, r.accel_weight);
  put(p, r.quality);
  for (auto l : r.leds) put(p, l);
  put(p, r.led_count);
  put(p, r.level);
  unsigned char* h = out;
  put(h, kMagic);
  put(h, crc32(out + 8, kLogRecordBytes - 8));
}

std::optional<LogRecord> decode_record(const unsigned char* in) {
  const unsigned char* h = in;
  if (get<std::uint32_t>(h) != kMagic) return std::nullopt;
  if (get<std::uint32_t>(h) != crc32(in + 8, kLogRecordBytes - 8)) return std::nullopt;
  LogRecord r;
  const unsigned char* p = in + 8;
  r.seq = get<std::uint64_t>(p);
  r.t_utc_ns = get<std::uint64_t>(p);
  r.heel_deg = get<double>(p);
  r.pitch_deg = get<double>(p);
  r.heading_deg = get<double>(p);
  r.heel_rate_deg_s = get<double>(p);
  r.pitch_rate_deg_s = get<double>(p);
  r.yaw_rate_deg_s = get<double>(p);
  r.accel_weight = get<float>(p);
  r.quality = get<float>(p);
  for (auto& l : r.leds) l = get<std::uint8_t>(p);
  r.led_count = get<std::uint8_t>(p);
  r.level = get<std::uint8_t>(p);
  return r;
}

SessionLog::SessionLog(SessionLogConfig config) : config_(std::move(config)) {
  std::error_code ec;
  std::filesystem::create_directories(config_.dir, ec);
  if (ec)
    throw std::runtime_error("cannot create log directory " + config_.dir.string() + ": " +
                             ec.message());
}

SessionLog::~SessionLog() {
  if (file_) std::fclose(file_);
}

void SessionLog::open_next(std::uint64_t first_seq) {
  if (file_) std::fclose(file_);
  char seq[24];
  std::snprintf(seq, sizeof seq, "%012llu", static_cast<unsigned long long>(first_seq));
  current_ = config_.dir / (file_prefix(config_.boat_id, config_.boot_id) + seq + ".tlog");
  file_ = std::fopen(current_.c_str(), "ab");
  in_file_ = 0;
  enforce_limit();
}

bool SessionLog::append(const LogRecord& record) {
  if (!file_ || in_file_ >= config_.records_per_file) open_next(record.seq);
  if (!file_) return false;
  unsigned char buf[kLogRecordBytes];
  encode_record(record, buf);
  if (std::fwrite(buf, 1, sizeof buf, file_) != sizeof buf) return false;
  ++in_file_;
  return true;
}

void SessionLog::flush() {
  if (file_) std::fflush(file_);
}

void SessionLog::enforce_limit() {
  struct Entry {
    std::filesystem::path path;
    std::filesystem::file_time_type mtime;
    std::uintmax_t size;
  };
  std::vector<Entry> files;
  std::uintmax_t total = 0;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(config_.dir, ec)) {
    if (e.path().extension() != ".tlog") continue;
    const auto size = e.file_size(ec);
    files.push_back({e.path(), e.last_write_time(ec), size});
    total += size;
  }
  // Room for the file just opened to fill up.
  total += config_.records_per_file * kLogRecordBytes;
  std::sort(files.begin(), files.end(),
            [](const Entry& a, const Entry& b) { return a.mtime < b.mtime; });
  for (const auto& f : files) {
    if (total <= config_.max_bytes) break;
    if (f.path == current_) continue;
    std::filesystem::remove(f.path, ec);
    if (!ec) {
      total -= f.size;
      bytes_deleted_ += f.size;
    }
  }
}

SessionLogReader::SessionLogReader(std::filesystem::path dir, std::string boat_id,
                                   std::uint64_t boot_id)
    : dir_(std::move(dir)), prefix_(file_prefix(boat_id, boot_id)) {}

std::vector<LogRecord> SessionLogReader::read(std::uint64_t first_seq, std::uint64_t last_seq) {
  std::vector<LogRecord> out;
  if (first_seq > last_seq) return out;
  std::vector<std::pair<std::uint64_t, std::filesystem::path>> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec))
    if (auto s = first_seq_of(e.path(), prefix_)) files.emplace_back(*s, e.path());
  std::sort(files.begin(), files.end());
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::uint64_t start = files[i].first;
    const std::uint64_t next = i + 1 < files.size() ? files[i + 1].first : UINT64_MAX;
    if (next <= first_seq || start > last_seq) continue;
    std::FILE* f = std::fopen(files[i].second.c_str(), "rb");
    if (!f) continue;
    const std::uint64_t from = std::max(first_seq, start);
    std::fseek(f, static_cast<long>((from - start) * kLogRecordBytes), SEEK_SET);
    unsigned char buf[kLogRecordBytes];
    while (std::fread(buf, 1, sizeof buf, f) == sizeof buf) {
      const auto r = decode_record(buf);
      if (!r) continue;
      if (r->seq > last_seq) break;
      if (r->seq >= first_seq) out.push_back(*r);
    }
    std::fclose(f);
  }
  return out;
}

std::uint64_t SessionLogReader::last_seq() const {
  std::uint64_t last = 0;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec)) {
    const auto first = first_seq_of(e.path(), prefix_);
    if (!first) continue;
    const auto records = e.file_size(ec) / kLogRecordBytes;
    if (!ec && records > 0) last = std::max(last, *first + records - 1);
  }
  return last;
}

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
    if (const auto boot = boot_of(name, boat_id)) {
      Run& r = runs[*boot];
      r.has_log = true;
      r.newest = std::max(r.newest, e.last_write_time(ec));
    }
  }
  for (auto& [boot, r] : runs)
    r.delivered = std::filesystem::exists(delivered_marker(dir, boat_id, boot), ec);
  // Markers whose run is gone (disk policy) would pile up.
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!name.ends_with(".delivered") || name.size() != boat_id.size() + 27 ||
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

void mark_delivered(const std::filesystem::path& dir, const std::string& boat_id,
                    std::uint64_t boot_id) {
  if (std::FILE* f = std::fopen(delivered_marker(dir, boat_id, boot_id).c_str(), "w"))
    std::fclose(f);
}

}  // namespace telltale::boat

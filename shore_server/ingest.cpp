#include "ingest.hpp"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "shutdown.hpp"

namespace telltale::shore {

namespace {

constexpr std::array<const char*, kRejectKinds> kRejectNames = {"none",  "id",   "time",
                                                                "value", "text", "reader_full"};
constexpr std::array<const char*, kTopics> kTopicNames = {
    "attitude", "backfill", "status", "wearable", "fix", "fix_backfill", "wind"};

bool finite_in(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }
/// NaN ("no value") or within [lo, hi].
bool nan_or_in(double v, double lo, double hi) { return std::isnan(v) || (v >= lo && v <= hi); }

/// The first member of every keyed type the shore reads is its string id: after the 4-byte
/// encapsulation header comes its CDR length (terminating NUL included). True when that length
/// is the length the bounded string kept plus one, i.e. nothing was cut and no NUL was inside.
bool key_string_intact(const eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                       std::size_t kept_chars) {
  if (payload == nullptr || payload->data == nullptr || payload->length < 8) return false;
  const auto* d = payload->data;
  const bool little = (d[1] & 1) != 0;  // CDR_LE 0x0001, PL_CDR_LE 0x0003
  std::uint32_t n = 0;
  for (int i = 0; i < 4; ++i) {
    const std::uint32_t byte = d[4 + (little ? 3 - i : i)];
    n = (n << 8) | byte;
  }
  return n >= 1 && n - 1 == kept_chars;
}

}  // namespace

const char* reject_name(Reject r) { return kRejectNames[static_cast<std::size_t>(r)]; }
const char* topic_name(Topic t) { return kTopicNames[static_cast<std::size_t>(t)]; }

bool valid_utf8(std::string_view text) {
  std::size_t i = 0;
  const std::size_t n = text.size();
  while (i < n) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      ++i;
      continue;
    }
    std::size_t len = 0;
    std::uint32_t cp = 0;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
      cp = c & 0x1F;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      cp = c & 0x0F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      cp = c & 0x07;
    } else {
      return false;  // continuation byte first, overlong 0xC0/0xC1, or 0xF5..0xFF
    }
    if (n - i < len) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const auto cc = static_cast<unsigned char>(text[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    if ((len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000) || cp > 0x10FFFF ||
        (cp >= 0xD800 && cp <= 0xDFFF))
      return false;
    i += len;
  }
  return true;
}

bool clean_text(std::string_view text) {
  if (!valid_utf8(text)) return false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7F) return false;
    // C1 controls U+0080..U+009F are 0xC2 0x80..0x9F in UTF-8.
    if (c == 0xC2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) <= 0x9F)
      return false;
  }
  return true;
}

bool contract_id(std::string_view id) {
  if (id.empty() || id.size() > 32) return false;
  for (char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

bool contract_time(std::uint64_t t_utc_ns, std::uint64_t shore_now_ns) {
  return t_utc_ns >= kEarliestSampleNs && t_utc_ns <= shore_now_ns + kMaxAheadNs;
}

Reject check(const AttitudeSample& s, std::uint64_t shore_now_ns) {
  if (!contract_id(s.boat_id)) return Reject::kId;
  if (!contract_time(s.t_utc_ns, shore_now_ns)) return Reject::kTime;
  // Heel and pitch are the sample: without them it is nothing to store (the schema says NOT
  // NULL), so a NaN is refused and counted here rather than dropped by SQLite and acknowledged.
  if (!finite_in(s.heel_deg, -180.0, 180.0) || !finite_in(s.pitch_deg, -90.0, 90.0) ||
      !nan_or_in(s.heading_deg, 0.0, 360.0) || !std::isfinite(s.heel_rate_deg_s) ||
      !std::isfinite(s.pitch_rate_deg_s) || !std::isfinite(s.yaw_rate_deg_s) ||
      !std::isfinite(s.accel_weight) || !std::isfinite(s.quality))
    return Reject::kValue;
  return Reject::kNone;
}

Reject check(const WearableSample& s, std::uint64_t shore_now_ns) {
  if (!contract_id(s.athlete_id)) return Reject::kId;
  if (!contract_time(s.t_utc_ns, shore_now_ns)) return Reject::kTime;
  // NaN is "no value" (no position before the first step); infinities are broken.
  for (double v : {s.cadence_spm, s.x_m, s.y_m, s.distance_m})
    if (std::isinf(v)) return Reject::kValue;
  if (!nan_or_in(s.heading_deg, 0.0, 360.0)) return Reject::kValue;
  return Reject::kNone;
}

Reject check(const FixSample& s, std::uint64_t shore_now_ns) {
  if (!contract_id(s.boat_id)) return Reject::kId;
  if (!contract_time(s.t_utc_ns, shore_now_ns)) return Reject::kTime;
  if (!known_fix_kind(s.fix)) return Reject::kValue;
  if (s.fix == "none") {
    // No fix: no position may ride along (the gate on the boat blanks it).
    for (double v : {s.lat_deg, s.lon_deg, s.sog_m_s, s.cog_deg})
      if (!std::isnan(v)) return Reject::kValue;
  } else if (!finite_in(s.lat_deg, -90.0, 90.0) || !finite_in(s.lon_deg, -180.0, 180.0)) {
    return Reject::kValue;
  }
  // 100 m/s: well above any boat; the boat's gate already rejects above 30.
  if (!nan_or_in(s.sog_m_s, 0.0, 100.0) || !nan_or_in(s.cog_deg, 0.0, 360.0)) return Reject::kValue;
  if (!nan_or_in(s.hdop, 0.0, 100.0) || s.satellites > 255) return Reject::kValue;
  if (s.gnss_utc_ns != 0 && !contract_time(s.gnss_utc_ns, shore_now_ns)) return Reject::kTime;
  return Reject::kNone;
}

Reject check(const WindSample& s, std::uint64_t shore_now_ns) {
  if (!contract_id(s.boat_id)) return Reject::kId;
  if (!contract_time(s.t_utc_ns, shore_now_ns)) return Reject::kTime;
  // 100 m/s: beyond any wind a boat sails in, as for SOG.
  if (!finite_in(s.from_deg, 0.0, 360.0) || !nan_or_in(s.speed_m_s, 0.0, 100.0))
    return Reject::kValue;
  static constexpr std::array<std::string_view, 4> kSources = {"mwd", "mwd_magnetic", "mwv_true",
                                                               "mwv_apparent"};
  if (std::find(kSources.begin(), kSources.end(), s.source) == kSources.end()) return Reject::kText;
  return Reject::kNone;
}

Reject check(const std::string& node_id, const NodeStatusInfo& s, std::uint64_t t_utc_ns,
             std::uint64_t shore_now_ns) {
  if (!contract_id(node_id)) return Reject::kId;
  if (!contract_time(t_utc_ns, shore_now_ns)) return Reject::kTime;
  if (!std::isfinite(s.uptime_s) || s.uptime_s < 0.0) return Reject::kValue;
  if (!clean_text(s.software_version) || !clean_text(s.health_text) || !clean_text(s.group))
    return Reject::kText;
  return Reject::kNone;
}

void IngestCounters::count(Topic topic, Reject reason, std::uint64_t n) {
  const auto t = static_cast<std::size_t>(topic);
  if (reason == Reject::kNone) {
    accepted_[t].fetch_add(n, std::memory_order_relaxed);
    return;
  }
  rejected_[t][static_cast<std::size_t>(reason)].fetch_add(n, std::memory_order_relaxed);
  std::lock_guard lock(last_mutex_);
  last_rejected_ = std::string(topic_name(topic)) + ": " + reject_name(reason);
}

std::uint64_t IngestCounters::accepted(Topic topic) const {
  return accepted_[static_cast<std::size_t>(topic)].load();
}

std::uint64_t IngestCounters::rejected(Topic topic, Reject reason) const {
  return rejected_[static_cast<std::size_t>(topic)][static_cast<std::size_t>(reason)].load();
}

std::uint64_t IngestCounters::rejected_total() const {
  std::uint64_t n = 0;
  for (const auto& per_topic : rejected_)
    for (const auto& c : per_topic) n += c.load();
  return n;
}

nlohmann::json IngestCounters::to_json() const {
  nlohmann::json accepted = nlohmann::json::object();
  nlohmann::json rejected = nlohmann::json::object();
  for (std::size_t t = 0; t < kTopics; ++t) {
    accepted[kTopicNames[t]] = accepted_[t].load();
    nlohmann::json per = nlohmann::json::object();
    for (std::size_t r = 1; r < kRejectKinds; ++r) per[kRejectNames[r]] = rejected_[t][r].load();
    rejected[kTopicNames[t]] = std::move(per);
  }
  nlohmann::json j = {{"accepted", std::move(accepted)},
                      {"rejected", std::move(rejected)},
                      {"rejected_total", rejected_total()}};
  std::lock_guard lock(last_mutex_);
  j["last_rejected"] =
      last_rejected_.empty() ? nlohmann::json(nullptr) : nlohmann::json(last_rejected_);
  return j;
}

Ingest::Ingest(IngestSinks sinks, std::function<std::uint64_t()> clock)
    : sinks_(std::move(sinks)), clock_(std::move(clock)) {}

std::uint64_t Ingest::now() const { return clock_ ? clock_() : utc_now_ns(); }

Reject Ingest::attitude(const msg::BoatAttitude& m, bool backfill) {
  const Topic topic = backfill ? Topic::kBackfill : Topic::kAttitude;
  const AttitudeSample s = from_wire(m);
  const Reject r = check(s, now());
  counters_.count(topic, r);
  if (r != Reject::kNone) return r;
  const auto& sink = backfill ? sinks_.on_backfill : sinks_.on_attitude;
  if (sink) sink(s);
  return r;
}

Reject Ingest::status(const msg::NodeStatus& m) {
  const std::string id = m.node_id().to_string();
  const NodeStatusInfo s = from_wire(m);
  const Reject r = check(id, s, m.t_utc_ns(), now());
  counters_.count(Topic::kStatus, r);
  if (r == Reject::kNone && sinks_.on_status) sinks_.on_status(id, s);
  return r;
}

Reject Ingest::wearable(const msg::WearableMotion& m) {
  const WearableSample w = from_wire(m);
  const Reject r = check(w, now());
  counters_.count(Topic::kWearable, r);
  if (r == Reject::kNone && sinks_.on_wearable) sinks_.on_wearable(w);
  return r;
}

Reject Ingest::fix(const msg::BoatFix& m, bool backfill) {
  const FixSample f = from_wire(m);
  const Reject r = check(f, now());
  counters_.count(backfill ? Topic::kFixBackfill : Topic::kFix, r);
  const auto& sink = backfill ? sinks_.on_fix_backfill : sinks_.on_fix;
  if (r == Reject::kNone && sink) sink(f);
  return r;
}

Reject Ingest::wind(const msg::BoatWind& m) {
  const WindSample w = from_wire(m);
  const Reject r = check(w, now());
  counters_.count(Topic::kWind, r);
  if (r == Reject::kNone && sinks_.on_wind) sinks_.on_wind(w);
  return r;
}

namespace {
/// The generated deserialize, then the key's raw length checked against what Fast DDS kept: a
/// key it cut to its bound (or that holds a NUL) is emptied, which the door refuses as an id.
/// Any Fast CDR exception is a malformed payload, not a sample.
template <class Base, class Msg, class KeyOf>
bool strict_deserialize(Base& type, eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                        void* data, KeyOf key_of) {
  try {
    if (!type.Base::deserialize(payload, data)) return false;
  } catch (...) {
    return false;
  }
  auto& key = key_of(*static_cast<Msg*>(data));
  if (!key_string_intact(payload, key.size())) key = "";
  return true;
}
}  // namespace

bool StrictBoatAttitudeType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                                         void* data) {
  return strict_deserialize<msg::BoatAttitudePubSubType, msg::BoatAttitude>(
      *this, payload, data, [](msg::BoatAttitude & m) -> auto& { return m.boat_id(); });
}

bool StrictNodeStatusType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                                       void* data) {
  return strict_deserialize<msg::NodeStatusPubSubType, msg::NodeStatus>(
      *this, payload, data, [](msg::NodeStatus & m) -> auto& { return m.node_id(); });
}

bool StrictWearableMotionType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                                           void* data) {
  return strict_deserialize<msg::WearableMotionPubSubType, msg::WearableMotion>(
      *this, payload, data, [](msg::WearableMotion & m) -> auto& { return m.athlete_id(); });
}

bool StrictBoatFixType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                                    void* data) {
  return strict_deserialize<msg::BoatFixPubSubType, msg::BoatFix>(
      *this, payload, data, [](msg::BoatFix & m) -> auto& { return m.boat_id(); });
}

bool StrictBoatWindType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                                     void* data) {
  return strict_deserialize<msg::BoatWindPubSubType, msg::BoatWind>(
      *this, payload, data, [](msg::BoatWind & m) -> auto& { return m.boat_id(); });
}

}  // namespace telltale::shore

// libFuzzer target: the shore's door (shore_server/ingest.hpp) and what lies behind it, without
// DDS. Arbitrary bytes become samples of every topic the shore reads, either as a CDR payload
// through the strict types the shore's readers use (what a hostile publisher can really send) or
// field by field (to reach the checks with near-valid samples); what the door lets through is
// stored in a real Store (SQLite). The first byte picks the topic and the form.
//
// Invariants beyond "no crash": whatever reaches a sink meets the contract (id, time window,
// values, clean text); every sample is either accepted or counted as refused; every session the
// store holds belongs to a contract id and lies in the time window.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "fuzz_support.hpp"
#include "ingest.hpp"
#include "store.hpp"

namespace {

using namespace telltale::shore;

constexpr std::uint64_t kNow = 1795300000ULL * 1000000000ULL;

Store& store() {
  static Store* s = [] {
    const auto path = std::filesystem::temp_directory_path() /
                      ("fuzz_ingest_" + std::to_string(::getpid()) + ".db");
    std::filesystem::remove(path);
    StoreConfig c{path.string()};
    c.commit_interval = std::chrono::milliseconds(50);
    return new Store(c);
  }();
  return *s;
}

Ingest& ingest() {
  static Ingest* i =
      new Ingest(IngestSinks{[](const AttitudeSample& s) {
                               FUZZ_CHECK(check(s, kNow) == Reject::kNone);
                               store().enqueue(s);
                             },
                             [](const AttitudeSample& s) {
                               FUZZ_CHECK(check(s, kNow) == Reject::kNone);
                               store().enqueue(s);
                             },
                             [](const std::string& id, const NodeStatusInfo& s) {
                               FUZZ_CHECK(contract_id(id));
                               FUZZ_CHECK(clean_text(s.health_text) && clean_text(s.group) &&
                                          clean_text(s.software_version));
                             },
                             [](const WearableSample& w) {
                               FUZZ_CHECK(check(w, kNow) == Reject::kNone);
                               store().enqueue(w);
                             },
                             [](const FixSample& f) {
                               FUZZ_CHECK(check(f, kNow) == Reject::kNone);
                               store().enqueue(f);
                             },
                             [](const FixSample& f) {
                               FUZZ_CHECK(check(f, kNow) == Reject::kNone);
                               store().enqueue(f);
                             },
                             [](const WindSample& w) {
                               FUZZ_CHECK(check(w, kNow) == Reject::kNone);
                               store().enqueue(w);
                             }},
                 [] { return kNow; });
  return *i;
}

std::string text(telltale::fuzz::Input& in) {
  const std::size_t n = in.byte() % 40;
  std::string s;
  for (std::size_t i = 0; i < n && in.size() > 0; ++i) s.push_back(static_cast<char>(in.byte()));
  return s;
}

std::uint64_t time_near(telltale::fuzz::Input& in) {
  // Half the time near the shore's clock, so accepted samples reach the store.
  const std::uint64_t raw = in.u64();
  return (raw & 1) ? kNow - (raw >> 20) : raw;
}

eprosima::fastrtps::rtps::SerializedPayload_t payload(std::string_view bytes) {
  eprosima::fastrtps::rtps::SerializedPayload_t p(static_cast<std::uint32_t>(bytes.size() + 1));
  std::copy(bytes.begin(), bytes.end(), p.data);
  p.length = static_cast<std::uint32_t>(bytes.size());
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  telltale::fuzz::Input in(data, size);
  const std::uint8_t pick = in.byte();
  const int topic = pick % 6;
  const bool as_cdr = (pick & 4) != 0;
  Ingest& door = ingest();
  const auto before = door.counters().rejected_total();
  std::uint64_t accepted_before = 0;
  for (auto t : {Topic::kAttitude, Topic::kBackfill, Topic::kStatus, Topic::kWearable, Topic::kFix,
                 Topic::kFixBackfill, Topic::kWind})
    accepted_before += door.counters().accepted(t);

  bool handed = true;
  if (topic <= 1) {
    telltale::msg::BoatAttitude m;
    if (as_cdr) {
      auto p = payload(in.rest());
      StrictBoatAttitudeType type;
      handed = type.deserialize(&p, &m);
    } else {
      m.boat_id(text(in));
      m.seq(in.u64());
      m.t_utc_ns(time_near(in));
      m.heel_deg(in.raw_double());
      m.pitch_deg(in.raw_double());
      m.heading_deg(in.raw_double());
      m.heel_rate_deg_s(in.raw_double());
      m.boot_id(in.u64());
    }
    if (handed) (void)door.attitude(m, topic == 1);
  } else if (topic == 2) {
    telltale::msg::NodeStatus m;
    if (as_cdr) {
      auto p = payload(in.rest());
      StrictNodeStatusType type;
      handed = type.deserialize(&p, &m);
    } else {
      m.node_id(text(in));
      m.t_utc_ns(time_near(in));
      m.uptime_s(in.raw_double());
      m.health_text(text(in));
      m.group(text(in));
      m.software_version(text(in));
    }
    if (handed) (void)door.status(m);
  } else if (topic == 4) {
    telltale::msg::BoatFix m;
    if (as_cdr) {
      auto p = payload(in.rest());
      StrictBoatFixType type;
      handed = type.deserialize(&p, &m);
    } else {
      m.boat_id(text(in));
      m.t_utc_ns(time_near(in));
      m.gnss_utc_ns((in.byte() & 1) ? 0 : time_near(in));
      m.lat_deg(in.raw_double());
      m.lon_deg(in.raw_double());
      m.sog_m_s(in.raw_double());
      m.cog_deg(in.raw_double());
      m.fix(static_cast<telltale::msg::FixKind>(in.byte() % 6));
      m.hdop(static_cast<float>(in.raw_double()));
    }
    if (handed) (void)door.fix(m, (pick & 8) != 0);  // live or resent from the boat's log
  } else if (topic == 5) {
    telltale::msg::BoatWind m;
    if (as_cdr) {
      auto p = payload(in.rest());
      StrictBoatWindType type;
      handed = type.deserialize(&p, &m);
    } else {
      m.boat_id(text(in));
      m.t_utc_ns(time_near(in));
      m.from_deg(in.raw_double());
      m.speed_m_s(in.raw_double());
      m.source(text(in).substr(0, 16));
    }
    if (handed) (void)door.wind(m);
  } else {
    telltale::msg::WearableMotion m;
    if (as_cdr) {
      auto p = payload(in.rest());
      StrictWearableMotionType type;
      handed = type.deserialize(&p, &m);
    } else {
      m.athlete_id(text(in));
      m.t_utc_ns(time_near(in));
      m.x_m(in.raw_double());
      m.y_m(in.raw_double());
      m.heading_deg(in.raw_double());
      m.cadence_spm(in.raw_double());
    }
    if (handed) (void)door.wearable(m);
  }
  std::uint64_t accepted_after = 0;
  for (auto t : {Topic::kAttitude, Topic::kBackfill, Topic::kStatus, Topic::kWearable, Topic::kFix,
                 Topic::kFixBackfill, Topic::kWind})
    accepted_after += door.counters().accepted(t);
  // Each sample handed to the door is counted exactly once, accepted or refused.
  if (handed)
    FUZZ_CHECK(accepted_after + door.counters().rejected_total() == accepted_before + before + 1);

  // Now and then: nothing off the contract in the recording.
  static unsigned calls = 0;
  if (++calls % 2048 == 0) {
    store().flush();
    for (const auto& s : store().sessions(std::nullopt, 0, UINT64_MAX)) {
      FUZZ_CHECK(contract_id(s.boat_id));
      FUZZ_CHECK(contract_time(s.start_ns, kNow) && contract_time(s.end_ns, kNow));
    }
  }
  return 0;
}

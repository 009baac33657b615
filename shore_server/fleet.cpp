#include "fleet.hpp"

#include <algorithm>

namespace telltale::shore {

namespace {
/// Removes the entry silent the longest.
template <class Map>
void evict_oldest(Map& m) {
  auto oldest = m.begin();
  for (auto it = m.begin(); it != m.end(); ++it)
    if (it->second.last_arrival < oldest->second.last_arrival) oldest = it;
  if (oldest != m.end()) m.erase(oldest);
}

/// A boat's view as a reader sees it at `now`: conditions that lapse with time (a fresh fix, a
/// second node under the same id) are judged now, not at the last sample.
BoatView as_seen_at(const BoatView& b, SteadyTime now) {
  BoatView v = b;
  v.fix_fresh = v.fix && now - v.fix_arrival < kFixFreshFor;
  if (v.duplicate_id && now - v.duplicate_seen > kDuplicateClearAfter) v.duplicate_id = false;
  return v;
}
}  // namespace

BoatView FleetModel::update(const AttitudeSample& sample, SteadyTime arrival,
                            std::uint64_t arrival_utc_ns) {
  std::lock_guard lock(mutex_);
  if (boats_.size() >= kMaxFleetEntries && !boats_.count(sample.boat_id)) evict_oldest(boats_);
  auto it = boats_.try_emplace(sample.boat_id).first;
  BoatView& b = it->second;
  // Clock offset: the minimum of (arrival - sample time) over a 10 s window filters out network
  // and scheduling delays, leaving the clock difference (plus the least delay, < 1 ms on a LAN).
  const double offset_ms =
      (static_cast<double>(arrival_utc_ns) - static_cast<double>(sample.t_utc_ns)) * 1e-6;
  if (b.samples_received == 0 || arrival - b.window_start > std::chrono::seconds(10)) {
    if (b.samples_received > 0) b.clock_offset_ms = b.window_min_offset_ms;
    b.window_start = arrival;
    b.window_min_offset_ms = offset_ms;
    if (b.samples_received == 0) b.clock_offset_ms = offset_ms;
  } else {
    b.window_min_offset_ms = std::min(b.window_min_offset_ms, offset_ms);
    b.clock_offset_ms = std::min(b.clock_offset_ms, b.window_min_offset_ms);
  }
  if (b.samples_received > 0 && sample.boot_id != b.last.boot_id) {
    if (sample.boot_id == b.previous_boot_id && arrival - b.boot_switch < kDuplicateSwitchWindow) {
      b.duplicate_id = true;
      b.duplicate_boot_id = b.last.boot_id;
      b.duplicate_seen = arrival;
    }
    b.previous_boot_id = b.last.boot_id;
    b.boot_switch = arrival;
  }
  if (b.duplicate_id && arrival - b.duplicate_seen > kDuplicateClearAfter) b.duplicate_id = false;
  b.last = sample;
  b.last_arrival = arrival;
  b.arrival_utc_ns = arrival_utc_ns;
  b.stale = false;
  ++b.samples_received;
  return b;
}

void FleetModel::update_status(const std::string& node_id, const NodeStatusInfo& status) {
  std::lock_guard lock(mutex_);
  auto it = boats_.find(node_id);
  if (it == boats_.end()) return;  // status before any sample: kept once the boat publishes
  it->second.status = status;
}

std::optional<BoatView> FleetModel::update_fix(const FixSample& fix, SteadyTime arrival) {
  std::lock_guard lock(mutex_);
  auto it = boats_.find(fix.boat_id);
  if (it == boats_.end()) return std::nullopt;
  it->second.fix = fix;
  it->second.fix_arrival = arrival;
  it->second.fix_fresh = true;
  return it->second;
}

std::vector<BoatView> FleetModel::sweep(SteadyTime now) {
  std::vector<BoatView> went_stale;
  std::lock_guard lock(mutex_);
  for (auto& entry : boats_) {
    BoatView& b = entry.second;
    if (!b.stale && now - b.last_arrival > stale_after_) {
      b.stale = true;
      went_stale.push_back(b);
    }
  }
  return went_stale;
}

std::optional<BoatView> FleetModel::set_alarm_state(const std::string& boat_id,
                                                    const std::string& state) {
  std::lock_guard lock(mutex_);
  auto it = boats_.find(boat_id);
  if (it == boats_.end()) {
    // Known from a stored alarm before the boat's first sample after a restart.
    it = boats_.try_emplace(boat_id).first;
    it->second.last.boat_id = boat_id;
    it->second.stale = true;
  }
  it->second.alarm_state = state;
  return it->second;
}

std::vector<std::string> FleetModel::forget(SteadyTime now, std::chrono::seconds older_than) {
  std::vector<std::string> gone;
  std::lock_guard lock(mutex_);
  std::erase_if(boats_, [&](const auto& e) {
    const bool old = e.second.samples_received > 0 && now - e.second.last_arrival > older_than;
    if (old) gone.push_back(e.first);
    return old;
  });
  std::erase_if(athletes_, [&](const auto& e) {
    const bool old = now - e.second.last_arrival > older_than;
    if (old) gone.push_back(e.first);
    return old;
  });
  return gone;
}

std::vector<BoatView> FleetModel::boats() const {
  std::lock_guard lock(mutex_);
  std::vector<BoatView> out;
  out.reserve(boats_.size());
  const auto now = std::chrono::steady_clock::now();
  for (const auto& [id, b] : boats_) out.push_back(as_seen_at(b, now));
  return out;
}

std::optional<BoatView> FleetModel::boat(const std::string& boat_id) const {
  std::lock_guard lock(mutex_);
  auto it = boats_.find(boat_id);
  if (it == boats_.end()) return std::nullopt;
  return as_seen_at(it->second, std::chrono::steady_clock::now());
}

AthleteView FleetModel::update(const WearableSample& sample, SteadyTime arrival) {
  std::lock_guard lock(mutex_);
  if (athletes_.size() >= kMaxFleetEntries && !athletes_.count(sample.athlete_id))
    evict_oldest(athletes_);
  AthleteView& a = athletes_[sample.athlete_id];
  a.last = sample;
  a.last_arrival = arrival;
  a.stale = false;
  return a;
}

std::vector<AthleteView> FleetModel::sweep_athletes(SteadyTime now) {
  std::vector<AthleteView> out;
  std::lock_guard lock(mutex_);
  for (auto& entry : athletes_) {
    AthleteView& a = entry.second;
    // Wearables publish at a few Hz: stale after twice the boats' limit.
    if (!a.stale && now - a.last_arrival > 2 * stale_after_) {
      a.stale = true;
      out.push_back(a);
    }
  }
  return out;
}

std::vector<AthleteView> FleetModel::athletes() const {
  std::lock_guard lock(mutex_);
  std::vector<AthleteView> out;
  for (const auto& [id, a] : athletes_) out.push_back(a);
  return out;
}

std::optional<AthleteView> FleetModel::athlete(const std::string& athlete_id) const {
  std::lock_guard lock(mutex_);
  auto it = athletes_.find(athlete_id);
  if (it == athletes_.end()) return std::nullopt;
  return it->second;
}

}  // namespace telltale::shore

#include "telltale/fusion/alarm_engine.hpp"

#include <algorithm>
#include <cstdio>

#include <cmath>
#include <regex>

namespace telltale::fusion {

const char* to_string(AlarmLevel level) {
  switch (level) {
    case AlarmLevel::kNormal:
      return "normal";
    case AlarmLevel::kWarn:
      return "warn";
    case AlarmLevel::kAlarm:
      return "alarm";
  }
  return "normal";
}

const char* to_string(AlarmQuantity quantity) {
  return quantity == AlarmQuantity::kHeel ? "heel" : "pitch";
}

const char* to_string(AlarmPhase phase) {
  switch (phase) {
    case AlarmPhase::kRaised:
      return "raised";
    case AlarmPhase::kAcknowledged:
      return "acknowledged";
    case AlarmPhase::kSilenced:
      return "silenced";
    case AlarmPhase::kCleared:
      return "cleared";
  }
  return "raised";
}

std::optional<AlarmLevel> parse_level(const std::string& s) {
  if (s == "warn") return AlarmLevel::kWarn;
  if (s == "alarm") return AlarmLevel::kAlarm;
  if (s == "normal") return AlarmLevel::kNormal;
  return std::nullopt;
}

std::optional<AlarmQuantity> parse_quantity(const std::string& s) {
  if (s == "heel") return AlarmQuantity::kHeel;
  if (s == "pitch") return AlarmQuantity::kPitch;
  return std::nullopt;
}

std::optional<AlarmPhase> parse_phase(const std::string& s) {
  for (auto p : {AlarmPhase::kRaised, AlarmPhase::kAcknowledged, AlarmPhase::kSilenced,
                 AlarmPhase::kCleared})
    if (s == to_string(p)) return p;
  return std::nullopt;
}

std::string AlarmRule::validate() const {
  static const std::regex kId("[A-Za-z0-9_-]{1,32}");
  static const std::regex kScope("fleet|group:[A-Za-z0-9_-]{1,32}|boat:[A-Za-z0-9_-]{1,32}");
  if (!std::regex_match(id, kId)) return "rule id must be 1-32 of [A-Za-z0-9_-]";
  if (!std::regex_match(scope, kScope)) return "scope must be fleet, group:NAME or boat:ID";
  for (double v : {min_deg, max_deg, hold_s, hysteresis_deg})
    if (!std::isfinite(v)) return "numbers must be finite";
  if (min_deg < -180.0 || max_deg > 180.0) return "band must lie within -180..180 deg";
  if (!(min_deg < max_deg)) return "min_deg must be below max_deg";
  if (hold_s < 0.0 || hold_s > 3600.0) return "hold_s must be 0..3600";
  if (hysteresis_deg < 0.0 || 2.0 * hysteresis_deg >= max_deg - min_deg)
    return "hysteresis_deg must be >= 0 and narrower than half the band";
  if (level == AlarmLevel::kNormal) return "level must be warn or alarm";
  return "";
}

bool AlarmRule::applies_to(const std::string& boat_id, const std::string& group) const {
  if (!enabled) return false;
  if (scope == "fleet") return true;
  if (scope.rfind("group:", 0) == 0) return !group.empty() && scope.compare(6, std::string::npos, group) == 0;
  return scope.compare(5, std::string::npos, boat_id) == 0;  // "boat:"
}

std::vector<AlarmEvent> AlarmEngine::set_rules(std::vector<AlarmRule> rules, std::uint64_t now_ns) {
  std::lock_guard lock(mutex_);
  std::vector<AlarmEvent> cleared;
  // A rule that is gone or changed restarts from scratch: its active events are cleared.
  const auto kept = [&](const std::string& rule_id) {
    const auto old_it = std::find_if(rules_.begin(), rules_.end(),
                                     [&](const AlarmRule& r) { return r.id == rule_id; });
    const auto new_it = std::find_if(rules.begin(), rules.end(),
                                     [&](const AlarmRule& r) { return r.id == rule_id; });
    return old_it != rules_.end() && new_it != rules.end() && *old_it == *new_it &&
           new_it->enabled;
  };
  for (auto it = tracks_.begin(); it != tracks_.end();) {
    if (kept(it->first.second)) {
      ++it;
      continue;
    }
    if (it->second.active_event) {
      auto ev = active_.find(*it->second.active_event);
      if (ev != active_.end()) {
        ev->second.phase = AlarmPhase::kCleared;
        ev->second.cleared_ns = now_ns;
        ev->second.message = "rule changed or removed";
        cleared.push_back(ev->second);
        active_.erase(ev);
      }
    }
    it = tracks_.erase(it);
  }
  rules_ = std::move(rules);
  return cleared;
}

std::vector<AlarmRule> AlarmEngine::rules() const {
  std::lock_guard lock(mutex_);
  return rules_;
}

std::vector<AlarmEvent> AlarmEngine::evaluate(const std::string& boat_id, const std::string& group,
                                              std::uint64_t t_ns, double heel_deg,
                                              double pitch_deg) {
  std::vector<AlarmEvent> changed;
  std::lock_guard lock(mutex_);
  for (const AlarmRule& rule : rules_) {
    if (!rule.applies_to(boat_id, group)) continue;
    const double v = rule.quantity == AlarmQuantity::kHeel ? heel_deg : pitch_deg;
    if (!std::isfinite(v)) continue;  // no judgement on a missing value
    Track& track = tracks_[{boat_id, rule.id}];
    const bool outside = v < rule.min_deg || v > rule.max_deg;
    const bool well_inside =
        v >= rule.min_deg + rule.hysteresis_deg && v <= rule.max_deg - rule.hysteresis_deg;
    if (outside) {
      if (!track.outside_since_ns || t_ns < *track.outside_since_ns) track.outside_since_ns = t_ns;
    } else {
      track.outside_since_ns.reset();
    }
    if (!track.active_event && track.outside_since_ns &&
        static_cast<double>(t_ns - *track.outside_since_ns) >= rule.hold_s * 1e9) {
      AlarmEvent e;
      e.id = next_id_++;
      e.boat_id = boat_id;
      e.rule_id = rule.id;
      e.level = rule.level;
      e.phase = AlarmPhase::kRaised;
      e.raised_ns = t_ns;
      e.value_deg = v;
      char msg[128];
      std::snprintf(msg, sizeof msg, "%s %.1f deg outside [%.1f, %.1f]", to_string(rule.quantity),
                    v, rule.min_deg, rule.max_deg);
      e.message = msg;
      active_[e.id] = e;
      track.active_event = e.id;
      changed.push_back(e);
    } else if (track.active_event && well_inside) {
      auto ev = active_.find(*track.active_event);
      if (ev != active_.end()) {
        ev->second.phase = AlarmPhase::kCleared;
        ev->second.cleared_ns = t_ns;
        changed.push_back(ev->second);
        active_.erase(ev);
      }
      track.active_event.reset();
    }
  }
  return changed;
}

std::optional<AlarmEvent> AlarmEngine::change_phase(std::uint64_t event_id, AlarmPhase phase,
                                                    std::uint64_t now_ns) {
  auto it = active_.find(event_id);
  if (it == active_.end()) return std::nullopt;
  AlarmEvent& e = it->second;
  if (phase == AlarmPhase::kAcknowledged) {
    if (!e.acknowledged_ns) e.acknowledged_ns = now_ns;
    if (e.phase == AlarmPhase::kRaised) e.phase = AlarmPhase::kAcknowledged;
  } else {
    if (!e.silenced_ns) e.silenced_ns = now_ns;
    e.phase = AlarmPhase::kSilenced;
  }
  return e;
}

std::optional<AlarmEvent> AlarmEngine::acknowledge(std::uint64_t event_id, std::uint64_t now_ns) {
  std::lock_guard lock(mutex_);
  return change_phase(event_id, AlarmPhase::kAcknowledged, now_ns);
}

std::optional<AlarmEvent> AlarmEngine::silence(std::uint64_t event_id, std::uint64_t now_ns) {
  std::lock_guard lock(mutex_);
  return change_phase(event_id, AlarmPhase::kSilenced, now_ns);
}

AlarmLevel AlarmEngine::level_of(const std::string& boat_id) const {
  std::lock_guard lock(mutex_);
  AlarmLevel worst = AlarmLevel::kNormal;
  for (const auto& [id, e] : active_)
    if (e.boat_id == boat_id && e.level > worst) worst = e.level;
  return worst;
}

std::vector<AlarmEvent> AlarmEngine::active() const {
  std::lock_guard lock(mutex_);
  std::vector<AlarmEvent> out;
  for (const auto& [id, e] : active_) out.push_back(e);
  return out;
}

void AlarmEngine::restore(std::vector<AlarmRule> rules, std::vector<AlarmEvent> active_events,
                          std::uint64_t next_event_id) {
  std::lock_guard lock(mutex_);
  rules_ = std::move(rules);
  tracks_.clear();
  active_.clear();
  for (auto& e : active_events) {
    if (e.phase == AlarmPhase::kCleared) continue;
    tracks_[{e.boat_id, e.rule_id}].active_event = e.id;
    active_[e.id] = std::move(e);
  }
  next_id_ = std::max<std::uint64_t>(next_event_id, 1);
  for (const auto& [id, e] : active_) next_id_ = std::max(next_id_, id + 1);
}

}  // namespace telltale::fusion

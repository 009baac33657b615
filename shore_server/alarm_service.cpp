#include "alarm_service.hpp"

#include <set>

#include "json_views.hpp"

namespace telltale::shore {

AlarmService::AlarmService(Store& store, LiveHub& hub, FleetModel& fleet)
    : store_(store), hub_(hub), fleet_(fleet) {}

void AlarmService::start(AlarmSinks sinks) {
  sinks_ = std::move(sinks);
  EventFilter active;
  active.active_only = true;
  active.limit = 100000;
  engine_.restore(store_.load_rules(), store_.events(active), store_.max_event_id() + 1);
  for (const auto& e : engine_.active())
    fleet_.set_alarm_state(e.boat_id, to_string(engine_.level_of(e.boat_id)));
  if (sinks_.push_rules) sinks_.push_rules(engine_.rules());
  for (const auto& e : engine_.active())
    if (sinks_.push_event) sinks_.push_event(e);
}

void AlarmService::on_sample(const AttitudeSample& s, const std::string& group) {
  const auto changed = engine_.evaluate(s.boat_id, group, s.t_utc_ns, s.heel_deg, s.pitch_deg);
  if (!changed.empty()) publish(changed);
}

void AlarmService::put_rules(std::vector<AlarmRule> rules, std::uint64_t now_ns) {
  store_.save_rules(rules);  // throws StoreError: nothing applied if it is not on disk
  const auto cleared = engine_.set_rules(std::move(rules), now_ns);
  if (sinks_.push_rules) sinks_.push_rules(engine_.rules());
  publish(cleared);
}

std::optional<AlarmEvent> AlarmService::acknowledge(std::uint64_t id, std::uint64_t now_ns) {
  auto e = engine_.acknowledge(id, now_ns);
  if (e) publish({*e});
  return e;
}

std::optional<AlarmEvent> AlarmService::silence(std::uint64_t id, std::uint64_t now_ns) {
  auto e = engine_.silence(id, now_ns);
  if (e) publish({*e});
  return e;
}

void AlarmService::publish(const std::vector<AlarmEvent>& changed) {
  std::set<std::string> boats;
  for (const auto& e : changed) {
    store_.save_event(e);
    if (sinks_.push_event) sinks_.push_event(e);
    hub_.publish_event("alarm", to_json_text(event_object(e)), e.boat_id);
    boats.insert(e.boat_id);
  }
  for (const auto& boat : boats) {
    if (auto view = fleet_.set_alarm_state(boat, to_string(engine_.level_of(boat))))
      hub_.publish_sample(boat, [v = std::move(*view)] { return boat_json(v); });
  }
}

}  // namespace telltale::shore

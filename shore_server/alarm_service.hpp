#pragma once
/// \file
/// Wires the alarm engine to the rest of the shore: every changed event is stored (synchronously,
/// so acknowledgements survive a restart), pushed to the boats over DDS and to the dashboards over
/// the live stream, and reflected in the fleet model's alarm state.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "telltale/fusion/alarm_engine.hpp"
#include "fleet.hpp"
#include "live_hub.hpp"
#include "store.hpp"

namespace telltale::shore {

struct AlarmSinks {
  std::function<void(const std::vector<AlarmRule>&)> push_rules;  ///< to the boats
  std::function<void(const AlarmEvent&)> push_event;              ///< to the boats
};

class AlarmService {
 public:
  AlarmService(Store& store, LiveHub& hub, FleetModel& fleet);

  /// Restores rules and active events from the store and pushes the rules. Call once at start,
  /// after the sinks are set.
  void start(AlarmSinks sinks);
  /// Evaluates one live sample of a boat.
  void on_sample(const AttitudeSample& sample, const std::string& group);
  [[nodiscard]] std::vector<AlarmRule> rules() const { return engine_.rules(); }
  /// Stores and applies a validated rule set.
  void put_rules(std::vector<AlarmRule> rules, std::uint64_t now_ns);
  std::optional<AlarmEvent> acknowledge(std::uint64_t id, std::uint64_t now_ns);
  std::optional<AlarmEvent> silence(std::uint64_t id, std::uint64_t now_ns);

 private:
  void publish(const std::vector<AlarmEvent>& changed);

  Store& store_;
  LiveHub& hub_;
  FleetModel& fleet_;
  AlarmEngine engine_;
  AlarmSinks sinks_;
};

}  // namespace telltale::shore

#pragma once
/// \file
/// The shore's DDS role: subscribes to the whole fleet (attitude, node status) and hands every
/// sample to the callbacks, on Fast DDS's listener thread. Callbacks must be quick and must not
/// throw (they update the fleet model, the live hub and the store queue).

#include <functional>
#include <memory>
#include <string>

#include "dds_participant.hpp"
#include "fleet.hpp"

namespace telltale::shore {

struct FleetCallbacks {
  std::function<void(const AttitudeSample&)> on_attitude;
  std::function<void(const std::string& node_id, const NodeStatusInfo&)> on_status;
  /// A boat missed its DDS deadline (no sample within the deadline period).
  std::function<void(const std::string& boat_id)> on_deadline_missed;
};

class FleetSubscriber {
 public:
  /// Creates the participant and readers (throws dds::DdsError).
  FleetSubscriber(const dds::DdsOptions& options, FleetCallbacks callbacks);
  ~FleetSubscriber();
  FleetSubscriber(const FleetSubscriber&) = delete;
  FleetSubscriber& operator=(const FleetSubscriber&) = delete;

 private:
  class Listener;
  FleetCallbacks callbacks_;
  std::unique_ptr<Listener> listener_;
  std::unique_ptr<dds::Participant> participant_;
};

}  // namespace telltale::shore

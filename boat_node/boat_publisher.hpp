#pragma once
/// \file
/// The boat node's DDS role: publishes BoatAttitude (QoS profile attitude_writer) and NodeStatus
/// (status_writer). Constructor creates the entities and throws DdsError; destructor deletes them.

#include <string>

#include "dds_participant.hpp"
#include "telltale.h"

namespace telltale::boat {

class BoatPublisher {
 public:
  BoatPublisher(const dds::DdsOptions& options, const std::string& boat_id);

  /// Writes one attitude sample (never blocks on a best-effort writer). Returns false on failure.
  bool publish(msg::BoatAttitude& sample);
  bool publish(msg::NodeStatus& status);

 private:
  dds::Participant participant_;
  eprosima::fastdds::dds::DataWriter* attitude_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* status_writer_ = nullptr;
};

}  // namespace telltale::boat

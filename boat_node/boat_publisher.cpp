#include "boat_publisher.hpp"

#include "telltalePubSubTypes.h"

namespace telltale::boat {

using eprosima::fastdds::dds::TypeSupport;


BoatPublisher::BoatPublisher(const dds::DdsOptions& options, const std::string& boat_id)
    : participant_(options, "boat_node " + boat_id) {
  attitude_writer_ = participant_.writer(
      participant_.topic(dds::kTopicBoatAttitude, TypeSupport(new msg::BoatAttitudePubSubType())),
      "attitude_writer");
  status_writer_ = participant_.writer(
      participant_.topic(dds::kTopicNodeStatus, TypeSupport(new msg::NodeStatusPubSubType())),
      "status_writer");
}

bool BoatPublisher::publish(msg::BoatAttitude& sample) {
  return attitude_writer_->write(&sample);
}

bool BoatPublisher::publish(msg::NodeStatus& status) {
  return status_writer_->write(&status);
}

}  // namespace telltale::boat

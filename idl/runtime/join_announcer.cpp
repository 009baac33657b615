#include "join_announcer.hpp"

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <vector>

namespace telltale::dds {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;

JoinAnnouncer::JoinAnnouncer(fdds::DomainParticipantListener* forward,
                             std::chrono::milliseconds delay, std::chrono::milliseconds min_gap)
    : forward_(forward), delay_(delay), min_gap_(min_gap) {}

JoinAnnouncer::~JoinAnnouncer() { stop(); }

void JoinAnnouncer::start(fdds::DomainParticipant* participant) {
  std::lock_guard lock(mutex_);
  if (thread_.joinable() || !participant) return;
  participant_ = participant;
  thread_ = std::thread([this] { run(); });
}

void JoinAnnouncer::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::uint64_t JoinAnnouncer::announcements() const {
  std::lock_guard lock(mutex_);
  return announcements_;
}

void JoinAnnouncer::on_participant_discovery(fdds::DomainParticipant* participant,
                                             ParticipantDiscoveryInfo&& info) {
  if (info.status == ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) {
    {
      std::lock_guard lock(mutex_);
      joined_ = true;
    }
    cv_.notify_all();
  }
  if (forward_) forward_->on_participant_discovery(participant, std::move(info));
}

void JoinAnnouncer::on_subscriber_discovery(fdds::DomainParticipant* participant,
                                            eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) {
  if (forward_) forward_->on_subscriber_discovery(participant, std::move(info));
}

void JoinAnnouncer::on_publisher_discovery(fdds::DomainParticipant* participant,
                                           eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) {
  if (forward_) forward_->on_publisher_discovery(participant, std::move(info));
}

void JoinAnnouncer::run() {
  using Clock = std::chrono::steady_clock;
  auto last = Clock::now() - min_gap_;
  std::uint32_t counter = 0;
  std::unique_lock lock(mutex_);
  while (!stop_) {
    cv_.wait(lock, [this] { return stop_ || joined_; });
    if (stop_) break;
    // The newcomer's set-up first, then no sooner than min_gap after the previous announcement;
    // joins meanwhile are covered by this one.
    const auto at = std::max(Clock::now() + delay_, last + min_gap_);
    if (cv_.wait_until(lock, at, [this] { return stop_; })) break;
    joined_ = false;
    lock.unlock();
    fdds::DomainParticipantQos qos = participant_->get_qos();
    ++counter;
    qos.user_data().setValue(std::vector<eprosima::fastrtps::rtps::octet>{
        static_cast<eprosima::fastrtps::rtps::octet>(counter >> 24),
        static_cast<eprosima::fastrtps::rtps::octet>(counter >> 16),
        static_cast<eprosima::fastrtps::rtps::octet>(counter >> 8),
        static_cast<eprosima::fastrtps::rtps::octet>(counter)});
    const bool ok =
        participant_->set_qos(qos) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
    last = Clock::now();
    lock.lock();
    if (ok) ++announcements_;
  }
}

}  // namespace telltale::dds

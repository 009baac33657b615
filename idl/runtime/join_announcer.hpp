#pragma once
/// \file
/// Announcing the local participant again when another one joins (the shore's participant).
///
/// Simple discovery: a participant that discovers a new one answers it at once with its own
/// announcement (DATA(p)); until the newcomer has that answer it does not know us, so none of
/// its writers match our readers. Measured with Fast DDS 2.9 on loopback (deploy/bench_join.sh,
/// and bare participants joining a bare one): in roughly a third of joins the newcomer never
/// takes the first answer in (it comes back within a millisecond, while the newcomer is still
/// setting itself up), and our later receipts of its own repeated announcements are not answered
/// again, since it is no longer new to us. It then learns of us only from our next periodic
/// announcement, up to the lease-announcement period (2 s) later: a boat joining a running shore
/// was listed after 0.3-1.9 s in those joins instead of ~50 ms.
///
/// So a short time after every discovery the participant announces itself again. Fast DDS 2.9
/// has no public call that announces; a change of the participant's USER_DATA is announced at
/// once to every known participant, so the announcer bumps a counter there (nothing reads it).
/// Cost: one DATA(p) to each known participant per announcement. Joins close together share one
/// (the first `delay` after a discovery, then at most one per `min_gap`), so a whole fleet
/// starting at once costs a few announcements a second while it joins, and nothing after.
///
/// The announcer is the participant's listener: it forwards the discovery callbacks to the
/// listener the caller gave (the shore's writer check in secured mode).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <mutex>
#include <thread>

namespace telltale::dds {

class JoinAnnouncer final : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  /// After a discovery, the announcement waits `delay` (the newcomer finishes setting itself up
  /// in a few ms) and comes at least `min_gap` after the previous one.
  explicit JoinAnnouncer(eprosima::fastdds::dds::DomainParticipantListener* forward,
                         std::chrono::milliseconds delay = std::chrono::milliseconds(50),
                         std::chrono::milliseconds min_gap = std::chrono::milliseconds(250));
  ~JoinAnnouncer() override;
  JoinAnnouncer(const JoinAnnouncer&) = delete;
  JoinAnnouncer& operator=(const JoinAnnouncer&) = delete;

  /// Starts announcing for `participant` (created with this listener).
  void start(eprosima::fastdds::dds::DomainParticipant* participant);
  /// Stops the thread; call before the participant is deleted. Idempotent.
  void stop();
  /// Announcements made so far.
  [[nodiscard]] std::uint64_t announcements() const;

  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override;
  void on_subscriber_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override;
  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;

 private:
  void run();

  eprosima::fastdds::dds::DomainParticipantListener* forward_;
  const std::chrono::milliseconds delay_, min_gap_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool joined_ = false;  ///< a participant was discovered since the last announcement
  bool stop_ = false;
  std::uint64_t announcements_ = 0;
  std::thread thread_;
};

}  // namespace telltale::dds

#pragma once
/// \file
/// Secured mode, second line of the per-boat authorisation: the shore accepts a sample only if
/// the id it claims (boat_id, athlete_id, node_id) hashes to a partition of the writer it came
/// from. Fast DDS's access control lets a node create writers only in the partitions its signed
/// permissions grant (tt-<tag(own id)>); this check makes a node that writes another boat's id
/// into its own partition (a modified binary) harmless: such samples are dropped, counted, and
/// logged once per writer.
///
/// The writers' partitions come from discovery (on_publisher_discovery, discovery thread); the
/// checks run on the readers' listener thread. A sample from a writer not yet discovered is
/// dropped too (fail closed) and counted apart.
///
/// Only the partitions a writer is first discovered with count: Fast DDS 2.9 checks them against
/// the writer's signed permissions when it matches the writer (check_remote_datawriter) but not
/// when the writer later changes its PARTITION QoS (measured: security_test's
/// PartitionSwitchAfterCreation). A writer whose partitions change is distrusted for good.

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "dds_participant.hpp"

namespace telltale::shore {

class WriterCheck : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  /// `security_dir`: the shore's node folder (its fleet.salt gives the tags).
  explicit WriterCheck(std::string security_dir);
  /// Prints the drop counts (stderr) when there were any.
  ~WriterCheck() override;
  WriterCheck(const WriterCheck&) = delete;
  WriterCheck& operator=(const WriterCheck&) = delete;

  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;

  /// True if `claimed_id` may come from the writer `publication_handle` (SampleInfo's). Never
  /// blocks for long: one map lookup under a mutex, one SHA-256 per new id.
  bool allowed(const eprosima::fastdds::dds::InstanceHandle_t& publication_handle,
               const std::string& claimed_id);

  /// Samples dropped because the claimed id is not the writer's (forged).
  [[nodiscard]] std::uint64_t forged() const { return forged_; }
  /// Samples dropped because their writer was not (yet) discovered.
  [[nodiscard]] std::uint64_t unknown_writer() const { return unknown_writer_; }

 private:
  std::string partition_of(const std::string& id);

  std::string security_dir_;
  std::mutex mutex_;
  struct Writer {
    std::vector<std::string> partitions;  ///< as first discovered
    bool trusted = true;                  ///< false once it announced other partitions
  };
  std::map<eprosima::fastrtps::rtps::GUID_t, Writer> writers_;
  std::map<std::string, std::string> partition_cache_;  ///< id -> tt-<tag>
  std::set<eprosima::fastrtps::rtps::GUID_t> logged_;
  std::atomic<std::uint64_t> forged_{0};
  std::atomic<std::uint64_t> unknown_writer_{0};
};

}  // namespace telltale::shore

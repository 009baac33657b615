#include "writer_check.hpp"

#include <fastdds/rtps/writer/WriterDiscoveryInfo.h>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "dds_security.hpp"

namespace telltale::shore {

namespace rtps = eprosima::fastrtps::rtps;

WriterCheck::WriterCheck(std::string security_dir) : security_dir_(std::move(security_dir)) {
  (void)dds::fleet_tag(security_dir_, "");  // fails now, not on the first sample, without salt
}

WriterCheck::~WriterCheck() {
  if (forged_ || unknown_writer_)
    std::fprintf(stderr,
                 "shore_server: security: dropped %llu samples with another node's id, %llu from "
                 "undiscovered writers\n",
                 static_cast<unsigned long long>(forged_.load()),
                 static_cast<unsigned long long>(unknown_writer_.load()));
}

void WriterCheck::on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                         rtps::WriterDiscoveryInfo&& info) {
  std::lock_guard lock(mutex_);
  const auto& guid = info.info.guid();
  auto partitions = info.info.m_qos.m_partition.getNames();
  switch (info.status) {
    case rtps::WriterDiscoveryInfo::DISCOVERED_WRITER:
      writers_[guid] = Writer{std::move(partitions), true};
      break;
    case rtps::WriterDiscoveryInfo::CHANGED_QOS_WRITER: {
      auto w = writers_.find(guid);
      if (w == writers_.end() || w->second.partitions == partitions || !w->second.trusted) break;
      w->second.trusted = false;
      std::ostringstream writer;
      writer << guid;
      std::fprintf(stderr,
                   "shore_server: security: writer %s changed its partitions after discovery; "
                   "they are not re-checked against its permissions, so its samples are dropped\n",
                   writer.str().c_str());
      break;
    }
    case rtps::WriterDiscoveryInfo::REMOVED_WRITER:
      writers_.erase(guid);
      break;
  }
}

std::string WriterCheck::partition_of(const std::string& id) {
  auto it = partition_cache_.find(id);
  if (it == partition_cache_.end())
    it = partition_cache_.emplace(id, dds::node_partition(security_dir_, id)).first;
  return it->second;
}

bool WriterCheck::allowed(const eprosima::fastdds::dds::InstanceHandle_t& publication_handle,
                          const std::string& claimed_id) {
  rtps::GUID_t guid;
  rtps::iHandle2GUID(guid, publication_handle);
  std::lock_guard lock(mutex_);
  const auto w = writers_.find(guid);
  if (w == writers_.end()) {
    ++unknown_writer_;
    return false;
  }
  const auto& partitions = w->second.partitions;
  if (w->second.trusted &&
      std::find(partitions.begin(), partitions.end(), partition_of(claimed_id)) != partitions.end())
    return true;
  ++forged_;
  if (logged_.insert(guid).second) {
    std::ostringstream writer;
    writer << guid;
    std::string names;
    for (const auto& p : partitions) names += (names.empty() ? "" : ",") + p;
    std::fprintf(stderr,
                 "shore_server: security: dropping samples claiming '%s' from writer %s "
                 "(partitions %s%s): not that node's partition (further drops counted silently)\n",
                 claimed_id.c_str(), writer.str().c_str(), names.c_str(),
                 w->second.trusted ? "" : ", changed since");
  }
  return false;
}

}  // namespace telltale::shore

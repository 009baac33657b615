#include "writer_check.hpp"

#include <algorithm>
#include <cstdio>
#include <fastdds/rtps/writer/WriterDiscoveryInfo.h>
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
  if (info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER) {
    writers_.erase(guid);
    return;
  }
  writers_[guid] = info.info.m_qos.m_partition.getNames();
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
  const std::string expected = partition_of(claimed_id);
  if (std::find(w->second.begin(), w->second.end(), expected) != w->second.end()) return true;
  ++forged_;
  if (logged_.insert(guid).second) {
    std::ostringstream writer;
    writer << guid;
    std::string partitions;
    for (const auto& p : w->second) partitions += (partitions.empty() ? "" : ",") + p;
    std::fprintf(stderr,
                 "shore_server: security: dropping samples claiming '%s' from writer %s "
                 "(partitions %s): not that node's partition (further drops counted silently)\n",
                 claimed_id.c_str(), writer.str().c_str(), partitions.c_str());
  }
  return false;
}

}  // namespace telltale::shore

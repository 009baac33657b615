#include "dds_participant.hpp"

#include <fastdds/rtps/common/Locator.h>
#include <fastrtps/types/TypesBase.h>
#include <fastrtps/utils/IPLocator.h>

#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <filesystem>
#include <mutex>

#include "dds_security.hpp"
#include "join_announcer.hpp"

namespace telltale::dds {

using eprosima::fastdds::dds::DomainParticipantFactory;
using eprosima::fastrtps::types::ReturnCode_t;
namespace fdds = eprosima::fastdds::dds;

int resolve_domain(const std::optional<int>& flag) {
  // With neither flag nor variable every binary lands on one shared default, so a shore and a
  // boat started with no options find each other; tests and the demo always pass their own.
  int domain = kDefaultDomain;
  if (flag) {
    domain = *flag;
  } else if (const char* env = std::getenv("TELLTALE_DOMAIN"); env && *env) {
    char* end = nullptr;
    const long v = std::strtol(env, &end, 10);
    if (*end != '\0') throw DdsError(std::string("TELLTALE_DOMAIN is not a number: ") + env);
    if (end == env || v < 0 || v > 232)
      throw DdsError(std::string("TELLTALE_DOMAIN must be a DDS domain 0..232, got '") + env + "'");
    domain = static_cast<int>(v);
  }
  if (domain < 0 || domain > 232) throw DdsError("DDS domain must be 0..232");
  return domain;
}

std::string resolve_profiles_file(const std::string& flag) {
  std::string path = flag;
  if (path.empty()) {
    if (const char* env = std::getenv("TELLTALE_DDS_PROFILES"); env && *env) path = env;
  }
  if (path.empty()) path = TELLTALE_DEFAULT_DDS_PROFILES;
  if (!std::filesystem::exists(path)) throw DdsError("DDS profiles file not found: " + path);
  return path;
}

namespace {

/// Peers from the options, else from TELLTALE_DDS_PEERS, appended to the initial peers. Port 0
/// lets Fast DDS probe the well-known ports of the first participant ids on each address.
void add_initial_peers(std::vector<std::string> peers, fdds::DomainParticipantQos& qos) {
  if (peers.empty()) {
    if (const char* env = std::getenv("TELLTALE_DDS_PEERS"); env && *env) {
      std::string list = env;
      for (std::size_t start = 0; start <= list.size();) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        if (comma > start) peers.push_back(list.substr(start, comma - start));
        start = comma + 1;
      }
    }
  }
  for (const auto& peer : peers) {
    if (!eprosima::fastrtps::rtps::IPLocator::isIPv4(peer))
      throw DdsError("DDS peer is not an IPv4 address: " + peer);
    eprosima::fastrtps::rtps::Locator_t locator;
    locator.kind = LOCATOR_KIND_UDPv4;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(locator, peer);
    qos.wire_protocol().builtin.initialPeersList.push_back(locator);
  }
}

}  // namespace

Participant::Participant(const DdsOptions& options, const std::string& name)
    : domain_(resolve_domain(options.domain)) {
  auto* factory = DomainParticipantFactory::get_instance();
  const std::string profiles = resolve_profiles_file(options.profiles_file);
  // The factory is process-wide; load each file once.
  static std::mutex load_mutex;
  static std::string loaded;
  {
    std::lock_guard lock(load_mutex);
    if (loaded != profiles) {
      if (factory->load_XML_profiles_file(profiles) != ReturnCode_t::RETCODE_OK)
        throw DdsError("cannot load DDS profiles " + profiles);
      loaded = profiles;
    }
  }
  fdds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(options.participant_profile, qos) !=
      ReturnCode_t::RETCODE_OK)
    throw DdsError("no participant profile '" + options.participant_profile + "' in " + profiles);
  qos.name(name);
  add_initial_peers(options.peers, qos);
  if (options.customize) options.customize(qos);
  secured_ = !options.security_dir.empty();
  if (secured_) apply_security(options.security_dir, qos);
  fdds::DomainParticipantListener* listener = options.listener;
  if (options.announce_on_join) {
    announcer_ = std::make_unique<JoinAnnouncer>(options.listener);
    listener = announcer_.get();
  }
  participant_ = factory->create_participant(static_cast<fdds::DomainId_t>(domain_), qos,
                                             listener, fdds::StatusMask::none());
  if (!participant_)
    throw DdsError("cannot create DDS participant on domain " + std::to_string(domain_) +
                   (secured_ ? " (DDS Security refused the files in " + options.security_dir +
                                   ": expired or foreign certificate, bad signature?)"
                             : std::string()));
  fdds::PublisherQos pub_qos = fdds::PUBLISHER_QOS_DEFAULT;
  for (const auto& p : options.publisher_partitions) pub_qos.partition().push_back(p.c_str());
  fdds::SubscriberQos sub_qos = fdds::SUBSCRIBER_QOS_DEFAULT;
  for (const auto& p : options.subscriber_partitions) sub_qos.partition().push_back(p.c_str());
  publisher_ = participant_->create_publisher(pub_qos);
  subscriber_ = participant_->create_subscriber(sub_qos);
  if (!publisher_ || !subscriber_) {
    if (announcer_) announcer_->stop();
    participant_->delete_contained_entities();
    factory->delete_participant(participant_);
    throw DdsError("cannot create DDS publisher/subscriber");
  }
  if (announcer_) announcer_->start(participant_);
}

Participant::~Participant() {
  if (!participant_) return;
  if (announcer_) announcer_->stop();
  // Readers stop calling their listeners before they are deleted: samples keep arriving while the
  // entities go, and a listener is often destroyed right after this participant.
  std::vector<fdds::DataReader*> readers;
  if (subscriber_->get_datareaders(readers) == ReturnCode_t::RETCODE_OK)
    for (auto* r : readers) r->set_listener(nullptr);
  // A participant Fast DDS refuses to delete keeps running (its readers, their listeners): say so
  // rather than leave it silent. A destructor cannot throw.
  if (participant_->delete_contained_entities() != ReturnCode_t::RETCODE_OK ||
      DomainParticipantFactory::get_instance()->delete_participant(participant_) !=
          ReturnCode_t::RETCODE_OK)
    std::fprintf(stderr, "telltale dds: a DDS participant could not be deleted (left running)\n");
}

fdds::Topic* Participant::topic(const std::string& topic_name, fdds::TypeSupport type) {
  if (auto it = topics_.find(topic_name); it != topics_.end()) return it->second;
  if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK)
    throw DdsError("cannot register type " + type.get_type_name());
  auto* t = participant_->create_topic(topic_name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (!t) throw DdsError("cannot create topic " + topic_name);
  topics_[topic_name] = t;
  return t;
}

fdds::DataWriter* Participant::writer(fdds::Topic* t, const std::string& profile,
                                      fdds::DataWriterListener* listener) {
  auto* w = publisher_->create_datawriter_with_profile(t, profile, listener);
  if (!w)
    throw DdsError("cannot create writer on " + t->get_name() + " with profile " + profile +
                   (secured_ ? " (DDS Security: this node's permissions do not allow it)" : ""));
  return w;
}

fdds::DataReader* Participant::reader(fdds::Topic* t, const std::string& profile,
                                      fdds::DataReaderListener* listener) {
  auto* r =
      subscriber_->create_datareader_with_profile(t, profile, listener, fdds::StatusMask::all());
  if (!r)
    throw DdsError("cannot create reader on " + t->get_name() + " with profile " + profile +
                   (secured_ ? " (DDS Security: this node's permissions do not allow it)" : ""));
  return r;
}

void Participant::delete_reader(fdds::DataReader* reader) {
  if (subscriber_->delete_datareader(reader) != ReturnCode_t::RETCODE_OK)
    throw DdsError("cannot delete reader on " + reader->get_topicdescription()->get_name());
}

}  // namespace telltale::dds

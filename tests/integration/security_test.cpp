// Secured mode: real shore_server and boat_node processes with DDS
// Security, each test with its own PKI made by deploy/security/make_fleet_pki.sh in a temporary
// folder, its own DDS domain and HTTP port.
#include <arpa/inet.h>
#include <linux/if_ether.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <netinet/ip.h>
#include <netinet/udp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "dds_participant.hpp"
#include "dds_security.hpp"
#include "shore_fixture.hpp"
#include "telltalePubSubTypes.h"

namespace telltale::testing {
namespace {

namespace fdds = eprosima::fastdds::dds;
using std::chrono::milliseconds;
using std::chrono::seconds;
using Clock = std::chrono::steady_clock;

/// Runs the fleet PKI script; the test fails (not skips) when it cannot.
void make_pki(const std::string& options, const std::string& dir, const std::string& nodes) {
  const std::string cmd = std::string(TELLTALE_SOURCE_DIR) + "/deploy/security/make_fleet_pki.sh " +
                          options + " " + dir + " " + nodes + " >/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

/// Counts the samples a DDS reader in this process receives.
class CountingListener : public fdds::DataReaderListener {
 public:
  void on_data_available(fdds::DataReader* reader) override {
    msg::BoatAttitude m;
    fdds::SampleInfo info;
    while (reader->take_next_sample(&m, &info) == ReturnCode::RETCODE_OK)
      if (info.valid_data) {
        if (m.boat_id().to_string() == "intruder")
          intruder_samples++;
        else
          other_samples++;
      }
  }
  std::atomic<int> intruder_samples{0};
  std::atomic<int> other_samples{0};

 private:
  using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
};

/// The UDP ports the sockets of processes `pids` are bound to (their /proc/<pid>/fd links to
/// socket inodes, looked up in /proc/net/udp).
std::set<std::uint16_t> udp_ports_of(const std::vector<pid_t>& pids) {
  std::set<unsigned long> inodes;
  for (const pid_t pid : pids) {
    std::error_code ec;
    for (const auto& fd :
         std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec)) {
      const auto target = std::filesystem::read_symlink(fd.path(), ec).string();
      if (!ec && target.rfind("socket:[", 0) == 0)
        inodes.insert(std::stoul(target.substr(8, target.size() - 9)));
    }
  }
  std::set<std::uint16_t> ports;
  for (const char* table : {"/proc/net/udp", "/proc/net/udp6"}) {
    std::ifstream in(table);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      // sl local_address rem_address st tx_queue:rx_queue tr:tm retrnsmt uid timeout inode
      std::istringstream fields(line);
      std::string sl, local, remote, st, queues, timer, retransmits, uid, timeout;
      unsigned long inode = 0;
      if (!(fields >> sl >> local >> remote >> st >> queues >> timer >> retransmits >> uid >>
            timeout >> inode))
        continue;
      if (inodes.count(inode) == 0) continue;
      const auto colon = local.rfind(':');
      if (colon != std::string::npos)
        ports.insert(static_cast<std::uint16_t>(std::stoul(local.substr(colon + 1), nullptr, 16)));
    }
  }
  return ports;
}

/// A capture of the UDP traffic on lo to and from one DDS domain's ports (7400 + 250 * domain
/// .. + 249), with an AF_PACKET socket. Those ports lie in the kernel's ephemeral range
/// (32768-60999), so another test's process may send from a port in it: finish() keeps the
/// datagrams sent from a port one of the given processes holds.
class LoopbackCapture {
 public:
  explicit LoopbackCapture(int domain)
      : low_(static_cast<std::uint16_t>(7400 + 250 * domain)),
        high_(static_cast<std::uint16_t>(low_ + 249)) {
    fd_ = socket(AF_PACKET, SOCK_DGRAM, htons(ETH_P_IP));
    if (fd_ < 0) {
      error_ = std::string("AF_PACKET socket: ") + std::strerror(errno) +
               " (the capture needs CAP_NET_RAW: run as root, as CI does)";
      return;
    }
    sockaddr_ll addr{};
    addr.sll_family = AF_PACKET;
    addr.sll_protocol = htons(ETH_P_IP);
    addr.sll_ifindex = static_cast<int>(if_nametoindex("lo"));
    if (bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      error_ = std::string("bind to lo: ") + std::strerror(errno);
      return;
    }
    thread_ = std::thread([this] { run(); });
  }
  ~LoopbackCapture() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    if (fd_ >= 0) close(fd_);
  }
  LoopbackCapture(const LoopbackCapture&) = delete;
  LoopbackCapture& operator=(const LoopbackCapture&) = delete;

  /// Empty when capturing; else why not.
  [[nodiscard]] const std::string& error() const { return error_; }
  /// Stops capturing; the payloads, as bytes in one string, of the datagrams sent from
  /// `senders` (UDP ports). `foreign`: datagrams in the domain's port range sent from elsewhere.
  std::string finish(const std::set<std::uint16_t>& senders, int* packets, int* foreign) {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    std::string payloads;
    *packets = 0;
    *foreign = 0;
    for (const auto& d : datagrams_) {
      if (senders.count(d.source) == 0) {
        ++*foreign;
        continue;
      }
      ++*packets;
      ++sizes_[d.payload.size()];
      payloads += d.payload;
    }
    return payloads;
  }

 private:
  void run() {
    std::vector<unsigned char> buf(65536);
    while (!stop_) {
      pollfd p{fd_, POLLIN, 0};
      if (poll(&p, 1, 100) <= 0) continue;
      const ssize_t n = recv(fd_, buf.data(), buf.size(), 0);
      if (n < static_cast<ssize_t>(sizeof(iphdr) + sizeof(udphdr))) continue;
      const auto* ip = reinterpret_cast<const iphdr*>(buf.data());
      if (ip->protocol != IPPROTO_UDP) continue;
      const std::size_t ihl = static_cast<std::size_t>(ip->ihl) * 4;
      if (static_cast<std::size_t>(n) < ihl + sizeof(udphdr)) continue;
      const auto* udp = reinterpret_cast<const udphdr*>(buf.data() + ihl);
      const auto src = ntohs(udp->source);
      const auto dst = ntohs(udp->dest);
      const bool ours = (src >= low_ && src <= high_) || (dst >= low_ && dst <= high_);
      if (!ours) continue;
      datagrams_.push_back(
          {src, std::string(reinterpret_cast<const char*>(buf.data() + ihl + sizeof(udphdr)),
                            static_cast<std::size_t>(n) - ihl - sizeof(udphdr))});
    }
  }

  std::uint16_t low_;
  std::uint16_t high_;
  int fd_ = -1;
  std::string error_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  struct Datagram {
    std::uint16_t source;
    std::string payload;
  };
  std::vector<Datagram> datagrams_;   ///< written by the capture thread until finish()
  std::map<std::size_t, int> sizes_;  ///< UDP payload size -> packets kept by finish()

 public:
  /// The most frequent UDP payload size (the 25 Hz attitude sample's datagram). After finish().
  [[nodiscard]] std::size_t commonest_size() const {
    std::size_t best = 0;
    int count = 0;
    for (const auto& [size, n] : sizes_)
      if (n > count) {
        best = size;
        count = n;
      }
    return best;
  }
};

/// A participant in this process with a node's certificate folder, writing BoatAttitude samples
/// in that node's partition with any boat id: a modified boat_node.
class Forger {
 public:
  Forger(int domain, const std::string& security_dir, const std::string& own_id) {
    dds::DdsOptions options;
    options.domain = domain;
    options.security_dir = security_dir;
    dds::use_node_partitions(options, own_id);
    participant_ = std::make_unique<dds::Participant>(options, "forger");
    writer = participant_->writer(
        participant_->topic(dds::kTopicBoatAttitude,
                            fdds::TypeSupport(new msg::BoatAttitudePubSubType())),
        "attitude_writer");
    m_.leds().led_count(6);
    m_.heel_deg(5.0);
  }
  /// One sample claiming `boat_id`.
  void write(const char* boat_id) {
    m_.boat_id(boat_id);
    m_.seq(++seq_);
    m_.t_utc_ns(static_cast<std::uint64_t>(std::chrono::system_clock::now().time_since_epoch() /
                                           std::chrono::nanoseconds(1)));
    writer->write(&m_);
  }
  /// Writes `ids` every 40 ms for `duration`, or until `stop()` (checked once a second).
  template <class Stop>
  void write_for(std::initializer_list<const char*> ids, std::chrono::milliseconds duration,
                 Stop stop) {
    const auto deadline = Clock::now() + duration;
    for (int i = 1; Clock::now() < deadline; ++i) {
      for (const char* id : ids) write(id);
      std::this_thread::sleep_for(milliseconds(40));
      if (i % 25 == 0 && stop()) return;
    }
  }

  fdds::DataWriter* writer = nullptr;

 private:
  std::unique_ptr<dds::Participant> participant_;
  msg::BoatAttitude m_;
  std::uint64_t seq_ = 0;
};

/// Moves the writer's publisher to `partition` (PARTITION is changeable). True if accepted.
bool move_to_partition(fdds::DataWriter* writer, const std::string& partition) {
  // Participant keeps its publisher to itself; Fast DDS hands it out const only.
  auto* publisher = const_cast<fdds::Publisher*>(writer->get_publisher());
  fdds::PublisherQos qos;
  publisher->get_qos(qos);
  qos.partition().clear();
  qos.partition().push_back(partition.c_str());
  return publisher->set_qos(qos) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
}

class SecurityTest : public ShoreFixture {
 protected:
  void SetUp() override {
    pki_ = make_temp_dir();
    make_pki("--wearable ann", pki_, "alpha bravo");
    // charlie: a certificate that expired in 2020, signed by the same fleet CA.
    make_pki("--start 20200101000000Z --end 20200102000000Z", pki_, "charlie");
    if (HasFatalFailure()) return;
    ShoreFixture::SetUp();
  }
  void TearDown() override {
    ShoreFixture::TearDown();
    std::filesystem::remove_all(pki_);
  }
  std::vector<std::string> shore_flags() const override {
    if (!secured_shore_) return {};
    return {"--security-dir", pki_ + "/shore"};
  }

  /// A boat_node with the certificate folder of `cert` (none: unsecured).
  Process& start_node(const std::string& id, const std::string& cert) {
    std::vector<std::string> extra = {"--log-dir", dir_ + "/log-" + id};
    if (!cert.empty()) {
      extra.push_back("--security-dir");
      extra.push_back(pki_ + "/" + cert);
    }
    return start_boat(id, extra);
  }

  /// A boat_node expected to stop by itself: its exit status (-1 if still running after 20 s).
  int run_refused_node(const std::string& id, const std::string& cert) {
    Process p({bin_dir() + "/boat_node", "--domain", std::to_string(domain_), "--boat-id", id,
               "--log-dir", dir_ + "/log-" + id, "--security-dir", pki_ + "/" + cert});
    const auto deadline = Clock::now() + seconds(20);
    while (p.running() && Clock::now() < deadline) std::this_thread::sleep_for(milliseconds(50));
    if (p.running()) return -1;
    return p.stop(SIGTERM);
  }

  bool listed_with_data(const std::string& id) {
    const auto boats = boats_by_id();
    const auto it = boats.find(id);
    return it != boats.end() && it->second["heel_deg"].is_number() &&
           it->second["samples_received"].get<int>() > 10;
  }

  /// Seconds from now until boat `id` (started by `start`) is listed with data.
  template <class Start>
  double join_time_s(const std::string& id, Start start) {
    const auto t0 = Clock::now();
    start();
    EXPECT_TRUE(eventually([&] { return boats_by_id().count(id) > 0; }, seconds(20)));
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

  /// Captures this domain's loopback traffic while `start` starts boats, until `listed` holds
  /// and 3 s more; the payloads.
  std::string capture_fleet(const std::function<void()>& start, const std::function<bool()>& listed,
                            int* foreign_out = nullptr) {
    LoopbackCapture capture(domain_);
    if (!capture.error().empty()) {
      ADD_FAILURE() << capture.error();
      return {};
    }
    start();
    EXPECT_TRUE(eventually(listed, seconds(20)));
    std::this_thread::sleep_for(seconds(3));
    std::vector<pid_t> fleet = {shore_->pid()};
    for (const auto& boat : boats_) fleet.push_back(boat->pid());
    const auto senders = udp_ports_of(fleet);
    int packets = 0;
    int foreign = 0;
    std::string payloads = capture.finish(senders, &packets, &foreign);
    EXPECT_GT(packets, 100) << "the capture saw almost nothing: it proves nothing";
    std::printf(
        "captured %d packets from the fleet's %zu UDP ports, %zu payload bytes, commonest "
        "datagram %zu bytes; %d datagrams in the domain's port range from other processes\n",
        packets, senders.size(), payloads.size(), capture.commonest_size(), foreign);
    if (foreign_out) *foreign_out = foreign;
    return payloads;
  }

  /// Stored sessions of `boat` (an empty array when it never reached the store).
  nlohmann::json sessions_of(const std::string& boat) const {
    return get_json("/api/v1/sessions?boat=" + boat);
  }

  std::string pki_;
  bool secured_shore_ = true;
};

TEST_F(SecurityTest, SecuredShoreListsTwoSecuredBoatsAndAWearableWithLiveData) {
  EXPECT_NE(shore_->output().find("dds_security=on"), std::string::npos) << shore_->output();
  const double join_s = join_time_s("alpha", [&] { start_node("alpha", "alpha"); });
  start_node("bravo", "bravo");
  Process wearable({bin_dir() + "/wearable_node", "--domain", std::to_string(domain_),
                    "--athlete-id", "ann", "--security-dir", pki_ + "/ann"});
  ASSERT_TRUE(eventually([&] { return listed_with_data("alpha") && listed_with_data("bravo"); },
                         seconds(20)))
      << get_json("/api/v1/boats").dump();
  const auto first = boats_by_id();
  std::this_thread::sleep_for(seconds(2));
  const auto second = boats_by_id();
  for (const char* id : {"alpha", "bravo"}) {
    EXPECT_GT(second.at(id)["seq"].get<std::uint64_t>(), first.at(id)["seq"].get<std::uint64_t>())
        << id;
    EXPECT_FALSE(second.at(id)["stale"].get<bool>()) << id;
  }
  EXPECT_TRUE(eventually(
      [&] {
        const auto athletes = get_json("/api/v1/athletes");
        return athletes.is_array() && athletes.size() == 1 && athletes[0]["id"] == "ann";
      },
      seconds(20)))
      << get_json("/api/v1/athletes").dump();
  std::printf("secured join (boat start -> listed at shore): %.2f s\n", join_s);
  RecordProperty("secured_join_ms", static_cast<int>(join_s * 1000));
}

TEST_F(SecurityTest, UnauthenticatedParticipantCanNeitherReadNorInject) {
  start_node("alpha", "alpha");
  start_node("intruder", "");  // plain boat_node, no certificate
  // A plain DDS reader in this process, on every partition and the default one. The listener is
  // declared first so that it outlives the participant: locals are destroyed in reverse order,
  // and Fast DDS may still deliver a sample while ~Participant deletes the reader (seen once
  // under ASan: the receive thread called through the destroyed listener's vtable).
  CountingListener counter;
  dds::DdsOptions options;
  options.domain = domain_;
  options.subscriber_partitions = {"*", ""};
  dds::Participant spy(options, "spy");
  spy.reader(
      spy.topic(dds::kTopicBoatAttitude, fdds::TypeSupport(new msg::BoatAttitudePubSubType())),
      "attitude_reader", &counter);
  ASSERT_TRUE(eventually([&] { return listed_with_data("alpha"); }, seconds(20)));
  // The reader works (it hears the unsecured intruder) yet gets nothing of alpha's while the
  // secured shore does.
  ASSERT_TRUE(eventually([&] { return counter.intruder_samples > 20; }, seconds(20)))
      << "the plain reader did not even hear the plain boat: the test proves nothing";
  std::this_thread::sleep_for(seconds(3));
  EXPECT_EQ(counter.other_samples, 0);
  EXPECT_TRUE(listed_with_data("alpha"));
  // The intruder's data never reaches the shore's REST API.
  EXPECT_EQ(boats_by_id().count("intruder"), 0u) << get_json("/api/v1/boats").dump();
  const auto sessions = sessions_of("intruder");
  EXPECT_TRUE(sessions.is_array() && sessions.empty()) << sessions.dump();
}

TEST_F(SecurityTest, BoatCertificateCannotPublishAsAnotherBoat) {
  // 1. boat_node with alpha's certificate and bravo's id: refused at startup by Fast DDS's access
  // control (bravo's partition is not in alpha's signed permissions).
  EXPECT_EQ(run_refused_node("bravo", "alpha"), 1);

  // 2. A forger that keeps to alpha's partition but writes bravo's id (a modified node): the shore
  // drops those samples. alpha's own samples from the same writer get through (control).
  Forger forger(domain_, pki_ + "/alpha", "alpha");
  bool alpha_seen = false;
  forger.write_for({"alpha", "bravo"}, seconds(20), [&] {
    const auto boats = boats_by_id();
    EXPECT_EQ(boats.count("bravo"), 0u) << get_json("/api/v1/boats").dump();
    if (boats.count("alpha") == 0) return false;
    if (alpha_seen) return true;  // one more second of forged samples after the control passed
    alpha_seen = true;
    return false;
  });
  EXPECT_TRUE(alpha_seen) << "the forger's writer never reached the shore: the test proves nothing";
  EXPECT_EQ(boats_by_id().count("bravo"), 0u);
  const auto sessions = sessions_of("bravo");
  EXPECT_TRUE(sessions.is_array() && sessions.empty()) << sessions.dump();
}

// 3. A node that creates its writer in its own partition and then moves the publisher to
// bravo's partition (PARTITION is changeable, and Fast DDS checks the permissions when the writer
// is created) still never gets bravo to the shore.
TEST_F(SecurityTest, PartitionSwitchAfterCreationCannotPublishAsAnotherBoat) {
  Forger forger(domain_, pki_ + "/alpha", "alpha");
  // Control: the writer reaches the shore as alpha.
  forger.write_for({"alpha"}, seconds(20), [&] { return boats_by_id().count("alpha") > 0; });
  ASSERT_EQ(boats_by_id().count("alpha"), 1u);
  const bool switched =
      move_to_partition(forger.writer, dds::node_partition(pki_ + "/alpha", "bravo"));
  const auto alpha_before = boats_by_id()["alpha"]["seq"].get<std::uint64_t>();
  forger.write_for({"alpha", "bravo"}, seconds(6), [] { return false; });
  const auto boats = boats_by_id();
  EXPECT_EQ(boats.count("bravo"), 0u) << get_json("/api/v1/boats").dump();
  const auto sessions = sessions_of("bravo");
  EXPECT_TRUE(sessions.is_array() && sessions.empty()) << sessions.dump();
  std::printf("partition switch accepted locally: %s; alpha samples after it: %llu\n",
              switched ? "yes" : "no",
              static_cast<unsigned long long>(boats.at("alpha")["seq"].get<std::uint64_t>() -
                                              alpha_before));
}

// 4. The same switch before the shore has discovered the writer: Fast DDS's access control
// checks the partitions the writer is first announced with against its signed permissions and
// never matches it (the shore's check alone would accept bravo in bravo's partition).
TEST_F(SecurityTest, PartitionSwitchBeforeDiscoveryIsNeverMatched) {
  Forger forger(domain_, pki_ + "/alpha", "alpha");
  ASSERT_TRUE(move_to_partition(forger.writer, dds::node_partition(pki_ + "/alpha", "bravo")));
  forger.write_for({"bravo"}, seconds(8), [] { return false; });
  EXPECT_EQ(boats_by_id().count("bravo"), 0u) << get_json("/api/v1/boats").dump();
  const auto sessions = sessions_of("bravo");
  EXPECT_TRUE(sessions.is_array() && sessions.empty()) << sessions.dump();
}

TEST_F(SecurityTest, ExpiredCertificateIsRefused) {
  start_node("alpha", "alpha");
  ASSERT_TRUE(eventually([&] { return listed_with_data("alpha"); }, seconds(20)));
  EXPECT_EQ(run_refused_node("charlie", "charlie"), 1);
  EXPECT_EQ(boats_by_id().count("charlie"), 0u) << get_json("/api/v1/boats").dump();
}

/// Sends one datagram holding `text` over loopback from port `from` to port `to` (another
/// process's traffic, as the capture sees it). False if it could not.
bool send_datagram(std::uint16_t from, std::uint16_t to, const std::string& text) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(from);
  bool ok = bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  a.sin_port = htons(to);
  ok = ok && sendto(fd, text.data(), text.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a) ==
                 static_cast<ssize_t>(text.size());
  close(fd);
  return ok;
}

TEST_F(SecurityTest, LoopbackCaptureShowsNoPlaintextBoatId) {
  int foreign = 0;
  const std::string payloads = capture_fleet(
      [&] {
        start_node("alpha", "alpha");
        start_node("bravo", "bravo");
        // Control: an unsecured process elsewhere naming alpha from a port in this domain's
        // range (the range is in the kernel's ephemeral one; CI once caught exactly that from a
        // parallel test) is not the fleet's wire. Participant ports are base + 10 + 2 i (+1),
        // so base + 240 is a participant this test never has.
        const auto base = static_cast<std::uint16_t>(7400 + 250 * domain_);
        EXPECT_TRUE(send_datagram(base + 240, base + 241, "alpha bravo, in clear"));
      },
      [&] { return listed_with_data("alpha") && listed_with_data("bravo"); }, &foreign);
  ASSERT_FALSE(payloads.empty());
  EXPECT_GE(foreign, 1) << "the control datagram was not seen: the capture's filter is untested";
  EXPECT_EQ(payloads.find("alpha"), std::string::npos);
  EXPECT_EQ(payloads.find("bravo"), std::string::npos);
  // The partition tag does travel in clear (in the permissions document of the handshake): a
  // keyed hash, not the id. Reported, not asserted.
  const auto tag = dds::fleet_tag(pki_ + "/alpha", "alpha");
  std::printf("alpha's tag %s in clear: %s\n", tag.c_str(),
              payloads.find(tag) != std::string::npos ? "yes" : "no");
}

class UnsecuredCaptureTest : public SecurityTest {
 protected:
  void SetUp() override {
    secured_shore_ = false;
    SecurityTest::SetUp();
  }
};

// Control for the capture: the same fleet unsecured does show the boat ids, so the capture works.
TEST_F(UnsecuredCaptureTest, LoopbackCaptureShowsBoatIdWhenUnsecured) {
  EXPECT_NE(shore_->output().find("dds_security=off"), std::string::npos) << shore_->output();
  double join_s = 0;
  const std::string payloads = capture_fleet(
      [&] {
        join_s = join_time_s("alpha", [&] { start_node("alpha", ""); });
        start_node("bravo", "");
      },
      [&] { return listed_with_data("alpha") && listed_with_data("bravo"); });
  EXPECT_NE(payloads.find("alpha"), std::string::npos);
  EXPECT_NE(payloads.find("bravo"), std::string::npos);
  std::printf("unsecured join (boat start -> listed at shore): %.2f s\n", join_s);
  RecordProperty("unsecured_join_ms", static_cast<int>(join_s * 1000));
}

}  // namespace
}  // namespace telltale::testing

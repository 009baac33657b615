#include "netns.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <regex>

namespace telltale::testing {

namespace {

constexpr int kDelayQueue = 7;

/// Where a program lives: the first PATH entry (plus the sbin folders root has) holding it.
std::string which(const std::string& name) {
  std::string path = "/usr/sbin:/usr/bin:/sbin:/bin";
  if (const char* env = std::getenv("PATH")) path = std::string(env) + ":" + path;
  for (std::size_t start = 0; start <= path.size();) {
    const std::size_t colon = std::min(path.find(':', start), path.size());
    const auto candidate = std::filesystem::path(path.substr(start, colon - start)) / name;
    if (colon > start && access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = colon + 1;
  }
  throw NetnsError(name + " not found (deploy/packages.txt lists the package)");
}

const std::string& ip_bin() {
  static const std::string path = which("ip");
  return path;
}

}  // namespace

std::string run_command(const std::vector<std::string>& argv) {
  Process p(argv);
  const int status = p.stop(0, std::chrono::seconds(20));  // signal 0: only wait for the exit
  std::string joined;
  for (const auto& a : argv) joined += a + " ";
  if (status != 0)
    throw NetnsError("command failed (status " + std::to_string(status) + "): " + joined + "\n" +
                     p.output());
  return p.output();
}

NetnsFleet::NetnsFleet(int boats) {
  if (geteuid() != 0)
    throw NetnsError("namespace tests need root (ip netns, veth, iptables); CI runs as root");
  remove_orphans();
  prefix_ = "ttn" + std::to_string(getpid());
  shore_ns_ = prefix_ + "s";
  try {
    build(boats);
  } catch (...) {
    // A half-built fleet has no destructor run: its namespaces go now, not at the next run's
    // orphan sweep (which a machine that never runs the tests again would not have).
    remove_created();
    throw;
  }
}

void NetnsFleet::build(int boats) {
  run_command({ip_bin(), "netns", "add", shore_ns_});
  created_.push_back(shore_ns_);
  run_command({ip_bin(), "-n", shore_ns_, "link", "set", "lo", "up"});
  run_command({ip_bin(), "-n", shore_ns_, "link", "add", "br0", "type", "bridge"});
  run_command(
      {ip_bin(), "-n", shore_ns_, "addr", "add", std::string(kShoreIp) + "/24", "dev", "br0"});
  run_command({ip_bin(), "-n", shore_ns_, "link", "set", "br0", "up"});
  for (int i = 0; i < boats; ++i) {
    const std::string ns = prefix_ + "b" + std::to_string(i);
    const std::string peer = "vb" + std::to_string(i);
    const std::string addr = "10.77.0." + std::to_string(10 + i);
    run_command({ip_bin(), "netns", "add", ns});
    created_.push_back(ns);
    // Both ends are created directly in their namespaces: no name ever exists on the host.
    run_command({ip_bin(), "link", "add", peer, "netns", shore_ns_, "type", "veth", "peer", "name",
                 "eth0", "netns", ns});
    run_command({ip_bin(), "-n", shore_ns_, "link", "set", peer, "master", "br0"});
    run_command({ip_bin(), "-n", shore_ns_, "link", "set", peer, "up"});
    run_command({ip_bin(), "-n", ns, "link", "set", "lo", "up"});
    run_command({ip_bin(), "-n", ns, "addr", "add", addr + "/24", "dev", "eth0"});
    run_command({ip_bin(), "-n", ns, "link", "set", "eth0", "up"});
    boat_ns_.push_back(ns);
    boat_ip_.push_back(addr);
  }
  for (const auto& ns : created_) {
    iptables(ns, {"-A", "INPUT", "-d", "224.0.0.0/4", "-j", "DROP"});
    iptables(ns, {"-A", "OUTPUT", "-d", "224.0.0.0/4", "-j", "DROP"});
  }
}

NetnsFleet::~NetnsFleet() {
  delays_.clear();  // stops the delay helpers (their SIGTERM releases what they hold)
  remove_created();
}

void NetnsFleet::remove_created() {
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    try {
      run_command({ip_bin(), "netns", "del", *it});
    } catch (const std::exception&) {
      // Best effort: the orphan sweep of the next run removes what is left.
    }
  }
}

void NetnsFleet::remove_orphans() {
  const std::regex name(R"(ttn(\d+)[sb]\d*)");
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/run/netns", ec)) {
    std::smatch m;
    const std::string n = e.path().filename().string();
    if (!std::regex_match(n, m, name)) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(m[1]));
    if (kill(pid, 0) != 0 && errno == ESRCH) {
      try {
        run_command({ip_bin(), "netns", "del", n});
      } catch (const std::exception&) {
      }
    }
  }
}

std::vector<std::string> NetnsFleet::in_ns(const std::string& ns, std::vector<std::string> argv) {
  std::vector<std::string> out = {ip_bin(), "netns", "exec", ns};
  for (auto& a : argv) out.push_back(std::move(a));
  return out;
}

void NetnsFleet::enter_ns(const std::string& ns) {
  const std::string path = "/run/netns/" + ns;
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw NetnsError("cannot open " + path + ": " + std::strerror(errno));
  const int rc = setns(fd, CLONE_NEWNET);
  close(fd);
  if (rc != 0) throw NetnsError("setns " + ns + ": " + std::strerror(errno));
}

void NetnsFleet::iptables(const std::string& ns, std::vector<std::string> rule) {
  rule.insert(rule.begin(), which("iptables"));
  run_command(in_ns(ns, std::move(rule)));
}

void NetnsFleet::cut_link(int i) {
  run_command({ip_bin(), "-n", shore_ns_, "link", "set", "vb" + std::to_string(i), "down"});
}

void NetnsFleet::restore_link(int i) {
  run_command({ip_bin(), "-n", shore_ns_, "link", "set", "vb" + std::to_string(i), "up"});
}

namespace {
std::vector<std::string> loss_rule(const char* op, const char* chain, double p) {
  return {op,   chain, "-m", "statistic", "--mode", "random", "--probability", std::to_string(p),
          "-j", "DROP"};
}
}  // namespace

void NetnsFleet::set_loss(int i, double p) {
  loss_.resize(boat_ns_.size(), 0.0);
  iptables(boat_ns(i), loss_rule("-A", "INPUT", p));
  iptables(boat_ns(i), loss_rule("-A", "OUTPUT", p));
  loss_[idx(i)] = p;
}

void NetnsFleet::clear_loss(int i) {
  const double p = loss_.at(idx(i));
  iptables(boat_ns(i), loss_rule("-D", "INPUT", p));
  iptables(boat_ns(i), loss_rule("-D", "OUTPUT", p));
}

void NetnsFleet::set_delay(int i, int delay_ms) {
  delays_.resize(boat_ns_.size());
  auto& helper = delays_[idx(i)];
  helper = std::make_unique<Process>(
      in_ns(boat_ns(i), {bin_dir() + "/nfq_delay", "--queue", std::to_string(kDelayQueue),
                         "--delay-ms", std::to_string(delay_ms)}));
  if (!helper->wait_for_line("nfq_delay ready", std::chrono::seconds(10)))
    throw NetnsError("nfq_delay did not start: " + helper->output());
  iptables(boat_ns(i), {"-A", "OUTPUT", "-o", "eth0", "-j", "NFQUEUE", "--queue-num",
                        std::to_string(kDelayQueue)});
}

std::string NetnsFleet::clear_delay(int i) {
  iptables(boat_ns(i), {"-D", "OUTPUT", "-o", "eth0", "-j", "NFQUEUE", "--queue-num",
                        std::to_string(kDelayQueue)});
  auto& helper = delays_.at(idx(i));
  helper->stop(SIGTERM);
  auto line = helper->wait_for_line("nfq_delay stopped", std::chrono::seconds(1));
  const std::string out = line ? *line : helper->output();
  helper.reset();
  return out;
}

void NetnsFleet::change_ip(int i, const std::string& new_ip) {
  // Old one first: deleting a primary address also deletes the secondaries of its subnet.
  run_command({ip_bin(), "-n", boat_ns(i), "addr", "del", boat_ip(i) + "/24", "dev", "eth0"});
  run_command({ip_bin(), "-n", boat_ns(i), "addr", "add", new_ip + "/24", "dev", "eth0"});
  boat_ip_[idx(i)] = new_ip;
}

}  // namespace telltale::testing

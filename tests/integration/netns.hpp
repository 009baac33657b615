#pragma once
/// \file
/// Hosts for fault tests: a shore and N boats, each in a network namespace of its own, joined by
/// veth pairs to a bridge in the shore's namespace (10.77.0.0/24: shore .1, boat i .10+i). The
/// addresses exist only inside these namespaces: nothing is routed to or from the host, and two
/// test processes may use the same subnet without seeing each other. Names carry the test's pid.
///
/// Multicast (224.0.0.0/4) is dropped in and out of every namespace, so discovery must work by
/// unicast. Faults: link cut (the shore-side veth down), random loss (iptables statistic match in
/// the boat's namespace, both directions), delay (NFQUEUE to tests/tools/nfq_delay on the boat's
/// egress: the kernel here has no sch_netem), address change. The destructor removes every
/// namespace (which takes the veths, bridge and iptables rules with it), also after a failure.
/// Needs root (CAP_NET_ADMIN + CAP_SYS_ADMIN): the constructor throws a clear error otherwise.

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "process.hpp"

namespace telltale::testing {

class NetnsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Runs a command (argv, no shell); throws NetnsError with its output if it fails.
std::string run_command(const std::vector<std::string>& argv);

class NetnsFleet {
 public:
  static constexpr const char* kShoreIp = "10.77.0.1";

  /// Creates the shore namespace and `boats` boat namespaces. Throws NetnsError.
  explicit NetnsFleet(int boats);
  ~NetnsFleet();
  NetnsFleet(const NetnsFleet&) = delete;
  NetnsFleet& operator=(const NetnsFleet&) = delete;

  [[nodiscard]] const std::string& shore_ns() const { return shore_ns_; }
  [[nodiscard]] const std::string& boat_ns(int i) const { return boat_ns_.at(idx(i)); }
  /// The boat's current address.
  [[nodiscard]] const std::string& boat_ip(int i) const { return boat_ip_.at(idx(i)); }

  /// `argv` prefixed to run inside namespace `ns`.
  static std::vector<std::string> in_ns(const std::string& ns, std::vector<std::string> argv);

  /// Runs `fn` on a thread that has entered `ns` (sockets it opens live there) and returns its
  /// result: how the test, in the host namespace, speaks HTTP to a shore inside one.
  template <class Fn>
  static auto call_in_ns(const std::string& ns, Fn fn) -> decltype(fn()) {
    decltype(fn()) result{};
    std::exception_ptr error;
    std::thread t([&] {
      try {
        enter_ns(ns);
        result = fn();
      } catch (...) {
        error = std::current_exception();
      }
    });
    t.join();
    if (error) std::rethrow_exception(error);
    return result;
  }

  // --- faults (boat i) -------------------------------------------------------------------
  void cut_link(int i);
  void restore_link(int i);
  /// Drops each packet in and out of the boat with probability `p`.
  void set_loss(int i, double p);
  void clear_loss(int i);
  /// Holds every packet the boat sends for `delay_ms` (starts nfq_delay in the boat's namespace).
  void set_delay(int i, int delay_ms);
  /// Removes the delay; returns nfq_delay's closing line (packets held, hold times).
  std::string clear_delay(int i);
  /// Moves the boat to a new address on the same subnet (the old one is removed).
  void change_ip(int i, const std::string& new_ip);

 private:
  static void enter_ns(const std::string& ns);
  [[nodiscard]] std::size_t idx(int i) const { return static_cast<std::size_t>(i); }
  void iptables(const std::string& ns, std::vector<std::string> rule);
  /// Deletes namespaces left by test processes that no longer exist (a crashed earlier run).
  static void remove_orphans();
  /// The namespaces and links of the constructor, one step each (throws NetnsError).
  void build(int boats);
  /// Deletes every namespace created, newest first (best effort).
  void remove_created();

  std::string prefix_;
  std::string shore_ns_;
  std::vector<std::string> boat_ns_;
  std::vector<std::string> boat_ip_;
  std::vector<std::unique_ptr<Process>> delays_;
  std::vector<double> loss_;
  std::vector<std::string> created_;
};

}  // namespace telltale::testing

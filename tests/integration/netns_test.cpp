// Faults across hosts: the shore and each boat in a network namespace of their
// own, multicast dropped everywhere (discovery by unicast initial peers, profile telltale_lan),
// real shore_server and boat_node processes. After each fault: the shore's recording holds every
// sample the boat published (seq 1..N, each once), the live view shows fresh data again without
// restarting anything, and a boat that went silent was marked stale meanwhile.
// Needs root; fails (never skips) without it.
#include "netns.hpp"

#include <signal.h>
#include <sqlite3.h>

#include <cstdio>
#include <set>

#include "shore_fixture.hpp"
#include "stored_seqs.hpp"

namespace telltale::testing {
namespace {

using namespace std::chrono_literals;
using Steady = std::chrono::steady_clock;

std::uint64_t utc_now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

double seconds_since(Steady::time_point t) {
  return std::chrono::duration<double>(Steady::now() - t).count();
}

/// What one boat went through, for the assertions and the report.
struct Watch {
  std::string fault;
  bool seen_stale = false;
  double recovery_s = -1;   ///< link restored -> fresh, non-stale data on /api/v1/boats
  double caught_up_s = -1;  ///< link restored -> the store holds all but the newest 2.4 s
  long published = -1;
  long stored = -1;
};

class NetnsTest : public ShoreFixture {
 protected:
  void SetUp() override {
    dir_ = make_temp_dir();
    domain_ = unique_domain();
  }
  void TearDown() override {
    ShoreFixture::TearDown();  // processes first, then their namespaces
    fleet_.reset();
  }

  /// Namespaces, the shore and `boats` boats (ids nb0..), all on telltale_lan.
  void start_fleet(int boat_count) {
    try {
      fleet_ = std::make_unique<NetnsFleet>(boat_count);
    } catch (const std::exception& e) {
      FAIL() << e.what();
    }
    shore_ = std::make_unique<Process>(NetnsFleet::in_ns(
        fleet_->shore_ns(),
        {bin_dir() + "/shore_server", "--domain", std::to_string(domain_), "--http-port", "0",
         "--db", db_path(), "--coach-token", kCoachToken, "--dds-participant", "telltale_lan"}));
    const auto ready = shore_->wait_for_line("shore_server ready: ", 20s);
    ASSERT_TRUE(ready) << "shore did not start: " << shore_->output();
    std::smatch m;
    ASSERT_TRUE(std::regex_search(*ready, m, std::regex(R"(:(\d+)/)")));
    port_ = std::stoi(m[1]);
    for (int i = 0; i < boat_count; ++i) {
      boats_.push_back(std::make_unique<Process>(NetnsFleet::in_ns(
          fleet_->boat_ns(i),
          {bin_dir() + "/boat_node", "--domain", std::to_string(domain_), "--boat-id", id(i),
           "--log-dir", dir_ + "/log_" + id(i), "--dds-participant", "telltale_lan", "--dds-peer",
           NetnsFleet::kShoreIp})));
      ASSERT_TRUE(boats_.back()->wait_for_line("boat_node ready: ", 20s))
          << boats_.back()->output();
    }
    // Discovery by unicast peers only: every boat reaches the shore.
    ASSERT_TRUE(eventually(
        [&] { return fresh_boats(0).size() == static_cast<std::size_t>(boat_count); }, 40s))
        << "boats seen: " << boats().size();
  }

  static std::string id(int i) { return "nb" + std::to_string(i); }

  /// /api/v1/boats, asked from inside the shore's namespace.
  std::map<std::string, nlohmann::json> boats() const {
    return NetnsFleet::call_in_ns(fleet_->shore_ns(), [this] { return boats_by_id(); });
  }

  /// Boats that are not stale and whose latest sample is newer than `since_utc_ns`.
  std::set<std::string> fresh_boats(std::uint64_t since_utc_ns) const {
    std::set<std::string> out;
    for (const auto& [boat, b] : boats())
      if (!b["stale"].get<bool>() && b["t_utc_ns"].get<std::uint64_t>() > since_utc_ns)
        out.insert(boat);
    return out;
  }

  /// Polls /boats every 250 ms for `duration`, noting which boats were stale at some point.
  void watch_stale(std::vector<Watch>& w, std::chrono::milliseconds duration) const {
    const auto end = Steady::now() + duration;
    while (Steady::now() < end) {
      const auto b = boats();
      for (std::size_t i = 0; i < w.size(); ++i) {
        const auto it = b.find(id(static_cast<int>(i)));
        if (it != b.end() && it->second["stale"].get<bool>()) w[i].seen_stale = true;
      }
      std::this_thread::sleep_for(250ms);
    }
  }

  /// Waits until every boat shows fresh data again; fills recovery_s.
  void watch_recovery(std::vector<Watch>& w, std::uint64_t restored_utc_ns,
                      Steady::time_point restored, std::chrono::seconds timeout) const {
    const auto end = restored + timeout;
    while (Steady::now() < end) {
      const auto fresh = fresh_boats(restored_utc_ns);
      bool all = true;
      for (std::size_t i = 0; i < w.size(); ++i) {
        if (w[i].recovery_s < 0 && fresh.count(id(static_cast<int>(i))))
          w[i].recovery_s = seconds_since(restored);
        all = all && w[i].recovery_s >= 0;
      }
      if (all) return;
      std::this_thread::sleep_for(100ms);
    }
  }

  long stored_up_to(const std::string& boat, long max_seq) const {
    return stored_seqs(db_path(), boat, max_seq);
  }

  /// Waits until the shore holds (almost) everything each boat has sent so far (all but the
  /// newest 60 samples: the boats leave 2 s to the live path), noting when; then stops the boats
  /// (each drains its backlog) and compares: every seq 1..published stored once.
  void stop_and_check(std::vector<Watch>& w, Steady::time_point restored) {
    const auto deadline = restored + 120s;
    for (;;) {
      const auto b = boats();
      bool all = true;
      for (std::size_t i = 0; i < w.size(); ++i) {
        if (w[i].caught_up_s >= 0) continue;
        const std::string boat = id(static_cast<int>(i));
        const long settled = (b.count(boat) ? b.at(boat)["seq"].get<long>() : 0) - 60;
        if (settled > 0 && stored_up_to(boat, settled) >= settled)
          w[i].caught_up_s = seconds_since(restored);
        else
          all = false;
      }
      if (all || Steady::now() > deadline) break;
      std::this_thread::sleep_for(250ms);
    }
    for (const auto& x : w) EXPECT_GE(x.caught_up_s, 0) << x.fault << ": backfill did not catch up";
    for (std::size_t i = 0; i < w.size(); ++i) {
      Process& p = *boats_[i];
      EXPECT_EQ(p.stop(SIGINT, 20s), 0) << p.output();
      const auto line = p.wait_for_line("boat_node stopped: ", 1s);
      ASSERT_TRUE(line) << p.output();
      std::smatch m;
      ASSERT_TRUE(std::regex_search(*line, m, std::regex(R"(published=(\d+))")));
      w[i].published = std::stol(m[1]);
      EXPECT_NE(line->find("shore_has_all=yes"), std::string::npos) << w[i].fault << ": " << *line;
    }
    std::this_thread::sleep_for(1s);  // the shore's commit interval, with margin
    for (std::size_t i = 0; i < w.size(); ++i) {
      w[i].stored = stored_up_to(id(static_cast<int>(i)), w[i].published);
      EXPECT_EQ(w[i].stored, w[i].published)
          << w[i].fault << ": every sample stored; missing "
          << missing_seqs(db_path(), id(static_cast<int>(i)), w[i].published);
      EXPECT_GE(w[i].recovery_s, 0) << w[i].fault << ": live view did not recover";
    }
  }

  void report(const std::vector<Watch>& w) const {
    for (std::size_t i = 0; i < w.size(); ++i)
      std::printf(
          "[netns] %s %-16s published=%ld stored=%ld stale_seen=%s live_after_s=%.1f "
          "stored_after_s=%.1f\n",
          id(static_cast<int>(i)).c_str(), w[i].fault.c_str(), w[i].published, w[i].stored,
          w[i].seen_stale ? "yes" : "no", w[i].recovery_s, w[i].caught_up_s);
    std::fflush(stdout);
  }

  std::unique_ptr<NetnsFleet> fleet_;
};

// One fleet, five boats, five faults at once for 30 s: a cut link, 20 % and 30 % loss both ways,
// 200 ms delay on the boat's egress, and an address change (after which the fault is permanent).
TEST_F(NetnsTest, FaultsShareOneFleet) {
  ASSERT_NO_FATAL_FAILURE(start_fleet(5));
  std::vector<Watch> w = {
      {"link cut 30 s"}, {"loss 20 %"}, {"loss 30 %"}, {"delay 200 ms"}, {"address change"}};
  std::this_thread::sleep_for(3s);
  fleet_->cut_link(0);
  fleet_->set_loss(1, 0.2);
  fleet_->set_loss(2, 0.3);
  fleet_->set_delay(3, 200);
  watch_stale(w, 5s);
  fleet_->change_ip(4, "10.77.0.114");
  watch_stale(w, 25s);
  fleet_->restore_link(0);
  fleet_->clear_loss(1);
  fleet_->clear_loss(2);
  const std::string delay_line = fleet_->clear_delay(3);
  const std::uint64_t restored_utc = utc_now_ns();
  const auto restored = Steady::now();
  watch_recovery(w, restored_utc, restored, 60s);
  std::printf("[netns] %s\n", delay_line.c_str());
  std::smatch m;
  ASSERT_TRUE(std::regex_search(delay_line, m, std::regex(R"(packets=(\d+).*mean=([\d.]+))")))
      << delay_line;
  EXPECT_GT(std::stol(m[1]), 500) << "the delay line held the boat's traffic";
  EXPECT_GE(std::stod(m[2]), 199.0) << "each packet held 200 ms";
  EXPECT_TRUE(w[0].seen_stale) << "a cut boat is marked stale";
  stop_and_check(w, restored);
  report(w);
}

// The five-minute cut: longer than every DDS lease, so both sides forget each other and must
// rediscover by unicast peers alone; the boat's log carries 7 500 samples across.
TEST_F(NetnsTest, LinkCutFiveMinutes) {
  ASSERT_NO_FATAL_FAILURE(start_fleet(1));
  std::vector<Watch> w = {{"link cut 5 min"}};
  std::this_thread::sleep_for(3s);
  fleet_->cut_link(0);
  watch_stale(w, 300s);
  fleet_->restore_link(0);
  const std::uint64_t restored_utc = utc_now_ns();
  const auto restored = Steady::now();
  watch_recovery(w, restored_utc, restored, 60s);
  EXPECT_TRUE(w[0].seen_stale) << "a cut boat is marked stale";
  stop_and_check(w, restored);
  report(w);
  // Longer than the 60 s session gap: live data after the cut opened a second session, which the
  // backfill of the cut joins to the first again.
  const auto sessions = NetnsFleet::call_in_ns(
      fleet_->shore_ns(), [this] { return get_json("/api/v1/sessions?boat=nb0"); });
  ASSERT_TRUE(sessions.is_array());
  EXPECT_EQ(sessions.size(), 1u) << sessions.dump();
}

}  // namespace
}  // namespace telltale::testing

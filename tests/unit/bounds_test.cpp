// Issue 25, finding 8: the shore's per-boat resources are bounded and released. The receipt
// writer used to hold every (boat, run) it ever acknowledged until its 2000-instance limit, after
// which no new run got a receipt; the fleet model never forgot a boat.
#include <gtest/gtest.h>
#include <unistd.h>

#include "fleet.hpp"
#include "live_hub.hpp"
#include "shore_dds.hpp"

namespace telltale::shore {
namespace {

TEST(ReceiptBounds, MoreRunsThanTheWriterHoldsAllGetTheirReceipt) {
  dds::DdsOptions o;
  o.domain = 150 + static_cast<int>(::getpid() % 60);
  ShoreDds shore(o, FleetCallbacks{});
  // Twice what the writer can hold at once (its profile allows 4096 instances).
  const std::uint64_t runs = 2 * kMaxAckInstances;
  for (std::uint64_t run = 1; run <= runs; ++run) {
    const std::string boat = "b" + std::to_string(run % 40);
    ASSERT_TRUE(shore.publish_ack(boat, run, 10)) << "receipt of run " << run << " refused";
  }
  EXPECT_LE(shore.ack_instances(), kMaxAckInstances);
  // A receipt written again keeps its instance; the bound holds.
  EXPECT_TRUE(shore.publish_ack("b0", runs, 11));
  EXPECT_LE(shore.ack_instances(), kMaxAckInstances);
}

AttitudeSample sample(const std::string& id) {
  AttitudeSample s;
  s.boat_id = id;
  s.t_utc_ns = 1795300000ULL * 1000000000ULL;
  return s;
}

TEST(FleetBounds, SilentBoatsAreForgottenAndTheModelIsCapped) {
  FleetModel fleet(std::chrono::milliseconds(2000));
  const SteadyTime t0 = std::chrono::steady_clock::now();
  fleet.update(sample("old"), t0, 0);
  fleet.update(sample("new"), t0 + std::chrono::hours(5), 0);
  (void)fleet.set_alarm_state("alarm_only", "warn");  // known from a stored alarm, never heard
  const auto gone = fleet.forget(t0 + std::chrono::hours(7), std::chrono::hours(6));
  ASSERT_EQ(gone, std::vector<std::string>{"old"});
  EXPECT_FALSE(fleet.boat("old"));
  EXPECT_TRUE(fleet.boat("new"));
  EXPECT_TRUE(fleet.boat("alarm_only"));

  // A publisher inventing ids: the model stays at its cap, the longest silent going first.
  for (std::size_t i = 0; i < 3 * kMaxFleetEntries; ++i)
    fleet.update(sample("x" + std::to_string(i)),
                 t0 + std::chrono::hours(6) + std::chrono::milliseconds(i), 0);
  EXPECT_LE(fleet.boats().size(), kMaxFleetEntries);
  EXPECT_TRUE(fleet.boat("x" + std::to_string(3 * kMaxFleetEntries - 1)));
}

TEST(LiveHubBounds, ForgottenBoatsLeaveTheHub) {
  LiveHub hub(4, 16, std::chrono::milliseconds(10));
  auto c = hub.connect();
  hub.publish_sample("gone", [] { return std::string("{}"); });
  hub.forget("gone");
  bool closed = false;
  EXPECT_EQ(hub.wait(*c, std::chrono::milliseconds(50), closed), "");
}

}  // namespace
}  // namespace telltale::shore

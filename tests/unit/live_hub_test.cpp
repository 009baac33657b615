#include "live_hub.hpp"

#include <gtest/gtest.h>

#include <atomic>

namespace telltale::shore {
namespace {

using namespace std::chrono_literals;

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

// A slow client that has not read for a while gets only the latest sample per boat, and every
// event (up to the bound), never a backlog of samples.
TEST(LiveHub, SlowClientGetsLatestPerBoat) {
  LiveHub hub(4, 3);
  auto c = hub.connect();
  ASSERT_TRUE(c);
  for (int i = 0; i < 100; ++i) {
    hub.publish_sample("A", [i] { return "{\"v\":" + std::to_string(i) + "}"; });
    hub.publish_sample("B", [i] { return "{\"w\":" + std::to_string(i) + "}"; });
  }
  hub.publish_event("alarm", "{\"e\":1}", "A");
  bool closed = false;
  // Taken before the first batch: its next frame time is set inside that wait, so the second
  // batch comes at least one interval (40 ms) after this, however long the thread is preempted.
  const auto t0 = std::chrono::steady_clock::now();
  const std::string out = hub.wait(*c, 100ms, closed);
  EXPECT_FALSE(closed);
  EXPECT_EQ(count(out, "event: sample"), 2);
  EXPECT_NE(out.find("{\"v\":99}"), std::string::npos);
  EXPECT_NE(out.find("{\"w\":99}"), std::string::npos);
  EXPECT_EQ(count(out, "event: alarm"), 1);
  EXPECT_TRUE(hub.wait(*c, 1ms, closed).empty());
  // The next batch comes no sooner than one frame interval later, with only what changed.
  hub.publish_sample("B", [] { return std::string("{\"w\":100}"); });
  const std::string next = hub.wait(*c, 500ms, closed);
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 40ms);
  EXPECT_EQ(count(next, "event: sample"), 1);
  EXPECT_NE(next.find("{\"w\":100}"), std::string::npos);
}

// Given 100 samples of a boat published between two batches and two clients, then the frame is
// rendered once: not for the 99 samples no client sent, and not again for the second client.
TEST(LiveHub, FramesAreRenderedOnlyWhenSentAndOnceForAllClients) {
  LiveHub hub(4, 3);
  auto a = hub.connect();
  auto b = hub.connect();
  std::atomic<int> renders{0};
  for (int i = 0; i < 100; ++i) {
    hub.publish_sample("A", [i, &renders] {
      ++renders;
      return "{\"v\":" + std::to_string(i) + "}";
    });
  }
  EXPECT_EQ(renders.load(), 0) << "rendered before any client asked";
  bool closed = false;
  const std::string first = hub.wait(*a, 100ms, closed);
  const std::string second = hub.wait(*b, 100ms, closed);
  EXPECT_EQ(renders.load(), 1);
  EXPECT_EQ(first, second);
  EXPECT_NE(first.find("{\"v\":99}"), std::string::npos) << first;
}

TEST(LiveHub, EventOverflowIsReported) {
  LiveHub hub(4, 3);
  auto c = hub.connect();
  for (int i = 0; i < 5; ++i) hub.publish_event("alarm", std::to_string(i), "A");
  bool closed = false;
  const std::string out = hub.wait(*c, 100ms, closed);
  EXPECT_EQ(count(out, "event: alarm"), 3);
  EXPECT_NE(out.find("event: overflow\ndata: {\"dropped_events\":2}"), std::string::npos);
  EXPECT_EQ(out.find("data: 0\n"), std::string::npos);  // the oldest were dropped
}

TEST(LiveHub, BoundedClientsFilterAndClose) {
  LiveHub hub(2, 8);
  auto athlete = hub.connect(std::string("A"));
  auto coach = hub.connect();
  EXPECT_FALSE(hub.connect());  // full
  hub.publish_sample("B", [] { return std::string("{}"); });
  hub.publish_event("alarm", "{}", "B");
  bool closed = false;
  EXPECT_TRUE(hub.wait(*athlete, 50ms, closed).empty());
  EXPECT_EQ(count(hub.wait(*coach, 50ms, closed), "event:"), 2);
  hub.disconnect(coach);
  EXPECT_TRUE(hub.connect());
  hub.close();
  hub.wait(*athlete, 1s, closed);
  EXPECT_TRUE(closed);
  EXPECT_FALSE(hub.connect());
}

}  // namespace
}  // namespace telltale::shore

// The queue between pipeline threads: the newest item wins when full and the
// one it replaces comes back to be released; a waiting push loses nothing;
// close() wakes every waiter and refuses what comes after.
#include <chrono>
#include <optional>
#include <thread>

#include "camhead/base/bounded_queue.h"

#include <gtest/gtest.h>

namespace camhead::base {
namespace {

using namespace std::chrono_literals;

TEST(BoundedQueue, AFullQueueHandsBackItsOldestForTheNewest) {
  BoundedQueue<int> q(2);
  EXPECT_FALSE(q.push(1));
  EXPECT_FALSE(q.push(2));
  EXPECT_EQ(q.push(3), 1); // the caller releases what 1 holds and counts it
  EXPECT_EQ(q.pop(0ms), 2);
  EXPECT_EQ(q.pop(0ms), 3);
  EXPECT_FALSE(q.pop(1ms)) << "empty: times out";
}

TEST(BoundedQueue, AWaitingPushLosesNothing) {
  BoundedQueue<int> q(1);
  ASSERT_FALSE(q.push_waiting(0));
  std::thread producer([&] {
    for (int i = 1; i < 100; ++i)
      EXPECT_FALSE(q.push_waiting(i));
  });
  for (int i = 0; i < 100; ++i)
    EXPECT_EQ(q.pop(5s), i);
  producer.join();
}

TEST(BoundedQueue, CloseWakesWaitersAndRefusesLaterItems) {
  BoundedQueue<int> q(1);
  ASSERT_FALSE(q.push(7));
  std::optional<int> refused;
  std::thread producer([&] { refused = q.push_waiting(8); }); // full: waits
  std::this_thread::sleep_for(20ms);
  q.close();
  producer.join();
  EXPECT_EQ(refused, 8) << "a push waiting at close() gets its item back";
  EXPECT_EQ(q.push(9), 9);
  EXPECT_EQ(q.pop(0ms), 7) << "what was queued can still be taken";
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(q.pop(10s));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s) << "a closed, empty queue does not wait";
  EXPECT_TRUE(q.closed());
}

} // namespace
} // namespace camhead::base

// The frame loop allocates nothing (architecture.md): the queues between its
// threads take, drop and hand back items in slots made with the queue. The
// allocations of the thread that asks are counted while it asks
// (support/counting_new.h).
#include <chrono>

#include "camhead/base/bounded_queue.h"
#include "counting_new.h"

#include <gtest/gtest.h>

namespace camhead::base {
namespace {

using namespace std::chrono_literals;

// A move-only item, as a camera frame's lease is.
struct Item {
  explicit Item(int v) : value(v) {}
  Item(Item &&) = default;
  Item &operator=(Item &&) = default;
  int value;
};

TEST(BoundedQueueAllocations, PushingDroppingAndPoppingAllocateNothing) {
  BoundedQueue<Item> queue(3);
  static thread_local bool asking = false;
  asking = true;
  test::counting_new::start([] { return asking ? 0 : -1; });
  int dropped = 0, popped = 0;
  for (int i = 0; i < 1000; ++i) {
    dropped += queue.push(Item(i)) ? 1 : 0; // full from the fourth on: the oldest out
    if (i % 2 != 0)
      continue;
    popped += queue.pop(0ns) ? 1 : 0;
    if (i % 14 == 0) {
      (void)queue.push_waiting(Item(-i)); // there is room: the pop made it
      popped += queue.pop(0ns) ? 1 : 0;
    }
  }
  test::counting_new::stop();
  asking = false;
  EXPECT_EQ(test::counting_new::count(0), 0u);
  EXPECT_GT(dropped, 0) << "the full queue dropped its oldest";
  EXPECT_GT(popped, 0);
}

} // namespace
} // namespace camhead::base

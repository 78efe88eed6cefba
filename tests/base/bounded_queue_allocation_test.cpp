// The frame loop allocates nothing (architecture.md): the queues between its
// threads take, drop and hand back items in slots made with the queue. The
// global operator new of this test binary counts the allocations of the
// thread that asks, while it asks; every other test is unaffected.
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <new>

#include "camhead/base/bounded_queue.h"

#include <gtest/gtest.h>

namespace {

thread_local bool counting = false;
thread_local std::size_t allocations = 0;

} // namespace

void *operator new(std::size_t bytes) {
  if (counting)
    ++allocations;
  if (void *p = std::malloc(bytes > 0 ? bytes : 1))
    return p;
  throw std::bad_alloc();
}
void operator delete(void *p) noexcept {
  std::free(p);
}
void operator delete(void *p, std::size_t) noexcept {
  std::free(p);
}

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
  counting = true;
  allocations = 0;
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
  const std::size_t counted = allocations;
  counting = false;
  EXPECT_EQ(counted, 0u);
  EXPECT_GT(dropped, 0) << "the full queue dropped its oldest";
  EXPECT_GT(popped, 0);
}

} // namespace
} // namespace camhead::base

// A counting operator new for the allocation tests (architecture.md:
// nothing in the frame loop allocates). A test binary that links
// counting_new.cpp has every unaligned form of operator new and delete
// replaced: while counting, each allocation is counted in the bucket that
// the classifier names for the calling thread. Counted: C++ allocations,
// not the C library's malloc.
#pragma once

#include <cstdint>

namespace camhead::test::counting_new {

inline constexpr int kBuckets = 4;

// The bucket (0 .. kBuckets - 1) an allocation on the calling thread counts
// in, or -1 for none. Called inside operator new: it must not allocate.
using Classifier = int (*)();

// Zeroes the buckets and counts from now, by `classify`.
void start(Classifier classify);
// Stops counting; the buckets keep their counts.
void stop();
[[nodiscard]] std::uint64_t count(int bucket);

} // namespace camhead::test::counting_new

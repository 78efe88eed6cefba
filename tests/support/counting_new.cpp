// See counting_new.h. Every unaligned form is replaced, so that whatever the
// process allocates with one (a sanitizer's runtime, lavapipe's LLVM) it
// frees with its own kind; the aligned forms stay the library's, a matched
// pair.
#include "counting_new.h"

#include <array>
#include <atomic>
#include <cstdlib>
#include <new>

// GCC takes the replaced delete's free() for a mismatch with the new that it
// cannot see is replaced too.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

namespace camhead::test::counting_new {
namespace {

std::atomic<Classifier> classifier{nullptr};
std::array<std::atomic<std::uint64_t>, kBuckets> buckets{};

void *counted(std::size_t bytes) noexcept {
  if (const Classifier classify = classifier.load(std::memory_order_relaxed)) {
    const int bucket = classify();
    if (bucket >= 0 && bucket < kBuckets)
      buckets[std::size_t(bucket)].fetch_add(1, std::memory_order_relaxed);
  }
  return std::malloc(bytes == 0 ? 1 : bytes);
}

void *counted_or_throw(std::size_t bytes) {
  if (void *p = counted(bytes))
    return p;
  throw std::bad_alloc();
}

} // namespace

void start(Classifier classify) {
  for (auto &bucket : buckets)
    bucket = 0;
  classifier = classify;
}

void stop() {
  classifier = nullptr;
}

std::uint64_t count(int bucket) {
  return buckets.at(std::size_t(bucket)).load();
}

} // namespace camhead::test::counting_new

using camhead::test::counting_new::counted;
using camhead::test::counting_new::counted_or_throw;

void *operator new(std::size_t bytes) {
  return counted_or_throw(bytes);
}
void *operator new[](std::size_t bytes) {
  return counted_or_throw(bytes);
}
void *operator new(std::size_t bytes, const std::nothrow_t &) noexcept {
  return counted(bytes);
}
void *operator new[](std::size_t bytes, const std::nothrow_t &) noexcept {
  return counted(bytes);
}
void operator delete(void *p) noexcept {
  std::free(p);
}
void operator delete[](void *p) noexcept {
  std::free(p);
}
void operator delete(void *p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void *p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void *p, const std::nothrow_t &) noexcept {
  std::free(p);
}
void operator delete[](void *p, const std::nothrow_t &) noexcept {
  std::free(p);
}

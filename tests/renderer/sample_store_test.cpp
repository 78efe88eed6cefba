// The store of the last frames' samples (renderer/src/sample_store.h), on
// its own: frames of different sizes fill its ring, and a frame whose
// samples another has overwritten must not be moved again. Each sample here
// is the ray through its own pixel's centre, so that under the same lens it
// lands back where it was traced; its mixed radiance names its frame.
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/influence_region.h"
#include "sample_store.h"

#include <gtest/gtest.h>

namespace camhead::renderer::cpu {
namespace {

constexpr std::uint32_t kSize = 16; // pixels a side: four 8 x 8 tiles
constexpr float kFocalPx = 20.0f;

gpu::FrameParams camera() {
  gpu::FrameParams frame{};
  frame.cam_forward = {0.0f, 0.0f, -1.0f, 0.0f};
  frame.lens = {0.01f, 2.0f, kFocalPx, 1.0f}; // aperture radius, focus, f, a 1-px box
  frame.image = {kSize, kSize, 0u, 1u};
  return frame;
}

// The top-left tile: 64 pixels.
InfluenceRegion tile() {
  InfluenceRegion region;
  region.width = kSize;
  region.height = kSize;
  region.rects = {{0, 0, 8, 8}};
  return region;
}

// A frame of `per_pixel` samples a pixel of the tile, each the ray through
// its pixel's centre from the pupil's centre, its mixed radiance `id`.
void add(SampleStore &store, std::uint32_t per_pixel, float id) {
  const InfluenceRegion region = tile();
  const std::span<StoredSample> samples =
      store.add_frame(camera(), region, region.pixels() * per_pixel);
  ASSERT_EQ(samples.size(), region.pixels() * per_pixel);
  std::size_t s = 0;
  for (std::uint32_t y = 0; y < 8; ++y) // row by row, as the renderer keeps them
    for (std::uint32_t x = 0; x < 8; ++x)
      for (std::uint32_t k = 0; k < per_pixel; ++k) {
        const float tx = (float(x) + 0.5f - 0.5f * float(kSize)) / kFocalPx;
        const float ty = (0.5f * float(kSize) - float(y) - 0.5f) / kFocalPx;
        samples[s++] = {{tx, ty, 0.0f, 0.0f}, {id, 0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 2.0f}};
      }
}

// How many samples of each frame (by id) move into the same camera.
std::map<int, std::uint64_t> moved(SampleStore &store) {
  store.begin_reprojection(camera(), tile(), SampleStore::kMostFrames);
  std::map<int, std::uint64_t> by_frame;
  (void)store.reproject_rows(
      0, kSize, [&](std::size_t, const StoredSample &sample) { ++by_frame[int(sample.mixed.x)]; });
  return by_frame;
}

// The store holds 8 frames of 1 sample a pixel. Frames of 3, 3, 1, 2, 2, 2
// and 3 samples a pixel: the 4th and the 7th do not fit at the end and
// start again at 0, and when the 7th does, the oldest frame still listed
// (the 3rd, which the 4th left at the end) lies past its samples, while the
// 4th and 5th lie under them. Only the pixels whose every ray the tile
// traced take samples (sample_store.h): the 6 x 6 inside its edge.
TEST(SampleStore, AFrameOverwrittenAfterAWrapIsNotMovedAgain) {
  SampleStore store;
  store.reserve(8 * 64, kSize, kSize);
  const std::uint32_t per_pixel[] = {3, 3, 1, 2, 2, 2, 3};
  for (int frame = 0; frame < 7; ++frame)
    add(store, per_pixel[frame], float(frame + 1));
  const std::map<int, std::uint64_t> by_frame = moved(store);
  constexpr std::uint64_t kCovered = 36;
  EXPECT_EQ(by_frame.at(7), 3 * kCovered) << "the newest frame, each sample once";
  for (const auto &[id, count] : by_frame)
    EXPECT_LE(count, per_pixel[id - 1] * kCovered) << "frame " << id << ": moved twice";
  EXPECT_EQ(by_frame.count(4), 0u) << "overwritten by the 7th";
  EXPECT_EQ(by_frame.count(5), 0u) << "overwritten in part by the 7th";
}

// Without a wrap every frame that fits is moved, each sample once, newest
// first up to the store's size.
TEST(SampleStore, FramesThatFitAreEachMovedOnce) {
  SampleStore store;
  store.reserve(8 * 64, kSize, kSize);
  for (int frame = 0; frame < 4; ++frame)
    add(store, 2, float(frame + 1));
  const std::map<int, std::uint64_t> by_frame = moved(store);
  ASSERT_EQ(by_frame.size(), 4u);
  for (const auto &[id, count] : by_frame)
    EXPECT_EQ(count, 2 * 36u) << "frame " << id;
}

} // namespace
} // namespace camhead::renderer::cpu

// The Sobol' camera sampler's points (renderer/shaders/sampling.glsl),
// taken from the kernel itself: each pixel's own samples are a stratified,
// progressive set, and sample s of the pixels of an aligned block is a
// stratified set too, so that neighbours' single rays cover the aperture
// rather than clump, while every pixel's point stays uniform over passes.
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "cpu_kernel.h"

#include <gtest/gtest.h>

namespace camhead::renderer::cpu {
namespace {

using Points = std::vector<glm::vec2>;

// Whether `points` (2^m of them) are a (t, m, 2)-net in base 2: every
// dyadic box of area 2^(t-m), 2^a columns by 2^(m-t-a) rows for each a,
// holds exactly 2^t. A (0, m, 2)-net is as even as 2^m points can be.
bool is_net(const Points &points, int t = 0) {
  const int m = std::countr_zero(points.size());
  if (points.size() != std::size_t{1} << m || t > m)
    return false;
  for (int a = 0; a <= m - t; ++a) {
    const std::uint32_t columns = 1u << a, rows = 1u << (m - t - a);
    std::vector<int> hits(std::size_t(columns) * rows, 0);
    for (const glm::vec2 &p : points)
      ++hits[std::uint32_t(p.y * float(rows)) * columns + std::uint32_t(p.x * float(columns))];
    for (const int h : hits)
      if (h != 1 << t)
        return false;
  }
  return true;
}

glm::vec2 jitter(const glm::vec4 &q) {
  return {q.x, q.y};
}
glm::vec2 aperture(const glm::vec4 &q) {
  return {q.z, q.w};
}

// Sample s of every pixel of the `side` x `side` block at (x0, y0).
template <class Take>
Points block_points(CpuKernel &kernel, std::uint32_t x0, std::uint32_t y0, std::uint32_t side,
                    std::uint32_t s, std::uint32_t seed, Take take) {
  Points points;
  for (std::uint32_t y = y0; y < y0 + side; ++y)
    for (std::uint32_t x = x0; x < x0 + side; ++x)
      points.push_back(take(kernel.sobol_owen_4d(s, kernel.sobol_pixel_for(x, y, seed))));
  return points;
}

// The keys' short way to Sobol' dimension 1 is the sequence's own.
TEST(SobolKeys, DimensionOneInFiveShiftsIsTheSequences) {
  CpuKernel kernel;
  std::uint32_t i = 0;
  for (int k = 0; k < 100000; ++k, i = i * 2654435761u + 12345u) // every bit pattern's kind
    ASSERT_EQ(CpuKernel::bitfieldReverse(kernel.sobol_reversed_dimension_1(i)),
              kernel.sobol_u32_123(i).x)
        << "index " << i;
  for (i = 0; i < 4096; ++i)
    ASSERT_EQ(CpuKernel::bitfieldReverse(kernel.sobol_reversed_dimension_1(i)),
              kernel.sobol_u32_123(i).x)
        << "index " << i;
}

TEST(SobolKeys, OneRayAPixelOfAnAlignedBlockCoversTheApertureAndThePixelEvenly) {
  CpuKernel kernel;
  for (std::uint32_t seed = 1; seed <= 16; ++seed)
    for (const std::uint32_t side : {2u, 4u, 8u})
      for (const glm::uvec2 corner : {glm::uvec2(0, 0), glm::uvec2(8, 16), glm::uvec2(712, 568)})
        for (const std::uint32_t s : {0u, 1u, 6u, 200u}) {
          SCOPED_TRACE(::testing::Message() << "seed " << seed << ", block of " << side << " at "
                                            << corner.x << ", " << corner.y << ", sample " << s);
          EXPECT_TRUE(is_net(block_points(kernel, corner.x, corner.y, side, s, seed, aperture)));
          EXPECT_TRUE(is_net(block_points(kernel, corner.x, corner.y, side, s, seed, jitter)));
        }
}

// The jitter is Sobol' dimensions 0 and 1, a (0, m, 2)-net; the aperture
// dimensions 2 and 3, whose pair is a (1, m, 2)-net at the even m taken
// here (t is 2 at m = 3). An XOR key changes neither. (The count is no
// argument of the points, so a pixel's first n samples are its first n
// whatever the history's length.)
TEST(SobolKeys, EachPixelsFirstSamplesAreStratifiedWhateverTheirCount) {
  CpuKernel kernel;
  for (std::uint32_t seed = 1; seed <= 8; ++seed)
    for (const glm::uvec2 pixel : {glm::uvec2(0, 0), glm::uvec2(37, 11), glm::uvec2(719, 575)}) {
      const CpuKernel::SobolPixel keys = kernel.sobol_pixel_for(pixel.x, pixel.y, seed);
      for (const std::uint32_t n : {4u, 16u, 64u, 256u}) {
        Points apertures, jitters;
        for (std::uint32_t s = 0; s < n; ++s) {
          apertures.push_back(aperture(kernel.sobol_owen_4d(s, keys)));
          jitters.push_back(jitter(kernel.sobol_owen_4d(s, keys)));
        }
        SCOPED_TRACE(::testing::Message() << "seed " << seed << ", pixel " << pixel.x << ", "
                                          << pixel.y << ", " << n << " samples");
        EXPECT_TRUE(is_net(jitters));
        EXPECT_TRUE(is_net(apertures, 1));
      }
    }
}

// The CPU frame renderer hands the kernel a pass's points made once
// (cpu_kernel.h); read from the table or made where they are needed (past
// it, or in a pass of another seed), a pixel's samples are the same.
TEST(SobolKeys, APassesPointsFromTheTableAreThoseMadeWhereNeeded) {
  constexpr std::uint32_t kSeed = 77, kTable = 16;
  CpuKernel making;
  std::vector<glm::uvec4> table(kTable);
  for (std::uint32_t s = 0; s < kTable; ++s)
    table[s] = making.sobol_scrambled_point(s, kSeed);
  CpuKernel reading;
  reading.sobol_points = table.data();
  reading.sobol_points_count = kTable;
  reading.sobol_points_seed = kSeed;
  for (const std::uint32_t seed : {kSeed, kSeed + 1})
    for (std::uint32_t s = 0; s < 2 * kTable; ++s) {
      const CpuKernel::SobolPixel keys = making.sobol_pixel_for(5, 9, seed);
      EXPECT_EQ(reading.sobol_owen_4d(s, keys), making.sobol_owen_4d(s, keys))
          << "seed " << seed << ", sample " << s;
    }
  // A table that is not the pass's would show: one point altered is read.
  table[3] = glm::uvec4(0u);
  const CpuKernel::SobolPixel keys = making.sobol_pixel_for(5, 9, kSeed);
  EXPECT_NE(reading.sobol_owen_4d(3, keys), making.sobol_owen_4d(3, keys));
}

// Unbiased: over passes (seeds), a pixel's first ray is uniform over the
// aperture, whatever its place in the Z order; and the keys themselves,
// which the shared scramble would hide, favour no part of it either. A
// chi-square test on an 8 x 8 grid of 4096 passes; 103.4 is the 99.9th
// percentile of chi-square with 63 degrees of freedom, and the seeds are
// fixed, so the test is one draw, repeatable.
TEST(SobolKeys, APixelsFirstRayIsUniformOverTheAperture) {
  CpuKernel kernel;
  constexpr int kPasses = 4096, kCells = 64;
  auto chi2 = [](const std::array<int, kCells> &cells) {
    const double expected = double(kPasses) / kCells;
    double sum = 0.0;
    for (const int c : cells)
      sum += (c - expected) * (c - expected) / expected;
    return sum;
  };
  for (const glm::uvec2 pixel : {glm::uvec2(0, 0), glm::uvec2(3, 2), glm::uvec2(400, 301)}) {
    std::array<int, kCells> rays{}, keys{};
    for (std::uint32_t seed = 1; seed <= std::uint32_t(kPasses); ++seed) {
      const CpuKernel::SobolPixel sobol = kernel.sobol_pixel_for(pixel.x, pixel.y, seed);
      const glm::vec2 u = aperture(kernel.sobol_owen_4d(0, sobol));
      ++rays[std::size_t(int(u.y * 8.0f) * 8 + int(u.x * 8.0f))];
      ++keys[(sobol.shift.w >> 29) * 8 + (sobol.shift.z >> 29)]; // the aperture key's top 3 bits
    }
    EXPECT_LT(chi2(rays), 103.4) << "pixel " << pixel.x << ", " << pixel.y;
    EXPECT_LT(chi2(keys), 103.4) << "pixel " << pixel.x << ", " << pixel.y;
  }
}

} // namespace
} // namespace camhead::renderer::cpu

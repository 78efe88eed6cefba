// How a live frame accumulates (frame_history.h): the settings alone, free of
// the renderer's other headers, for the board reader.
#pragma once

#include <cstdint>

namespace camhead::renderer {

struct AccumulationSettings {
  bool enabled = false;
  // The largest movement, in pixels, of any point's blur circle or position
  // that keeps a history: below what a viewer can see (the blur follows a
  // focus pull within 0.1 px), above encoder noise after the lens chain's
  // filter and hold.
  double tolerance_px = 0.05;
  // Samples per pixel at which a history stops growing: from there a still
  // frame traces nothing (a 1024-rpp reference is only half as noisy).
  std::uint32_t max_samples = 256;
  // After a few samples everywhere, give each frame's rays to the pixels
  // whose samples disagree most (the blurred edges and shadows) rather than
  // to every pixel alike; and in a history's first frame of more than a ray
  // a pixel (nothing moved into it: a moving camera's every frame), after a
  // ray each, give the sharp pixels' rest to those whose neighbours' rays
  // disagree, the edges that one ray a pixel aliases
  // (renderer/src/ray_shares.h). Off, N still frames of k rays are exactly
  // one frame of N k rays (tests/renderer/frame_history_test.cpp); on, each
  // pixel holds its own count of samples of its own pattern. The CPU
  // reference's only, so far.
  bool share_by_noise = true;
  // Let each pixel borrow its neighbours' samples within a Gaussian of
  // sigma = strength sqrt(blur radius) / samples^(1/3) pixels, among
  // neighbours of alike blur (renderer/src/defocus_filter.h): at the
  // simulated rig's near focus a 1-rpp frame has less error than 9 rpp
  // (bench/RESULTS.md), at the price of about 2 strength^2 / samples^(2/3)
  // pixels of extra blur. Only the traced pixels take part, so with it (or
  // share_by_noise) on the influence region and the whole frame give
  // different (equally valid) estimates; the camera image outside the region
  // stays exact.
  bool reconstruct = true;
  double reconstruct_strength = 1.0;
  // A frame that starts a new history (the lens moved: a focus pull) starts
  // with the samples of the last frames that traced every pixel alike, each
  // moved to the pixel whose ray it is through the new focus, image scale
  // and aperture (renderer/src/sample_store.h: exact while the pose holds;
  // frames with a smaller aperture, another pose, or rays the old frame did
  // not trace are left out). Off, the first frame after a change carries
  // nothing of the frames before it. The CPU reference's only, so far.
  bool reproject = true;
  // At most this many frames' samples, fewer where the CPU reference's store
  // holds fewer (two pictures' worth: 13 frames of 1 rpp where the influence
  // region is 15 % of the picture, 9 where it is 22 %). 12 rather than 8
  // brings `camhead bench live`'s pull frame focused at 1.47 m from 1.12x
  // 9 rpp's error to par with it (0.98-1.03x over five seeds then, 0.96-1.00x
  // since the pixels' Sobol' keys), for about 1 ms a pull frame
  // (bench/RESULTS.md).
  std::uint32_t reproject_frames = 12;
  // The most reproject_frames means: the store keeps no more frames.
  static constexpr std::uint32_t kMostReprojectFrames = 16;
};

} // namespace camhead::renderer

// The adaptive ray budget's arithmetic (renderer/include/camhead/renderer/
// adaptive.h), written once for the GPU kernels adaptive_*.comp and the C++
// executor in renderer/src/adaptive.cpp, in kernel.glsl's common subset.
//
// The allocation is water-filling: pixel i gets n_i = clamp(lambda (w_i + F),
// k, cap) samples, which minimises sum sigma_i^2 / n_i for a fixed total when
// w_i estimates sigma_i; lambda is the level at which the n_i add up to the
// frame's budget. Finding lambda by bisection over every pixel would read the
// whole image forty times, so the weights are first counted into a
// logarithmic histogram (16 bins per octave, each with the mean position of
// its weights inside it) and lambda is found on the 4096 bins. The shares are
// then rounded up or down at random with the fraction as probability: the
// total is the budget in expectation (to within sqrt(pixels) / 2 samples), and
// no sort is needed.
//
// Expects: accum_aux_at() (the pilot's aux layer, layout.h), frame (FrameParams
// with tracing.y = k pilot samples, sampling.z = the mean budget per pixel,
// sampling.w = the seed, adaptive = the settings).

#include "sampling.glsl"

// Float bits >> 19 keep sign, exponent and 4 mantissa bits: 16 bins per
// octave, ADAPTIVE_BINS (layout.h) for the non-negative floats (weights are
// never negative).
#define ADAPTIVE_BIN_SHIFT 19u
// The next 8 mantissa bits place a weight inside its bin; their sum over a
// bin fits 32 bits for up to 16 M pixels.
#define ADAPTIVE_OFFSET_SHIFT 11u
#define ADAPTIVE_OFFSET_MASK 0xffu
// The weight every pixel has beyond its own, as a fraction of the image's
// mean luminance: pixels without variance still take a sliver, and a black
// image still has a water level.
#define ADAPTIVE_FLOOR_FRACTION 1e-3f
#define ADAPTIVE_FLOOR_ABSOLUTE 1e-12f
// Bisection on log2(lambda) in [-126, 126]: 40 halvings leave 2e-10.
#define ADAPTIVE_LOG2_LAMBDA_RANGE 126.0f
#define ADAPTIVE_BISECTION_STEPS 40

// The pixels that share the frame's budget: the influence region's
// (frame.adaptive.z), or all of them.
float adaptive_pixels() {
  return frame.adaptive.z > 0.0f ? frame.adaptive.z : float(frame.image.x) * float(frame.image.y);
}

// The pilot's per-sample mean and unbiased variance of one pixel's composite
// luminance, from its aux accumulator of n samples.
vec2 adaptive_moments(vec4 aux, float n) {
  float mean = aux.z / n;
  float variance = 0.0f;
  if (n > 1.0f) {
    variance = max(0.0f, aux.w / n - mean * mean) * n / (n - 1.0f);
  }
  return vec2(mean, variance);
}

// Pixel (x, y)'s weight, an estimate of the standard deviation of one of its
// samples: the largest pilot variance in its 3x3 neighbourhood (a pilot of a
// few samples misses edges that its neighbours catch), a quarter of the
// variance of the neighbourhood's samples pooled (which alone sees anything
// when the pilot is one sample), and a floor from the circle of confusion
// (a defocused pixel whose pilot happened to agree is not left at the
// minimum). Finite and non-negative.
float adaptive_weight(int x, int y) {
  int width = int(frame.image.x);
  int height = int(frame.image.y);
  float n = float(frame.tracing.y);
  float largest = 0.0f;
  float sum = 0.0f;
  float squares = 0.0f;
  float count = 0.0f;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      int nx = x + dx;
      int ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= width || ny >= height) {
        continue;
      }
      vec4 a = accum_aux_at(ny * width + nx);
      largest = max(largest, adaptive_moments(a, n).y);
      sum += a.z;
      squares += a.w;
      count += n;
    }
  }
  float pooled_mean = sum / count;
  float pooled = max(0.0f, squares / count - pooled_mean * pooled_mean);
  vec4 own = accum_aux_at(y * width + x);
  float mean = adaptive_moments(own, n).x;
  float inverse_depth = own.y > 0.0f ? own.y / own.x : 0.0f; // a miss is at infinity
  float coc_px = 0.0f;
  if (frame.lens.x > 0.0f) {
    coc_px = frame.lens.x * frame.lens.z * abs(inverse_depth - 1.0f / frame.lens.y);
  }
  float coc = frame.adaptive.x * abs(mean) * min(coc_px, 8.0f) / 8.0f;
  // abs: sqrt(-0) is -0, whose bits would land past the last bin.
  float w = abs(sqrt(largest + 0.25f * pooled + coc * coc));
  return w < 1e30f ? w : 1e30f; // also maps NaN, which no test render has
}

uint adaptive_bin(float w) {
  return floatBitsToUint(w) >> ADAPTIVE_BIN_SHIFT;
}

uint adaptive_bin_offset(float w) {
  return (floatBitsToUint(w) >> ADAPTIVE_OFFSET_SHIFT) & ADAPTIVE_OFFSET_MASK;
}

// The mean weight of the `count` weights in `bin` whose offsets add up to
// `offset_sum` (the half restores the mean of the bits dropped below).
float adaptive_bin_mean(uint bin, uint count, uint offset_sum) {
  float low = uintBitsToFloat(bin << ADAPTIVE_BIN_SHIFT);
  float unit = uintBitsToFloat((bin << ADAPTIVE_BIN_SHIFT) | (1u << ADAPTIVE_OFFSET_SHIFT)) - low;
  return low + (float(offset_sum) / float(count) + 0.5f) * unit;
}

// Samples the pixels of one bin get at water level lambda (overflow to
// infinity clamps to the cap).
float adaptive_bin_total(float mean_weight, uint count, float lambda, float floor_weight,
                         float pilot, float cap) {
  return float(count) * clamp(lambda * (mean_weight + floor_weight), pilot, cap);
}

// Pixel i's share: its water-filling target rounded down or up at random,
// up with the fraction as probability, and never past the cap.
uint adaptive_share(float w, uint i, float lambda, float floor_weight, float pilot, float cap) {
  float target = clamp(lambda * (w + floor_weight), pilot, cap);
  uint bits = hash_u32(i * 0x9e3779b1u ^ hash_u32(frame.sampling.w + 0x2545f491u));
  float u = float(bits >> 8) * (1.0f / 16777216.0f);
  return uint(min(floor(target + u), cap));
}

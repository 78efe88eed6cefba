// The adaptive second pass's queue (layout.h, "The adaptive second pass
// traces..."): the bin of a pixel's share of second-pass samples, and the
// pixel an invocation of a second-pass batch traces.
//
// Expects: frame (FrameParams of the second pass: tracing.y the pilot,
// adaptive.y the cap), queue_bins[], sample_queue[].
#ifndef CAMHEAD_SAMPLE_QUEUE_GLSL
#define CAMHEAD_SAMPLE_QUEUE_GLSL

// The bin of this frame's second-pass share `second_pass_samples` (layout.h).
uint queue_bin(uint second_pass_samples) {
  return QUEUE_BIN(second_pass_samples, frame.tracing.y, uint(frame.adaptive.y));
}

uint greatest_common_divisor(uint a, uint b) {
  while (b != 0u) {
    uint r = a % b;
    a = b;
    b = r;
  }
  return a;
}

// The stride by which the workgroups of a batch take the queue's runs of
// QUEUE_GROUP_PIXELS (queue_pixel): close to groups / golden ratio and
// coprime to `groups`, so that workgroup w taking run w x stride mod groups
// is a permutation that spreads any run of consecutive workgroups over the
// whole queue. llvmpipe hands each of its threads an equal run of a
// dispatch's workgroups (lp_cs_tpool.c); in queue order, largest shares
// first, one thread would get all the long pixels and the other wait. A GPU
// that hands out workgroups as its cores come free gains nothing and loses
// nothing.
uint queue_stride(uint groups) {
  uint stride = max(uint(0.618034f * float(groups)), 1u);
  while (greatest_common_divisor(stride, groups) > 1u) {
    ++stride; // ends by groups - 1 at the latest
  }
  return stride;
}

// (a b) mod m for a, b < m < 2^31, without 64-bit integers.
uint multiply_mod(uint a, uint b, uint m) {
  uint product = 0u;
  while (b != 0u) {
    if ((b & 1u) != 0u) {
      product += a;
      product = product >= m ? product - m : product;
    }
    a += a;
    a = a >= m ? a - m : a;
    b >>= 1u;
  }
  return product;
}

// The pixel this invocation traces in the second-pass batch of samples from
// `first` on, or -1. The pixels that may have samples there are the queue's
// first ones, those of the bins from that of first + 1 up.
int queue_pixel(uint first) {
  uint bin = queue_bin(first + 1u);
  uint pixels = queue_bins[QUEUE_ENDS + bin];
  uint groups = (pixels + QUEUE_GROUP_PIXELS - 1u) / QUEUE_GROUP_PIXELS;
  uint group = gl_WorkGroupID.y * QUEUE_ROW_GROUPS + gl_WorkGroupID.x;
  if (group >= groups) {
    return -1; // a spare of the last row
  }
  uint stride = queue_bins[QUEUE_DISPATCH + 4u * bin + 3u];
  uint place = multiply_mod(group, stride, groups) * QUEUE_GROUP_PIXELS + gl_LocalInvocationIndex;
  return place < pixels ? int(sample_queue[place]) : -1;
}

#endif

#version 450
// Adaptive allocation, step 4 of 5 (sample_queue.glsl): from the pixels in
// each bin of shares, where each bin's pixels start in the queue (largest
// shares first), how many pixels the bins from each one up hold, and an
// indirect dispatch over those with its stride. One workgroup; invocation t
// takes BINS_PER_THREAD bins in a row.
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "sample_queue.glsl"

#define QUEUE_BINS_THREADS 256u
#define BINS_PER_THREAD (QUEUE_BINS / QUEUE_BINS_THREADS)

layout(local_size_x = QUEUE_BINS_THREADS) in;

shared uint from_here_up[QUEUE_BINS_THREADS];

void main() {
  uint t = gl_LocalInvocationIndex;
  uint first_bin = t * BINS_PER_THREAD;
  uint own = 0u;
  for (uint j = 0u; j < BINS_PER_THREAD; ++j) {
    own += queue_bins[QUEUE_COUNTS + first_bin + j];
  }
  // A scan from the top bin down (Hillis and Steele): the pixels in this
  // invocation's bins and all above them.
  from_here_up[t] = own;
  barrier();
  for (uint step = 1u; step < QUEUE_BINS_THREADS; step *= 2u) {
    uint above = t + step < QUEUE_BINS_THREADS ? from_here_up[t + step] : 0u;
    barrier();
    from_here_up[t] += above;
    barrier();
  }
  uint end = from_here_up[t] - own; // the pixels of the bins above this invocation's
  for (int j = int(BINS_PER_THREAD) - 1; j >= 0; --j) {
    uint bin = first_bin + uint(j);
    uint count = queue_bins[QUEUE_COUNTS + bin];
    queue_bins[QUEUE_COUNTS + bin] = end; // adaptive_queue_fill's cursor
    end += count;
    queue_bins[QUEUE_ENDS + bin] = end;
    uint groups = (end + QUEUE_GROUP_PIXELS - 1u) / QUEUE_GROUP_PIXELS;
    uint dispatch = QUEUE_DISPATCH + 4u * bin;
    queue_bins[dispatch] = min(groups, QUEUE_ROW_GROUPS);
    queue_bins[dispatch + 1u] = (groups + QUEUE_ROW_GROUPS - 1u) / QUEUE_ROW_GROUPS;
    queue_bins[dispatch + 2u] = 1u;
    queue_bins[dispatch + 3u] = queue_stride(groups);
  }
}

// The GLSL side of layout.h: buffer declarations and the GLSL spelling of the
// vocabulary that kernel.glsl shares with C++ (renderer/src/cpu_kernel.h).
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

#define INOUT(T) inout T
#define OUT(T) out T
#define PRECISE precise
#define CAMHEAD_PI 3.14159265358979f

layout(constant_id = 0) const uint KERNEL_FEATURES = KERNEL_ALL; // layout.h

// The scene's geometry, read at every step of every traversal, is read
// through texel buffers rather than storage buffers: lavapipe (Mesa 22.3)
// loads a storage buffer at an index that differs between lanes one lane at
// a time, in a loop with a branch per lane and component (lp_bld_nir_soa.c,
// emit_load_mem), where a texel fetch is one gather (bench/RESULTS.md,
// "Where lavapipe's time goes"). Integer texels keep the bits of the
// integers that .w holds exactly.
layout(binding = BINDING_PRIMITIVES) uniform usamplerBuffer primitive_texels;
layout(binding = BINDING_NODES) uniform usamplerBuffer node_texels;

Primitive primitive_at(uint index) {
  int texel = int(index * PRIMITIVE_TEXELS);
  Primitive prim;
  prim.p0 = uintBitsToFloat(texelFetch(primitive_texels, texel));
  prim.p1 = uintBitsToFloat(texelFetch(primitive_texels, texel + 1));
  prim.p2 = uintBitsToFloat(texelFetch(primitive_texels, texel + 2));
  return prim;
}

BvhNode node_at(uint index) {
  int texel = int(index * NODE_TEXELS);
  BvhNode node;
  node.bmin = uintBitsToFloat(texelFetch(node_texels, texel));
  node.bmax = uintBitsToFloat(texelFetch(node_texels, texel + 1));
  return node;
}
layout(std430, binding = BINDING_MATERIALS) readonly buffer Materials { Material materials[]; };
layout(std430, binding = BINDING_LIGHTS) readonly buffer Lights { Light lights[]; };
layout(std140, binding = BINDING_FRAME) uniform Frame { FrameParams frame; };
layout(std430, binding = BINDING_ACCUM_MIXED) buffer AccumMixed { vec4 accum_mixed[]; };
layout(std430, binding = BINDING_ACCUM_REAL) buffer AccumReal { vec4 accum_real[]; };
layout(std430, binding = BINDING_ACCUM_AUX) buffer AccumAux { vec4 accum_aux[]; };
// The live frame's kernels write the plate (video_decode.comp) and read the
// composite (video_encode.comp); the others only read one and write the other.
#ifdef CAMHEAD_WRITES_PLATE
layout(std430, binding = BINDING_PLATE) writeonly buffer Plate { vec4 plate[]; };
#else
layout(std430, binding = BINDING_PLATE) readonly buffer Plate { vec4 plate[]; };
#endif
#ifdef CAMHEAD_READS_COMPOSITE
layout(std430, binding = BINDING_OUT_COMPOSITE) readonly buffer OutComposite { vec4 out_composite[]; };
#else
layout(std430, binding = BINDING_OUT_COMPOSITE) writeonly buffer OutComposite { vec4 out_composite[]; };
#endif
layout(std430, binding = BINDING_OUT_MIXED) writeonly buffer OutMixed { vec4 out_mixed[]; };
layout(std430, binding = BINDING_OUT_REAL) writeonly buffer OutReal { vec4 out_real[]; };
layout(std430, binding = BINDING_OUT_AUX) writeonly buffer OutAux { vec4 out_aux[]; };
layout(std430, binding = BINDING_OUT_DISPLAY) writeonly buffer OutDisplay { uint out_display[]; };
layout(std430, binding = BINDING_SAMPLE_COUNTS) buffer SampleCounts { uint sample_counts[]; };
layout(std430, binding = BINDING_ADAPTIVE_WEIGHTS) buffer AdaptiveWeights { float adaptive_weights[]; };
// Pairs per bin (count, offset sum), flat for atomicAdd.
layout(std430, binding = BINDING_ADAPTIVE_HISTOGRAM) buffer AdaptiveHistogram { uint adaptive_histogram[]; };
layout(std430, binding = BINDING_ADAPTIVE_GROUPS) buffer AdaptiveGroups { float adaptive_groups[]; };
layout(std430, binding = BINDING_ADAPTIVE_SOLUTION) buffer AdaptiveSolutionBuffer { AdaptiveSolution adaptive_solution; };
layout(std430, binding = BINDING_SAMPLE_QUEUE) buffer SampleQueue { uint sample_queue[]; };
layout(std430, binding = BINDING_QUEUE_BINS) buffer QueueBins { uint queue_bins[]; };
// Only the video kernels declare the video bindings: with them declared in
// trace.comp too, lavapipe (Mesa 22.3.6) traced the glass ball of
// light_transport_test 8 % too dark (0.852 against 0.923); the cause is not
// known, and the tracer has no use for them.
#if defined(CAMHEAD_WRITES_PLATE) || defined(CAMHEAD_READS_COMPOSITE)
layout(std140, binding = BINDING_VIDEO) uniform Video { VideoFrames video; };
layout(std430, binding = BINDING_VIDEO_IN) readonly buffer VideoIn { uint video_in[]; };
layout(std430, binding = BINDING_VIDEO_OUT) writeonly buffer VideoOut { uint video_out[]; };
#endif

// Index of this invocation's pixel, or -1 outside the image.
int pixel_index() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= frame.image.x || p.y >= frame.image.y) {
    return -1;
  }
  return int(p.y * frame.image.x + p.x);
}

// The GLSL side of layout.h: buffer declarations and the GLSL spelling of the
// vocabulary that kernel.glsl shares with C++ (renderer/src/cpu_kernel.h).
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

#define INOUT(T) inout T
#define OUT(T) out T
#define PRECISE precise
#define KERNEL_TABLE const // a constant array
#define CAMHEAD_PI 3.14159265358979f

layout(constant_id = 0) const uint KERNEL_FEATURES = KERNEL_ALL; // layout.h

// The scene (geometry, materials, lights) is read through texel buffers
// rather than storage buffers: lavapipe (Mesa 22.3) loads a storage buffer
// at an index that differs between lanes one lane and one component at a
// time, in a loop that inserts each word into the vector through the stack
// (lp_bld_nir_soa.c, emit_load_mem). A texel fetch is a gather. On an AMD
// Zen 3 every insert also stalls on store forwarding; the loop took half of
// a frame there (bench/RESULTS.md, "Where lavapipe's time goes" and
// "lavapipe on the AMD EPYC"). Integer texels keep the bits of the integers
// that .w holds exactly.
layout(binding = BINDING_PRIMITIVES) uniform usamplerBuffer primitive_texels;
layout(binding = BINDING_NODES) uniform usamplerBuffer node_texels;
layout(binding = BINDING_MATERIALS) uniform usamplerBuffer material_texels;
layout(binding = BINDING_LIGHTS) uniform usamplerBuffer light_texels;
layout(binding = BINDING_SURFACES) uniform usamplerBuffer surface_texels;

vec4 texel_at(usamplerBuffer texels, uint texel) {
  return uintBitsToFloat(texelFetch(texels, int(texel)));
}

Primitive primitive_at(uint index) {
  uint texel = index * PRIMITIVE_TEXELS;
  return Primitive(texel_at(primitive_texels, texel), texel_at(primitive_texels, texel + 1u),
                   texel_at(primitive_texels, texel + 2u));
}

BvhNode node_at(uint index) {
  uint texel = index * NODE_TEXELS;
  return BvhNode(texel_at(node_texels, texel), texel_at(node_texels, texel + 1u));
}

Material material_at(uint index) {
  uint texel = index * MATERIAL_TEXELS;
  return Material(texel_at(material_texels, texel), texel_at(material_texels, texel + 1u));
}

Light light_at(uint index) {
  uint texel = index * LIGHT_TEXELS;
  return Light(texel_at(light_texels, texel), texel_at(light_texels, texel + 1u),
               texel_at(light_texels, texel + 2u), texel_at(light_texels, texel + 3u),
               texel_at(light_texels, texel + 4u));
}

uvec4 surface_texel_at(uint texel) {
  return texelFetch(surface_texels, int(texel));
}

layout(std140, binding = BINDING_FRAME) uniform Frame { FrameParams frame; };

// The per-pixel layers that kernels read are storage texel buffers for the
// same reason: imageLoad is a gather on lavapipe, where a storage buffer's
// vec4 is four loops over the lanes. Each invocation reads and writes only
// its own pixel's texel, or reads texels an earlier dispatch wrote.
layout(binding = BINDING_ACCUM_MIXED, rgba32f) uniform restrict imageBuffer accum_mixed;
layout(binding = BINDING_ACCUM_REAL, rgba32f) uniform restrict imageBuffer accum_real;
layout(binding = BINDING_ACCUM_AUX, rgba32f) uniform restrict imageBuffer accum_aux;
// adaptive.glsl's reader, which C++ also has (renderer/src/adaptive.cpp).
vec4 accum_aux_at(uint index) {
  return imageLoad(accum_aux, int(index));
}
// The live frame's kernels write the plate (video_decode.comp) and read the
// composite (video_encode.comp); the others only read one and write the other.
#ifdef CAMHEAD_WRITES_PLATE
layout(binding = BINDING_PLATE, rgba32f) uniform restrict writeonly imageBuffer plate;
#else
layout(binding = BINDING_PLATE, rgba32f) uniform restrict readonly imageBuffer plate;
#endif
#ifdef CAMHEAD_READS_COMPOSITE
layout(binding = BINDING_OUT_COMPOSITE, rgba32f) uniform restrict readonly imageBuffer out_composite;
#else
layout(binding = BINDING_OUT_COMPOSITE, rgba32f) uniform restrict writeonly imageBuffer out_composite;
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
// The camera frame's words, one fetch each (a texel buffer as above).
layout(binding = BINDING_VIDEO_IN) uniform usamplerBuffer video_in_words;
layout(std430, binding = BINDING_VIDEO_OUT) writeonly buffer VideoOut { uint video_out[]; };
#endif

// Over an influence region smaller than the frame, a kernel runs over a list
// of the workgroups of the frame's grid that the region touches (GROUP_LIST),
// in one dispatch, rather than one dispatch per rectangle of the region (often
// a single row of tiles): llvmpipe wakes its threads and waits for them at
// every dispatch, and a GPU's front end takes each in turn
// (bench/RESULTS.md, "The live frame on lavapipe, again"). The buffer holds
// two lists (layout.h, GROUP_LIST_*): each its length, then each group's
// place, y << 16 | x.
layout(constant_id = 2) const bool GROUP_LIST = false;
layout(binding = BINDING_GROUP_LIST) uniform usamplerBuffer group_list;

// This invocation's place in the frame's grid of invocations: what
// gl_GlobalInvocationID is in a dispatch over the whole frame. `list`: where
// the kernel's list starts (GROUP_LIST only); `size`: its local size (this
// file comes before the kernel declares it, so gl_WorkGroupSize is not yet
// the kernel's here). False for a workgroup past the list's end, which has
// nothing to do.
bool grid_invocation(uint list, uvec2 size, out uvec3 id) {
  if (!GROUP_LIST) {
    id = gl_GlobalInvocationID;
    return true;
  }
  uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (group >= texelFetch(group_list, int(list)).x) {
    return false;
  }
  uint place = texelFetch(group_list, int(list + 1u + group)).x;
  id = uvec3(uvec2(place & 0xffffu, place >> 16) * size + gl_LocalInvocationID.xy,
             gl_GlobalInvocationID.z);
  return true;
}

// Where the video kernels' list starts: after the tile list's longest.
uint group_list_video() {
  uint tiles_x = (frame.image.x + CAMHEAD_TILE_X - 1u) / CAMHEAD_TILE_X;
  uint tiles_y = (frame.image.y + CAMHEAD_TILE_Y - 1u) / CAMHEAD_TILE_Y;
  return GROUP_LIST_VIDEO(tiles_x * tiles_y);
}

// This invocation's pixel (of an 8x8-tile kernel, the tile list) and its
// index, or -1 outside the image.
int pixel_index(out uvec2 p) {
  uvec3 id;
  if (!grid_invocation(GROUP_LIST_TILES, uvec2(CAMHEAD_TILE_X, CAMHEAD_TILE_Y), id)) {
    return -1;
  }
  p = id.xy;
  if (p.x >= frame.image.x || p.y >= frame.image.y) {
    return -1;
  }
  return int(p.y * frame.image.x + p.x);
}

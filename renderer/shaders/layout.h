// Scene and frame layout shared by the GLSL kernels and the C++ host code.
//
// This header is included by GLSL (std430 buffers, std140 uniform block) and by
// C++ (through renderer/src/kernel_types.h, which maps the GLSL vocabulary onto
// glm). Every struct is built from vec4/uint quads so that std430 and C++ agree
// without padding rules; the C++ side static_asserts the sizes.
#ifndef CAMHEAD_RENDERER_LAYOUT_H
#define CAMHEAD_RENDERER_LAYOUT_H

// Primitive kinds, stored in bits 24..31 of Primitive.p0.w.
#define PRIM_TRIANGLE 0u
#define PRIM_SPHERE 1u
// Bit 16 of Primitive.p0.w: the primitive belongs to the real proxy.
#define PRIM_REAL_BIT 0x10000u
#define PRIM_MATERIAL_MASK 0xffffu

// One primitive, 48 bytes. Triangles store an edge form for Moeller-Trumbore.
//   triangle: p0.xyz = v0, p1.xyz = v1 - v0, p2.xyz = v2 - v0,
//             p1.w = uint bits of the index of its texture coordinates'
//             record + 1 (BINDING_SURFACES, SURFACE_UV_TEXELS texels each;
//             0 = none)
//   sphere:   p0.xyz = centre, p1.x = radius
//   p0.w = floatBitsFromUint(material | real << 16 | kind << 24)
struct Primitive {
  vec4 p0;
  vec4 p1;
  vec4 p2;
};
#define PRIMITIVE_TEXELS 3u // 16-byte texels per Primitive (BINDING_PRIMITIVES)

// Bounding volume hierarchy node, 32 bytes.
//   bmin.xyz / bmax.xyz: bounds
//   interior: bmax.w = 0, bmin.w = index of the left child; the right child
//             follows it directly (left + 1)
//   leaf:     bmax.w = primitive count > 0, bmin.w = first primitive
//   (w fields hold uint bits)
struct BvhNode {
  vec4 bmin;
  vec4 bmax;
};
#define NODE_TEXELS 2u // 16-byte texels per BvhNode (BINDING_NODES)

#define MAT_DIFFUSE 0u
#define MAT_MIRROR 1u
#define MAT_GLASS 2u
#define MAT_EMISSION 3u

// color.rgb: albedo (diffuse), tint (mirror), radiance (emission), unused (glass)
// params.x: index of refraction (glass); params.w: type (uint bits)
// A diffuse material with an albedo texture (texture.glsl): params.y and .z
// its width and height (uint bits; width 0 = none), color.w the
// BINDING_SURFACES texel where its level 0 starts (uint bits); the texture
// is multiplied by color.rgb.
struct Material {
  vec4 color;
  vec4 params;
};
#define MATERIAL_TEXELS 2u // 16-byte texels per Material (BINDING_MATERIALS)

// BINDING_SURFACES holds, in 16-byte texels, the texture coordinates of
// textured triangles, then the albedo textures:
// - a triangle's record, SURFACE_UV_TEXELS texels: (u0, v0, u1, v1), (u2, v2,
//   uv units per metre of surface, 0) for its vertices v0, v1, v2; u to the
//   image's right, v down it, (0, 0) the image's top-left corner
// - a texture: its mip levels, level 0 the image, each next one half the
//   last (rounded down, at least 1) down to 1 x 1; each level row-major from
//   its top row, starting at a whole texel, two pixels per texel as half
//   floats: (r, g) and (b, 0) of the even pixel in .x and .y, the odd one's
//   in .z and .w (linear albedo)
#define SURFACE_UV_TEXELS 2u

#define LIGHT_POINT 0u
#define LIGHT_AREA 1u
#define LIGHT_SUN 2u

// position.xyz: point / area centre; position.w: type (uint bits)
// emission.rgb: point: radiant intensity (W/sr) x colour; area: radiance
//               x colour; sun: irradiance (W/m^2) x colour
// axis_u.xyz, axis_v.xyz: area light full edge vectors (size[0], size[1])
// normal.xyz: area: unit front normal; sun: unit direction the light travels
// axis_u.w: area: surface area (m^2)
struct Light {
  vec4 position;
  vec4 emission;
  vec4 axis_u;
  vec4 axis_v;
  vec4 normal;
};
#define LIGHT_TEXELS 5u // 16-byte texels per Light (BINDING_LIGHTS)

// Per-frame parameters (std140 uniform block; vec4 and uvec4 only).
//
// The camera frame is orthonormal: right, up, forward (forward = -Z of the
// camera). focal_px is the projection focal length in pixels; lens.x the
// aperture radius (m, 0 = pinhole); lens.y the focal-plane depth (m).
struct FrameParams {
  vec4 cam_position;
  vec4 cam_right;
  vec4 cam_up;
  vec4 cam_forward;
  vec4 lens;        // x: aperture radius, y: focus depth, z: focal_px, w: pixel filter width (px)
  vec4 world_color; // rgb
  uvec4 image;      // x: width, y: height, z: has_plate, w: light count
  uvec4 sampling; // x: first sample, y: end sample (exclusive), z: total samples per pixel, w: seed
  uvec4 tracing;  // x: max_bounces; y: adaptive pilot samples (0 = uniform); z: camera
                  // sampler (SAMPLER_*); w: TRACING_* flags
  vec4 adaptive;  // adaptive allocation: x coc_weight, y cap (samples per pixel), z pixels
                  // sharing the budget (the influence region's; 0 = all); w reserved
  // The real lens beyond the pinhole (lens_model.glsl), read only with
  // TRACING_LENS_MODEL: x, y the principal point (pixels from the image's
  // top-left corner, y down); z the focal length down the image over the one
  // across it (fy / fx; fx is lens.z, which breathes); w k3.
  vec4 projection;
  vec4 distortion; // k1, k2, p1, p2 (OpenCV's order and convention)
  // A live frame's reconstruction (reconstruct.glsl), read by
  // reconstruct.comp and by the resolve with RESOLVE_FILTERED: x strength, y
  // the least sigma (px) that borrows, z the widest reach (px); x zero for
  // every other frame.
  vec4 reconstruct;
};

// Camera-ray samplers (FrameParams.tracing.z, sampling.glsl).
#define SAMPLER_CMJ 0u   // correlated multi-jittered, pixel and lens stratified apart
#define SAMPLER_SOBOL 1u // Owen-scrambled Sobol' in 4-D: pixel and lens jointly

// FrameParams.tracing.w flags.
// One sample stands for all where no ray of a pixel can meet the scene
// (kernel.glsl, pixel_misses_scene). bench/RESULTS.md: 1.2-2.8x faster on the
// CPU reference, but up to 1.4x slower on lavapipe where the proxy covers the
// frame, and not yet measured on a GPU; the CPU reference sets it.
#define TRACING_SKIP_EMPTY_PIXELS 1u
// The lens is more than a centred pinhole of square pixels: camera rays go
// through FrameParams.projection and .distortion (make_frame_params sets it
// for any lens that is; the ideal lens keeps the pinhole's arithmetic).
#define TRACING_LENS_MODEL 2u

// What a trace pipeline is built for: specialization constant 0 of
// trace.comp, KERNEL_FEATURES (buffers.glsl), the scene's primitive kinds,
// materials and lights and the frame's sampler and flags (gpu_tracer.cpp,
// kernel_features). The driver removes the code of every feature left out;
// lavapipe, which runs both sides of each branch masked, runs the rest
// faster for it (bench/RESULTS.md, "Where lavapipe's time goes"). The CPU
// reference has them all and decides at run time.
#define KERNEL_SPHERES 1u
#define KERNEL_TRIANGLES 2u
#define KERNEL_MIRRORS 4u
#define KERNEL_GLASS 8u
#define KERNEL_AREA_LIGHTS 16u
#define KERNEL_CAMERA_CMJ 32u   // camera samples may be SAMPLER_CMJ
#define KERNEL_CAMERA_SOBOL 64u // ... or SAMPLER_SOBOL
#define KERNEL_SKIP_EMPTY_PIXELS 128u
#define KERNEL_LENS_MODEL 256u // frames may have TRACING_LENS_MODEL
#define KERNEL_TEXTURES 512u   // a material has an albedo texture
#define KERNEL_ALL 1023u
#define KERNEL_HAS(feature) ((KERNEL_FEATURES & (feature)) != 0u)

// The layers resolve.comp writes: specialization constant 1, RESOLVE_LAYERS.
// A live frame wants the display image alone (and the composite where the
// video kernels encode it); the four float layers cost lavapipe a sixth of
// a 1-rpp frame (bench/RESULTS.md).
#define RESOLVE_COMPOSITE 1u
#define RESOLVE_MIXED 2u
#define RESOLVE_REAL 4u
#define RESOLVE_MASK_AND_DEPTH 8u
#define RESOLVE_DISPLAY 16u
#define RESOLVE_ALL 31u
// Not a layer: the composite from the reconstruction's means (reconstruct.glsl)
// rather than from the accumulators.
#define RESOLVE_FILTERED 32u

// Descriptor bindings, one set shared by the trace and resolve kernels.
#define BINDING_PRIMITIVES 0
#define BINDING_NODES 1
#define BINDING_MATERIALS 2
#define BINDING_LIGHTS 3
#define BINDING_FRAME 4       // uniform FrameParams
#define BINDING_ACCUM_MIXED 5 // vec4 per pixel: sum of mixed radiance (rgb), sum of mask (a)
#define BINDING_ACCUM_REAL 6  // vec4 per pixel: sum of real radiance (rgb)
// BINDING_ACCUM_AUX: x sum of hit depth, y number of hits, z sum and w sum of
// squares of each sample's composite luminance (adaptive sampling's variance).
#define BINDING_ACCUM_AUX 7      // vec4 per pixel, see above
#define BINDING_PLATE 8          // vec4 per pixel: camera image I_c (rgb); unused without plate
#define BINDING_OUT_COMPOSITE 9  // vec4 per pixel: I_f (rgb)
#define BINDING_OUT_MIXED 10     // vec4 per pixel: I_m (rgb)
#define BINDING_OUT_REAL 11      // vec4 per pixel: I_r (rgb)
#define BINDING_OUT_AUX 12       // vec4 per pixel: x mask M, y mean hit depth (0 if none)
#define BINDING_OUT_DISPLAY 13   // uint per pixel: RGBA8, sRGB-encoded I_f, alpha = M
#define BINDING_SAMPLE_COUNTS 14 // uint per pixel: samples of the pixel (adaptive only)
// The adaptive allocation's working buffers (adaptive.glsl).
#define BINDING_ADAPTIVE_WEIGHTS 15   // float per pixel: weight w_i
#define BINDING_ADAPTIVE_HISTOGRAM 16 // uint pairs per bin: count, sum of in-bin offsets
#define BINDING_ADAPTIVE_GROUPS 17    // float per 8x8 tile: sum of |pilot mean luminance|
#define BINDING_ADAPTIVE_SOLUTION 18  // AdaptiveSolution
// Live frames (video.glsl, video_decode.comp, video_encode.comp).
#define BINDING_VIDEO 19     // uniform VideoFrames
#define BINDING_VIDEO_IN 20  // uint per 4 bytes: the camera frame as it came, rows packed
#define BINDING_VIDEO_OUT 21 // uint per 4 bytes: the outputs one after another, rows packed
// The adaptive second pass's queue (sample_queue.glsl).
#define BINDING_SAMPLE_QUEUE 22 // uint per pixel: the pixels with samples left, largest share first
#define BINDING_QUEUE_BINS 23   // uint words at the QUEUE_* offsets below
// The workgroups a frame's kernels run over where its influence region is a
// part of the frame (buffers.glsl, grid_invocation): the tile list at
// GROUP_LIST_TILES, the video kernels' at GROUP_LIST_VIDEO(the frame's tile
// count), each its length, then y << 16 | x a group.
#define BINDING_GROUP_LIST 24
#define GROUP_LIST_TILES 0u
#define GROUP_LIST_VIDEO(tiles) (1u + (tiles))
#define BINDING_SURFACES 25 // texture coordinates and albedo textures (Material, above)
// The reconstruction's (reconstruct.glsl), vec4 per pixel: x the signed blur
// radius (px), y the samples (0: a pixel outside the traced ones); and the
// row pass's sums: mixed, and real with the weight in w.
#define BINDING_FILTER_PIXELS 26
#define BINDING_FILTER_ROWS_MIXED 27
#define BINDING_FILTER_ROWS_REAL 28
#define BINDING_COUNT 29

// Histogram bins of the adaptive weights: 16 per octave over every
// non-negative float (adaptive.glsl).
#define ADAPTIVE_BINS 4096u

// The adaptive second pass traces the pixels of a queue ordered by their
// share, largest first (sample_queue.glsl), so that the lanes that run
// together have shares alike, where a tile of neighbours has shares from the
// pilot up to the cap and each lane group runs as long as its largest. The
// shares fall into QUEUE_BINS bins of equal width; BINDING_QUEUE_BINS holds,
// as uint words:
//   [QUEUE_COUNTS + b]: the pixels of bin b, then where the next of them goes
//   [QUEUE_ENDS + b]: the pixels in bins b and above (the queue's first ones)
//   [QUEUE_DISPATCH + 4 b]: a VkDispatchIndirectCommand over those pixels,
//     a workgroup per QUEUE_GROUP_PIXELS of them, then the stride by which
//     its workgroups take them (sample_queue.glsl)
#define QUEUE_BINS 4096u
#define QUEUE_COUNTS 0u
#define QUEUE_ENDS QUEUE_BINS
#define QUEUE_DISPATCH (2u * QUEUE_BINS)
#define QUEUE_WORDS (6u * QUEUE_BINS)
#define QUEUE_GROUP_PIXELS (CAMHEAD_TILE_X * CAMHEAD_TILE_Y)
// A queue's workgroups are laid out in rows of this many (the y count stays
// far below the 65535 that every device allows).
#define QUEUE_ROW_GROUPS 1024u
// The bin of a second-pass share of `samples` in a frame of `pilot` samples
// a pixel and a cap of `cap`: bins of equal width cover the shares 1 ..
// cap - pilot, one share to a bin up to QUEUE_BINS - 1 of them. The kernels
// and the host (choosing a batch's indirect dispatch) use the same.
#define QUEUE_BIN(samples, pilot, cap) ((samples) / (((cap) - (pilot)) / QUEUE_BINS + 1u))

// The water level of the adaptive allocation and the rays it gave out.
//   solution: x lambda, y floor weight, z expected total samples
//   rays:     x, y the low and high words of the total samples given out
struct AdaptiveSolution {
  vec4 solution;
  uvec4 rays;
};

// Video frame formats (base/video_format.h), VideoParams.format.x and the
// video kernels' VIDEO_FORMAT.
#define VIDEO_YUYV 0u
#define VIDEO_NV12 1u
#define VIDEO_RGB24 2u
#define VIDEO_BGR24 3u
#define VIDEO_XRGB8888 4u
#define VIDEO_MAX_OUTPUTS 4
// The video kernels' workgroup: VIDEO_LOCAL_SIZE^2 invocations of a 4 x 2
// pixel block each, VIDEO_GROUP_X x VIDEO_GROUP_Y pixels.
#define VIDEO_LOCAL_SIZE 8
#define VIDEO_GROUP_X 32u
#define VIDEO_GROUP_Y 16u

// One video frame in BINDING_VIDEO_IN or _OUT.
//   format: x VIDEO_*, y VIDEO_MATRIX_*, z VIDEO_RANGE_* (video.glsl), w the
//           frame's first uint in its buffer
//   size:   x width (a multiple of 4), y height (even), z bytes per row
//           (packed, so a multiple of 4), w unused
// The kernels work on blocks of 4 x 2 pixels, which every format fills with
// whole uints: no two invocations write one word.
struct VideoParams {
  uvec4 format;
  uvec4 size;
};

// frames[0] is the camera frame, frames[1 + k] output k; count.x outputs.
struct VideoFrames {
  VideoParams frames[1 + VIDEO_MAX_OUTPUTS];
  uvec4 count;
};

// The trace kernel adds the samples [sampling.x, sampling.y) of every pixel to
// the accumulators; the first batch (sampling.x = 0, tracing.y = 0) writes
// them instead, so the host clears them only for frames whose kernels read
// pixels that no batch traced, as zeros (outside a smaller influence region:
// a resolve of the whole frame, or adaptive weights at the region's edge).
// The resolve kernel divides by sampling.z and composites. The resolve reads neither
// sampling.x nor sampling.y, so it runs in the last batch's submission, on
// the same frame parameters.
//
// Adaptive sampling (tracing.y = k > 0, renderer/include/camhead/renderer/
// adaptive.h): a pilot of k samples per pixel runs as above (tracing.y = 0,
// sampling.z = k); the host then sets each pixel's total n_i >= k in
// sample_counts. With tracing.y = k the trace kernel adds samples
// [sampling.x, sampling.y) of the pixel's own second pattern of n_i - k
// samples (another seed), stopping at n_i - k, and the resolve kernel divides
// by n_i. The shares are computed on the GPU between the passes by
// adaptive_weights.comp, adaptive_solve.comp and adaptive_shares.comp, and
// adaptive_queue_bins.comp and adaptive_queue_fill.comp order the pixels
// that have samples left into the queue that the second pass traces.

// Workgroup shape of both kernels (pixels).
#define CAMHEAD_TILE_X 8
#define CAMHEAD_TILE_Y 8

// Shadow-ray and secondary-ray offsets are relative to the scene scale.
#define CAMHEAD_RAY_EPSILON 1e-4f

#endif

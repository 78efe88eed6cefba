#version 450
// Averages the accumulators into the layers and composites them (equation 4).
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "kernel.glsl"
#include "reconstruct.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

layout(constant_id = 1) const uint RESOLVE_LAYERS = RESOLVE_ALL; // layout.h

// The sRGB transfer function (IEC 61966-2-1) as image_io's PNG writer applies
// it, in float where the writer uses double: the bytes may differ by one.
vec3 linear_to_srgb(vec3 v) {
  v = clamp(v, vec3(0.0f), vec3(1.0f));
  vec3 low = 12.92f * v;
  vec3 high = 1.055f * pow(v, vec3(1.0f / 2.4f)) - 0.055f;
  return mix(high, low, lessThanEqual(v, vec3(0.0031308f)));
}

void main() {
  uvec2 p;
  int i = pixel_index(p);
  if (i < 0) {
    return;
  }
  bool has_plate = frame.image.z != 0u;
  vec4 camera = has_plate ? imageLoad(plate, i) : vec4(0.0f);
  // The samples the accumulators hold: the last batch's end, the frame's
  // count (or, continuing a history, the history's: GpuTracer::render_video).
  uint samples = frame.tracing.y != 0u ? sample_counts[i] : frame.sampling.y;
  vec4 mixed = imageLoad(accum_mixed, i);
  vec4 real = imageLoad(accum_real, i);
  if ((RESOLVE_LAYERS & RESOLVE_FILTERED) != 0u) {
    // The reconstruction's last pass, the columns, where the pixel was
    // traced: means, which resolve as one sample. Elsewhere the
    // accumulators' zeros, the camera image.
    vec4 pixel = imageLoad(filter_pixels, i);
    if (pixel.y > 0.0f) {
      mixed = imageLoad(filter_rows_mixed, i);
      real = imageLoad(filter_rows_real, i);
      float sigma = reconstruct_sigma(pixel);
      if (sigma >= frame.reconstruct.y) {
        reconstruct_gather(i, pixel, sigma, int(p.y), int(frame.image.y), int(frame.image.x),
                           true, mixed, real);
      }
      mixed /= real.w;
      real /= real.w;
      samples = 1u;
    }
  }
  Resolved r = resolve_pixel(mixed, real, imageLoad(accum_aux, i), camera, has_plate, samples);
  if ((RESOLVE_LAYERS & RESOLVE_COMPOSITE) != 0u) {
    imageStore(out_composite, i, vec4(r.composite, 1.0f));
  }
  if ((RESOLVE_LAYERS & RESOLVE_MIXED) != 0u) {
    out_mixed[i] = vec4(r.mixed, 1.0f);
  }
  if ((RESOLVE_LAYERS & RESOLVE_REAL) != 0u) {
    out_real[i] = vec4(r.real, 1.0f);
  }
  if ((RESOLVE_LAYERS & RESOLVE_MASK_AND_DEPTH) != 0u) {
    out_aux[i] = vec4(r.mask, r.depth, 0.0f, 0.0f);
  }
  // The frame as a display or a V4L2 sink takes it: a quarter of the bytes of
  // out_composite, and no conversion left for the host.
  if ((RESOLVE_LAYERS & RESOLVE_DISPLAY) != 0u) {
    out_display[i] = packUnorm4x8(vec4(linear_to_srgb(r.composite), r.mask));
  }
}

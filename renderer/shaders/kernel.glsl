// The tracing kernel: thin-lens camera, shading and one-pass differential
// rendering (method.md sections 1-3), written once for two executors.
//
// GLSL includes this from trace.comp / resolve.comp; C++ includes it inside
// a struct in renderer/src/cpu_kernel.h, where the buffers are member
// pointers. It therefore keeps to the common subset of GLSL and C++ with glm:
// no swizzles, explicit float literals (1.0f), struct construction by field,
// INOUT(T) / OUT(T) for reference parameters, and no names that would hide a
// glm function inside a C++ class.
//
// Expects: primitive_at(), node_at(), material_at(), light_at(),
// surface_texel_at(), frame (FrameParams).
//
// Loops test their condition at the bottom (do-while, behind a test for
// none at all). lavapipe runs every branch masked and ends a loop only when
// no lane is left at its bottom, so a loop tested at the top runs its whole
// body once more, masked, after its last lane is done: one more traversal
// step, primitive test, shadow ray or sample each time (bench/RESULTS.md,
// "Where lavapipe's time goes").

#include "sampling.glsl"
#include "intersect.glsl"
#include "lens_model.glsl"
#include "texture.glsl"

// ---------------------------------------------------------------- camera

// With a lens model (TRACING_LENS_MODEL): the point of the ideal image plane
// (normalised, y down) that the lens's distortion takes to the sample
// position (px, py).
vec2 lens_preimage(float px, float py) {
  float fy = frame.lens.z * frame.projection.z;
  return lens_undistort(
      vec2((px - frame.projection.x) / frame.lens.z, (py - frame.projection.y) / fy),
      frame.distortion, frame.projection.w);
}

// Whether camera rays take their pixel and aperture points from Sobol'
// (sobol_owen_4d) rather than from CMJ patterns.
bool camera_uses_sobol() {
  return KERNEL_HAS(KERNEL_CAMERA_SOBOL) &&
         (!KERNEL_HAS(KERNEL_CAMERA_CMJ) || frame.tracing.z == SAMPLER_SOBOL);
}

// Pixel (x, y)'s Sobol' keys in the pass of pattern seed `seed`, where
// camera rays take them (a CMJ frame would make them for nothing).
SobolPixel camera_sobol_pixel(uint x, uint y, uint seed) {
  SobolPixel sobol;
  sobol.seed = seed;
  sobol.shift = uvec4(0u);
  if (camera_uses_sobol()) {
    sobol = sobol_pixel_for(x, y, seed);
  }
  return sobol;
}

// One camera ray through pixel (x, y) for sample s of n (method.md section
// 1): CMJ pattern pixel_pattern, or the pixel's Sobol' points.
Ray camera_ray(uint x, uint y, uint s, uint n, uint pixel_pattern, SobolPixel sobol) {
  float width = float(frame.image.x);
  float height = float(frame.image.y);
  float filter_width = frame.lens.w;
  // 1. Jitter inside the pixel (box filter of width filter_width pixels),
  //    and form the pinhole direction; row 0 is the top of the image.
  vec2 jitter;
  vec2 aperture;
  if (camera_uses_sobol()) {
    vec4 q = sobol_owen_4d(s, sobol);
    jitter = vec2(q.x, q.y);
    aperture = vec2(q.z, q.w);
  } else {
    jitter = sample_dimension(s, n, pixel_pattern, DIM_PIXEL);
    aperture = sample_dimension(s, n, pixel_pattern, DIM_LENS);
  }
  float px = float(x) + 0.5f + (jitter.x - 0.5f) * filter_width;
  float py = float(y) + 0.5f + (jitter.y - 0.5f) * filter_width;
  vec3 right = vec3(frame.cam_right);
  vec3 up = vec3(frame.cam_up);
  vec3 forward = vec3(frame.cam_forward);
  vec3 d;
  if (KERNEL_HAS(KERNEL_LENS_MODEL) && (frame.tracing.w & TRACING_LENS_MODEL) != 0u) {
    vec2 ideal = lens_preimage(px, py); // the real lens
    d = normalize(right * ideal.x - up * ideal.y + forward);
  } else {
    d = normalize(right * (px - 0.5f * width) + up * (0.5f * height - py) +
                  forward * frame.lens.z);
  }
  Ray ray;
  ray.origin = vec3(frame.cam_position);
  ray.dir = d;
  float aperture_radius = frame.lens.x;
  if (aperture_radius <= 0.0f) {
    return ray; // pinhole
  }
  // 2. Where the pinhole ray meets the focal plane (a plane, not a sphere:
  //    divide by the cosine to the optical axis).
  vec3 focus_point = ray.origin + d * (frame.lens.y / dot(d, forward));
  // 3. A point on the aperture disk (CMJ: stratified separately from the
  //    pixel; Sobol': jointly with it).
  vec2 disk = aperture_radius * concentric_disk(aperture);
  // 4. The lens ray starts there and aims at the focus point.
  ray.origin = ray.origin + right * disk.x + up * disk.y;
  ray.dir = normalize(focus_point - ray.origin);
  return ray;
}

// ---------------------------------------------------------------- shading

// Offset scale for new rays leaving a surface at p.
float ray_epsilon(vec3 p) {
  return CAMHEAD_RAY_EPSILON * (1.0f + max(abs(p.x), max(abs(p.y), abs(p.z))));
}

vec3 surface_normal(Primitive prim, vec3 p) {
  if (prim_is_sphere(prim)) {
    return normalize(p - vec3(prim.p0));
  }
  return normalize(cross(vec3(prim.p1), vec3(prim.p2))); // flat face normal
}

// Unpolarised Fresnel reflectance of a smooth dielectric; eta = n_t / n_i.
float fresnel_dielectric(float cos_i, float eta) {
  float sin_t2 = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin_t2 >= 1.0f) {
    return 1.0f; // total internal reflection
  }
  float cos_t = sqrt(1.0f - sin_t2);
  float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_par * r_par + r_perp * r_perp);
}

// Direct light at a diffuse point from the scene's lights (reference
// README, "What Cycles does": shadow rays only, no interreflection).
// Adds to lm the light that reaches p past all geometry, and, when
// want_real, to lr the light that reaches it past the real proxy alone.
void direct_light(vec3 p, vec3 n, vec3 brdf_weight, uint surface_dim, uint s, uint count,
                  uint pixel_pattern, bool want_real, bool real_only, INOUT(vec3) lm,
                  INOUT(vec3) lr) {
  float eps = ray_epsilon(p);
  Ray shadow;
  shadow.origin = p + n * eps;
  if (frame.image.w == 0u) {
    return;
  }
  uint li = 0u;
  do {
    Light light = light_at(li);
    uint type = floatBitsToUint(light.position.w);
    vec3 wi;
    float dist;
    vec3 irradiance;
    if (type == LIGHT_SUN) {
      wi = -vec3(light.normal);
      dist = CAMHEAD_NO_HIT;
      irradiance = vec3(light.emission) * max(dot(n, wi), 0.0f);
    } else {
      vec3 target = vec3(light.position);
      float geometry = 1.0f;
      bool area = KERNEL_HAS(KERNEL_AREA_LIGHTS) && type == LIGHT_AREA;
      if (area) {
        vec2 u = sample_dimension(s, count, pixel_pattern, surface_dim + 1u + li);
        target += (u.x - 0.5f) * vec3(light.axis_u) + (u.y - 0.5f) * vec3(light.axis_v);
      }
      vec3 to_light = target - shadow.origin;
      dist = length(to_light);
      wi = to_light / dist;
      if (area) {
        // Uniform area sampling: pdf 1/A, cosine at the light, front side only.
        geometry = max(-dot(wi, vec3(light.normal)), 0.0f) * light.axis_u.w;
      }
      irradiance = vec3(light.emission) * (geometry * max(dot(n, wi), 0.0f) / (dist * dist));
    }
    if (irradiance.x <= 0.0f && irradiance.y <= 0.0f && irradiance.z <= 0.0f) {
      continue;
    }
    shadow.dir = wi;
    float t_max = dist == CAMHEAD_NO_HIT ? CAMHEAD_NO_HIT : dist * (1.0f - 1e-5f);
    uint occluded = shadow_query(shadow, 0.0f, t_max, real_only, !want_real);
    vec3 contribution = brdf_weight * irradiance;
    if (!real_only && occluded == 0u) {
      lm += contribution;
    }
    if ((want_real || real_only) && (occluded & OCCLUDED_BY_REAL) == 0u) {
      lr += contribution;
    }
  } while (++li < frame.image.w);
}

// ---------------------------------------------------------------- paths

// Where the real radiance ray splits from the mixed path: at the first
// virtual surface, the real ray continues the same direction through it.
struct RealBranch {
  Ray ray;
  vec3 weight;
  uint surface;
  float travelled; // metres from the lens to ray.origin
  bool pending;
};

// What one camera sample contributes to the accumulators.
struct SampleResult {
  vec3 mixed;      // mixed radiance
  vec3 real;       // real radiance
  bool hit;        // the camera ray hit something
  bool is_virtual; // ... and that was a virtual object (mask)
  float depth;     // camera-axis depth of that hit
};

// Traces one camera ray, surface by surface, in up to two segments:
// 1. The mixed path from the camera. While it meets only real surfaces it is
//    the real path too: both radiances are shaded at the same hits, with the
//    mixed and the real shadow ray. At its first virtual surface the real
//    radiance ray is set aside in `branch`.
// 2. That real radiance ray, which sees the real proxy alone.
// Both segments run in the same loop: a second copy of the loop would double
// the code that SIMD executors such as lavapipe run for every lane.
// Surfaces 1 .. max_bounces + 1 are shaded; the ray leaving the last of them
// picks up emission only (reference README, "What Cycles does").
SampleResult trace_sample(Ray camera, uint s, uint count, uint pixel_pattern) {
  SampleResult result;
  result.mixed = vec3(0.0f);
  result.real = vec3(0.0f);
  result.hit = false;
  result.is_virtual = false;
  result.depth = 0.0f;
  RealBranch branch;
  branch.ray = camera;
  branch.weight = vec3(1.0f);
  branch.surface = 1u;
  branch.travelled = 0.0f;
  branch.pending = false;

  Ray ray = camera;
  vec3 weight = vec3(1.0f);
  uint surface = 1u;
  float travelled = 0.0f; // from the lens to ray.origin, for texture filtering
  bool real_only = false; // segment 2
  bool coupled = true;    // segment 1 before any virtual surface
  uint last_shaded = frame.tracing.x + 1u;
  for (;;) {
    Hit hit = closest_hit(ray, 0.0f, CAMHEAD_NO_HIT, real_only);
    bool missed = hit.t == CAMHEAD_NO_HIT;
    Primitive surface_prim = primitive_at(hit.prim); // primitive 0 where missed
    bool is_virtual = !missed && !prim_is_real(surface_prim);
    if (surface == 1u && !real_only) {
      result.hit = !missed;
      result.is_virtual = is_virtual;
      result.depth = missed ? 0.0f : hit.t * dot(ray.dir, vec3(frame.cam_forward));
    }
    if (coupled && is_virtual) {
      coupled = false;
      branch.ray = ray;
      branch.weight = weight;
      branch.surface = surface;
      branch.travelled = travelled;
      branch.pending = true;
    }
    bool add_mixed = !real_only;
    bool add_real = real_only || coupled;

    Material material = material_at(missed ? 0u : prim_material(surface_prim));
    uint type = floatBitsToUint(material.params.w);
    vec3 emitted = surface > 1u ? area_lights_along(ray, hit.t) : vec3(0.0f);
    if (missed) {
      emitted += vec3(frame.world_color);
    } else if (type == MAT_EMISSION) {
      emitted += vec3(material.color);
    }
    vec3 p = ray.origin + hit.t * ray.dir;
    vec3 n = missed ? vec3(0.0f, 0.0f, 1.0f) : surface_normal(surface_prim, p);
    bool entering = dot(n, ray.dir) < 0.0f;
    vec3 n_facing = entering ? n : -n; // planes and meshes are two-sided
    uint surface_dim = DIM_SURFACE_BASE + (surface - 1u) * DIM_PER_SURFACE;
    bool path_ends = missed || surface > last_shaded || type == MAT_EMISSION;
    if (!path_ends && type == MAT_DIFFUSE) {
      vec3 albedo = surface_albedo(material, surface_prim, p, n, ray.dir, travelled + hit.t);
      vec3 brdf_weight = weight * albedo * (1.0f / CAMHEAD_PI);
      vec3 dm = vec3(0.0f);
      vec3 dr = vec3(0.0f);
      direct_light(p, n_facing, brdf_weight, surface_dim, s, count, pixel_pattern,
                   add_real && !real_only, real_only, dm, dr);
      emitted = emitted * weight;
      weight = vec3(0.0f);
      result.mixed += add_mixed ? emitted + dm : vec3(0.0f);
      result.real += add_real ? emitted + dr : vec3(0.0f);
      path_ends = true;
    } else {
      result.mixed += add_mixed ? weight * emitted : vec3(0.0f);
      result.real += add_real ? weight * emitted : vec3(0.0f);
    }

    // Without mirrors and glass every path ends at its first shaded surface.
    if (path_ends || !KERNEL_HAS(KERNEL_MIRRORS | KERNEL_GLASS)) {
      if (!branch.pending) {
        break;
      }
      // Segment 2: the real radiance ray from the first virtual surface on.
      ray = branch.ray;
      weight = branch.weight;
      surface = branch.surface;
      travelled = branch.travelled;
      branch.pending = false;
      real_only = true;
      coupled = false;
      continue;
    }

    float eps = ray_epsilon(p);
    if (KERNEL_HAS(KERNEL_MIRRORS) && (!KERNEL_HAS(KERNEL_GLASS) || type == MAT_MIRROR)) {
      weight *= vec3(material.color); // reflectance = tint at every angle, no Fresnel
      ray.dir = reflect(ray.dir, n_facing);
      ray.origin = p + n_facing * eps;
    } else { // MAT_GLASS: reflect with probability F, else refract; weight 1
      float eta = entering ? material.params.x : 1.0f / material.params.x;
      float reflectance = fresnel_dielectric(-dot(ray.dir, n_facing), eta);
      float u = sample_dimension(s, count, pixel_pattern, surface_dim).x;
      bool reflects = u < reflectance;
      ray.dir = reflects ? reflect(ray.dir, n_facing)
                         : normalize(refract(ray.dir, n_facing, 1.0f / eta));
      ray.origin = p + (reflects ? n_facing : -n_facing) * eps;
    }
    travelled += hit.t;
    ++surface;
  }
  return result;
}

// Whether a ray of a pixel's bundle may meet box [bmin, bmax]. The rays of
// a pixel start on the aperture disk (radius frame.lens.x) and pass through
// the pixel's footprint on the focal plane at depth F (half-diagonal
// `footprint`). At axial depth z each lies within A |1 - z/F| + h z/F of the
// central ray (lens centre, pixel centre), a convex function of z; so a ray
// of the bundle can meet the box only if the central ray meets the box grown
// by that distance's larger end value over the box's depth range.
bool bundle_meets_box(vec3 origin, vec3 inv_dir, float footprint, vec4 bmin4, vec4 bmax4) {
  vec3 bmin = vec3(bmin4);
  vec3 bmax = vec3(bmax4);
  vec3 forward = vec3(frame.cam_forward);
  float z_mid = dot(0.5f * (bmin + bmax) - origin, forward);
  float z_extent = dot(0.5f * (bmax - bmin), abs(forward));
  float z_far = z_mid + z_extent;
  if (z_far <= 0.0f) {
    return false; // behind the lens: camera rays only go forward
  }
  float z_near = max(z_mid - z_extent, 0.0f);
  float focus = frame.lens.y;
  float spread_near = frame.lens.x * abs(1.0f - z_near / focus) + footprint * z_near / focus;
  float spread_far = frame.lens.x * abs(1.0f - z_far / focus) + footprint * z_far / focus;
  // A margin for the rounding of the rays themselves.
  float grow = max(spread_near, spread_far) * 1.001f + 1e-5f * max(z_far, 1.0f);
  return box_entry(origin, inv_dir, vec4(bmin - vec3(grow), 0.0f), vec4(bmax + vec3(grow), 0.0f),
                   CAMHEAD_NO_HIT) != CAMHEAD_NO_HIT;
}

// True when no camera ray of pixel (x, y) can meet any leaf of the BVH:
// every sample of the pixel then sees the world alone, and one sample stands
// for all of them (trace_pixel). This is what makes a frame cheap where the
// proxy and the virtual objects cover little of it. A traversal with the
// bundle test above that stops at the first leaf the bundle may reach;
// conservative (a full stack counts as a leaf reached).
bool pixel_misses_scene(uint x, uint y) {
  BvhNode root = node_at(0u);
  if (!(abs(root.bmin.x) < 1e30f)) {
    return true; // the empty BVH (bounds at +inf) admits no ray
  }
  vec3 origin = vec3(frame.cam_position);
  float px = float(x) + 0.5f;
  float py = float(y) + 0.5f;
  vec3 d;
  float footprint;
  if (KERNEL_HAS(KERNEL_LENS_MODEL) && (frame.tracing.w & TRACING_LENS_MODEL) != 0u) {
    // Through the lens: the pixel centre's preimage, and its samples' within
    // their distance over the least stretch of the lens there, a tenth more
    // for the stretch's change across a pixel.
    vec2 ideal = lens_preimage(px, py);
    float least = lens_least_stretch(ideal, frame.distortion, frame.projection.w);
    if (!(least > 0.05f)) {
      return false; // where the lens folds over: no bound
    }
    d = normalize(vec3(frame.cam_right) * ideal.x - vec3(frame.cam_up) * ideal.y +
                  vec3(frame.cam_forward));
    footprint = 1.1f * 0.70710678f * frame.lens.w * frame.lens.y /
                (min(frame.lens.z, frame.lens.z * frame.projection.z) * least);
  } else {
    d = normalize(vec3(frame.cam_right) * (px - 0.5f * float(frame.image.x)) +
                  vec3(frame.cam_up) * (0.5f * float(frame.image.y) - py) +
                  vec3(frame.cam_forward) * frame.lens.z);
    footprint = 0.70710678f * frame.lens.w * frame.lens.y / frame.lens.z;
  }
  vec3 inv_dir = safe_reciprocal(d);
  uint stack[CAMHEAD_STACK_SIZE];
  int top = 0;
  if (!bundle_meets_box(origin, inv_dir, footprint, root.bmin, root.bmax)) {
    return true;
  }
  stack[0] = 0u;
  top = 1;
  do {
    --top;
    BvhNode node = node_at(stack[top]);
    if (floatBitsToUint(node.bmax.w) > 0u) {
      return false; // a leaf
    }
    uint left = floatBitsToUint(node.bmin.w);
    uint child = left;
    do {
      BvhNode child_node = node_at(child);
      if (bundle_meets_box(origin, inv_dir, footprint, child_node.bmin, child_node.bmax)) {
        if (top == CAMHEAD_STACK_SIZE) {
          return false;
        }
        stack[top] = child;
        ++top;
      }
    } while (++child <= left + 1u);
  } while (top > 0);
  return true;
}

// The luminance (Rec. 709) by which a sample's composite is weighed for
// sharing rays (adaptive.glsl; renderer/src/ray_shares.h).
float composite_luminance(vec3 f) {
  return dot(f, vec3(0.2126f, 0.7152f, 0.0722f));
}

// Adds `weight` copies of sample r to the accumulators (trace_pixel).
void accumulate_sample(SampleResult r, float weight, vec4 camera, bool has_plate,
                       INOUT(vec4) acc_mixed, INOUT(vec4) acc_real, INOUT(vec4) acc_aux) {
  float m = r.is_virtual ? 1.0f : 0.0f;
  acc_mixed += weight * vec4(r.mixed, m);
  acc_real += weight * vec4(r.real, 0.0f);
  if (r.hit) {
    acc_aux += weight * vec4(r.depth, 1.0f, 0.0f, 0.0f);
  }
  // This sample's composite (equation 4, linear in the sample).
  vec3 f = has_plate ? r.mixed + (1.0f - m) * (vec3(camera) - r.real) : r.mixed;
  float lum = composite_luminance(f);
  acc_aux += weight * vec4(0.0f, 0.0f, lum, lum * lum);
}

// Adds samples [frame.sampling.x, frame.sampling.y) of pixel (x, y) to the
// accumulators (layout.h: mixed.rgb + mask, real.rgb, aux = depth sum, hits,
// and the sum and sum of squares of the luminance of each sample's composite,
// for adaptive sampling). `camera` is the plate's pixel (has_plate only).
// With frame.tracing.y = k > 0 (adaptive second pass) the samples are those
// of the pixel's own pattern of sample_counts[pixel] - k samples.
void trace_pixel(uint x, uint y, vec4 camera, bool has_plate, INOUT(vec4) acc_mixed,
                 INOUT(vec4) acc_real, INOUT(vec4) acc_aux) {
  uint count = frame.sampling.z;
  uint end = frame.sampling.y;
  uint seed = frame.sampling.w;
  if (frame.tracing.y != 0u) {
    count = sample_counts[y * frame.image.x + x] - frame.tracing.y;
    end = min(end, count);
    seed = hash_u32(seed ^ 0xad5a3c1bu); // independent of the pilot's pattern
  }
  uint pixel_pattern = pixel_pattern_for(x, y, frame.image.x, seed);
  uint first = frame.sampling.x;
  float weight = 1.0f;
  // One sample for all where none can differ. A shorter loop rather than a
  // second path: SIMD executors (lavapipe) run a branch's both sides but a
  // loop only as long as its longest lane. A pixel of one sample has none to
  // save, and the test would cost a fifth of a live 1-rpp frame
  // (bench/RESULTS.md).
  if (KERNEL_HAS(KERNEL_SKIP_EMPTY_PIXELS) && first + 1u < end &&
      (frame.tracing.w & TRACING_SKIP_EMPTY_PIXELS) != 0u && pixel_misses_scene(x, y)) {
    weight = float(end - first);
    end = first + 1u;
  }
  if (first >= end) {
    return;
  }
  SobolPixel sobol = camera_sobol_pixel(x, y, seed);
  uint s = first;
  do {
    SampleResult r = trace_sample(camera_ray(x, y, s, count, pixel_pattern, sobol), s, count,
                                  pixel_pattern);
    accumulate_sample(r, weight, camera, has_plate, acc_mixed, acc_real, acc_aux);
  } while (++s < end);
}

// ---------------------------------------------------------------- compositing

struct Resolved {
  vec3 composite;
  vec3 mixed;
  vec3 real;
  float mask;
  float depth;
};

// Equation (4),
//   I_f = M I_m + (1 - M)(I_c + I_m - I_r),
// evaluated as I_c + (I_m - I_r) - M (I_c - I_r), which returns I_c bit for
// bit where nothing virtual is seen (M = 0 and I_m == I_r). Where the camera
// pixel is darker than the real proxy predicts, a virtual shadow would take
// it below black (I_c + I_m - I_r < 0): light that cannot be, and video
// codes under 16 that limited range reserves. The virtual contribution
// stops at black, and never moves a camera value that is already below it
// (a Y'CbCr triple outside the RGB cube), so pass-through stays exact.
// (shared/reference/compose.py does not clamp: its composites differ from
// these only where they are negative.)
vec3 composite_pixel(vec3 camera, vec3 mixed, vec3 real, float mask) {
  // PRECISE: a reassociating compiler (Mesa does) would break the identity.
  PRECISE vec3 composite = camera + (mixed - real) - mask * (camera - real);
  return max(composite, min(camera, vec3(0.0f)));
}

// Layers from the accumulators, composited by composite_pixel(). Without a
// plate the real render stands in for the camera image, so I_f = I_m.
// `samples`: the pixel's sample count (frame.sampling.z, or its adaptive n_i;
// 0 outside the influence region, whose accumulators are zero: the camera
// image).
Resolved resolve_pixel(vec4 acc_mixed, vec4 acc_real, vec4 acc_aux, vec4 plate, bool has_plate,
                       uint samples) {
  float inv = samples > 0u ? 1.0f / float(samples) : 0.0f;
  Resolved r;
  r.mixed = vec3(acc_mixed) * inv;
  r.real = vec3(acc_real) * inv;
  r.mask = acc_mixed.w * inv;
  r.depth = acc_aux.y > 0.0f ? acc_aux.x / acc_aux.y : 0.0f;
  vec3 camera = has_plate ? vec3(plate) : r.real;
  r.composite = composite_pixel(camera, r.mixed, r.real, r.mask);
  return r;
}

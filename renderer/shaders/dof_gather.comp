#version 450
// Image-space depth of field: the baseline that the ray-traced thin lens is
// charted against (`camhead bench chart`). A pinhole render's layers are
// blurred by a depth-driven gather with the circle of confusion of method.md
// section 1, the scatter-as-gather approach of real-time engines:
//
// - Every neighbour q within the largest blur radius contributes to pixel p
//   when its own blur disk (radius r_q, from its depth) covers p, with the
//   density of a scatter, cover / (pi r_q^2): a defocused point spreads its
//   energy over its disk.
// - Neighbours in front of p are gathered as a separate foreground layer whose
//   summed density is its coverage alpha: a blurred foreground spreads over
//   whatever lies behind it.
// - Neighbours at p's depth or behind it use min(r_q, r_p): a background
//   cannot spread over a sharper surface in front of it, so an in-focus
//   foreground keeps its sharp silhouette and nothing bleeds across it.
//
// The three layers of differential rendering (I_m with the mask in alpha,
// I_r) are blurred with the same weights, then composited as resolve.comp
// does (method.md equation 4) with the camera image, which carries the
// physical lens's own blur already.

#define DOF_BINDING_PARAMS 0
#define DOF_BINDING_IN_MIXED 1  // vec4: I_m rgb, mask M
#define DOF_BINDING_IN_REAL 2   // vec4: I_r rgb, camera-axis depth (0 = nothing hit)
#define DOF_BINDING_PLATE 3     // vec4: I_c rgb (unused without a plate)
#define DOF_BINDING_OUT_COMPOSITE 4
#define DOF_BINDING_OUT_MIXED 5 // vec4: blurred I_m rgb, blurred M
#define DOF_BINDING_OUT_REAL 6  // vec4: blurred I_r rgb, 0

layout(local_size_x = 8, local_size_y = 8) in;

// lens: x aperture radius (m), y focus depth (m), z focal length (px),
//       w largest blur radius gathered (px);
// image: x width, y height, z has_plate, w unused;
// depth: x relative depth difference below which a neighbour counts as
//        "at p's depth" rather than in front of it.
layout(std140, binding = DOF_BINDING_PARAMS) uniform Params {
  vec4 lens;
  uvec4 image;
  vec4 depth;
}
params;

layout(std430, binding = DOF_BINDING_IN_MIXED) readonly buffer InMixed { vec4 in_mixed[]; };
layout(std430, binding = DOF_BINDING_IN_REAL) readonly buffer InReal { vec4 in_real[]; };
layout(std430, binding = DOF_BINDING_PLATE) readonly buffer Plate { vec4 plate[]; };
layout(std430, binding = DOF_BINDING_OUT_COMPOSITE) writeonly buffer OutComposite { vec4 out_composite[]; };
layout(std430, binding = DOF_BINDING_OUT_MIXED) writeonly buffer OutMixed { vec4 out_mixed[]; };
layout(std430, binding = DOF_BINDING_OUT_REAL) writeonly buffer OutReal { vec4 out_real[]; };

const float kPi = 3.14159265358979;
const float kFar = 1e30; // depth of pixels that hit nothing

float depth_of(float stored) { return stored > 0.0 ? stored : kFar; }

// Blur radius in pixels: half of c = 2R p |z - d_f| / (z d_f) (method.md
// section 1), at least half a pixel (the pixel itself), at most lens.w.
float coc_radius(float z) {
  float c = 2.0 * params.lens.x * params.lens.z * abs(z - params.lens.y) / (z * params.lens.y);
  return clamp(0.5 * c, 0.5, params.lens.w);
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  int width = int(params.image.x);
  int height = int(params.image.y);
  if (p.x >= width || p.y >= height) {
    return;
  }
  int i = p.y * width + p.x;
  float zp = depth_of(in_real[i].w);
  float rp = coc_radius(zp);
  float front_limit = zp * (1.0 - params.depth.x);
  int reach = int(ceil(params.lens.w));

  vec4 fg_mixed = vec4(0.0);
  vec3 fg_real = vec3(0.0);
  float fg_weight = 0.0;
  vec4 bg_mixed = vec4(0.0);
  vec3 bg_real = vec3(0.0);
  float bg_weight = 0.0;
  for (int dy = -reach; dy <= reach; ++dy) {
    int qy = p.y + dy;
    if (qy < 0 || qy >= height) {
      continue;
    }
    for (int dx = -reach; dx <= reach; ++dx) {
      int qx = p.x + dx;
      if (qx < 0 || qx >= width) {
        continue;
      }
      float dist = length(vec2(float(dx), float(dy)));
      int j = qy * width + qx;
      vec4 real_q = in_real[j];
      float zq = depth_of(real_q.w);
      float rq = coc_radius(zq);
      bool in_front = zq < front_limit;
      float r = in_front ? rq : min(rq, rp);
      // Fraction of pixel q's disk edge that reaches p (antialiased rim).
      float cover = clamp(r - dist + 0.5, 0.0, 1.0);
      if (cover <= 0.0) {
        continue;
      }
      float w = cover / max(kPi * r * r, 1.0);
      vec4 mixed_q = in_mixed[j];
      if (in_front) {
        fg_mixed += w * mixed_q;
        fg_real += w * vec3(real_q);
        fg_weight += w;
      } else {
        bg_mixed += w * mixed_q;
        bg_real += w * vec3(real_q);
        bg_weight += w;
      }
    }
  }
  // bg_weight > 0: p itself is at its own depth and covers itself.
  float alpha = clamp(fg_weight, 0.0, 1.0);
  vec4 mixed_out = bg_mixed / bg_weight;
  vec3 real_out = bg_real / bg_weight;
  if (fg_weight > 0.0) {
    mixed_out = mix(mixed_out, fg_mixed / fg_weight, alpha);
    real_out = mix(real_out, fg_real / fg_weight, alpha);
  }

  // Equation (4) as composite_pixel() (kernel.glsl) writes it, not below black.
  vec3 m = vec3(mixed_out);
  float mask = mixed_out.w;
  vec3 camera = params.image.z != 0u ? vec3(plate[i]) : real_out;
  precise vec3 composite = camera + (m - real_out) - mask * (camera - real_out);
  out_composite[i] = vec4(max(composite, min(camera, vec3(0.0))), 1.0);
  out_mixed[i] = mixed_out;
  out_real[i] = vec4(real_out, 0.0);
}

// The real lens beyond the pinhole: Brown-Conrady distortion in OpenCV's
// convention (cv::projectPoints), on normalised image coordinates (x right,
// y down, 1 at one focal length from the principal point):
//
//     r^2 = x^2 + y^2,   R = 1 + k1 r^2 + k2 r^4 + k3 r^6
//     x_d = x R + 2 p1 x y + p2 (r^2 + 2 x^2)
//     y_d = y R + p1 (r^2 + 2 y^2) + 2 p2 x y
//
// `k` holds k1, k2, p1, p2 (OpenCV's order) and `k3` the sixth-order term.
//
// Written once for the GPU kernels (kernel.glsl includes it) and the C++ side
// (renderer/src/lens_model_math.h includes it inside a struct, as
// cpu_kernel.h does kernel.glsl), so it keeps to the same common subset: no
// swizzles, explicit float literals, do-while loops.

vec2 lens_distort(vec2 p, vec4 k, float k3) {
  float r2 = p.x * p.x + p.y * p.y;
  float radial = 1.0f + r2 * (k.x + r2 * (k.y + r2 * k3));
  return vec2(p.x * radial + 2.0f * k.z * p.x * p.y + k.w * (r2 + 2.0f * p.x * p.x),
              p.y * radial + k.z * (r2 + 2.0f * p.y * p.y) + 2.0f * k.w * p.x * p.y);
}

// The Jacobian of lens_distort() at `p`, symmetric: (d x_d / d x,
// d y_d / d y, d x_d / d y = d y_d / d x).
vec3 lens_jacobian(vec2 p, vec4 k, float k3) {
  float r2 = p.x * p.x + p.y * p.y;
  float radial = 1.0f + r2 * (k.x + r2 * (k.y + r2 * k3));
  float slope = k.x + r2 * (2.0f * k.y + 3.0f * r2 * k3); // dR / d(r^2)
  return vec3(radial + 2.0f * p.x * p.x * slope + 2.0f * k.z * p.y + 6.0f * k.w * p.x,
              radial + 2.0f * p.y * p.y * slope + 6.0f * k.z * p.y + 2.0f * k.w * p.x,
              2.0f * p.x * p.y * slope + 2.0f * k.z * p.x + 2.0f * k.w * p.y);
}

// The least the lens stretches the image plane at `p`: its Jacobian's
// smaller eigenvalue (zero or less where the lens folds over).
float lens_least_stretch(vec2 p, vec4 k, float k3) {
  vec3 j = lens_jacobian(p, k, k3);
  float half_difference = 0.5f * (j.x - j.y);
  return 0.5f * (j.x + j.y) - sqrt(half_difference * half_difference + j.z * j.z);
}

// The point that lens_distort() takes to `d`: Newton's method from `d`
// itself, a fixed number of steps (every lane alike). Within the radius
// where the lens maps outward monotonically (the influence region checks
// that a frame stays inside it) the error squares at each step: from d,
// a lens of k1 = -0.3 is 0.07 off at the corners, then 4e-3, 2e-5, and at
// float precision after the fourth (tests/markers/lens_model_test.cpp holds
// the round trip within a thousandth of a pixel).
vec2 lens_undistort(vec2 d, vec4 k, float k3) {
  vec2 p = d;
  int step = 0;
  float moved2 = 0.0f;
  do {
    vec2 residual = lens_distort(p, k, k3) - d;
    vec3 j = lens_jacobian(p, k, k3);
    float det = j.x * j.y - j.z * j.z;
    vec2 delta =
        vec2(j.y * residual.x - j.z * residual.y, j.x * residual.y - j.z * residual.x) / det;
    p = p - delta;
    moved2 = delta.x * delta.x + delta.y * delta.y;
    ++step;
  } while (step < 4 && moved2 > 1e-14f); // converged: a step below float precision
  return p;
}

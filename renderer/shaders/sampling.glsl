// Deterministic stratified sampling, shared by GLSL and C++ (see kernel.glsl).
//
// method.md section 2: with n rays per pixel the pixel area and the aperture
// are each stratified, and the two pairings are decorrelated. Correlated
// multi-jittered sampling (Kensler 2013, "Correlated Multi-Jittered
// Sampling") does exactly that for any n, statelessly: sample s of n in
// pattern p lands in its own cell of an m x (n/m) grid and its own row and
// column sub-stratum; a different pattern p per dimension shuffles the
// pairing between dimensions. Everything is a function of (pixel, sample,
// dimension, seed), so a frame is reproducible and batches can run in any
// order.

uint hash_u32(uint x) {
  // lowbias32 (C. Wellons): full avalanche, cheap on GPUs and CPUs alike.
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// A pseudo-random permutation of [0, l), indexed by i, chosen by p (Kensler).
uint cmj_permute(uint i, uint l, uint p) {
  uint w = l - 1u;
  w |= w >> 1;
  w |= w >> 2;
  w |= w >> 4;
  w |= w >> 8;
  w |= w >> 16;
  do {
    i ^= p;
    i *= 0xe170893du;
    i ^= p >> 16;
    i ^= (i & w) >> 4;
    i ^= p >> 8;
    i *= 0x0929eb3fu;
    i ^= p >> 23;
    i ^= (i & w) >> 1;
    i *= 1u | p >> 27;
    i *= 0x6935fa69u;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfu;
    i &= w;
    i ^= i >> 5;
  } while (i >= l);
  return (i + p) % l;
}

// A value in [0, 1) from (i, p) (Kensler).
float cmj_randfloat(uint i, uint p) {
  i ^= p;
  i ^= i >> 17;
  i ^= i >> 10;
  i *= 0xb36534e5u;
  i ^= i >> 12;
  i ^= i >> 21;
  i *= 0x93fc4795u;
  i ^= 0xdf6e307fu;
  i ^= i >> 17;
  i *= 1u | p >> 18;
  return min(float(i) * (1.0f / 4294967808.0f), 0.99999994f);
}

// Sample s of n of a 2-D stratified pattern p in [0, 1)^2.
vec2 cmj_sample(uint s, uint n, uint p) {
  uint m = uint(sqrt(float(n)));
  if ((m + 1u) * (m + 1u) <= n) { // guard float rounding of sqrt
    m += 1u;
  }
  uint rows = (n + m - 1u) / m;
  s = cmj_permute(s, n, p * 0x51633e2du);
  uint sx = cmj_permute(s % m, m, p * 0x68bc21ebu);
  uint sy = cmj_permute(s / m, rows, p * 0x02e5be93u);
  float jx = cmj_randfloat(s, p * 0x967a889bu);
  float jy = cmj_randfloat(s, p * 0x368cc8b7u);
  return vec2((float(sx) + (float(sy) + jx) / float(rows)) / float(m), (float(s) + jy) / float(n));
}

// Sample dimensions. Each bounce gets its own block so that the glass choice
// and the area-light samples of different surfaces are independent strata.
#define DIM_PIXEL 0u
#define DIM_LENS 1u
#define DIM_SURFACE_BASE 2u
#define DIM_PER_SURFACE 64u // 0: glass choice, 1 + light index: area light

uint pattern_for(uint pixel_pattern, uint dimension) {
  return hash_u32(pixel_pattern ^ hash_u32(dimension * 0x9e3779b9u + 0x632be5abu));
}

// The pattern seed of one pixel in one frame.
uint pixel_pattern_for(uint x, uint y, uint width, uint seed) {
  return hash_u32((y * width + x) * 0x9e3779b1u ^ hash_u32(seed + 0x85ebca6bu));
}

vec2 sample_dimension(uint s, uint n, uint pixel_pattern, uint dimension) {
  return cmj_sample(s, n, pattern_for(pixel_pattern, dimension));
}

// Shirley-Chiu concentric map: keeps the square's strata as disk strata.
vec2 concentric_disk(vec2 u) {
  float ox = 2.0f * u.x - 1.0f;
  float oy = 2.0f * u.y - 1.0f;
  if (ox == 0.0f && oy == 0.0f) {
    return vec2(0.0f);
  }
  float r;
  float theta;
  if (abs(ox) > abs(oy)) {
    r = ox;
    theta = (CAMHEAD_PI / 4.0f) * (oy / ox);
  } else {
    r = oy;
    theta = (CAMHEAD_PI / 2.0f) - (CAMHEAD_PI / 4.0f) * (ox / oy);
  }
  return vec2(r * cos(theta), r * sin(theta));
}

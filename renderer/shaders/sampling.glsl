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
  // One sample: its one cell is the square, and the general case below
  // gives the jitter alone, bit for bit, through six permutations and
  // divisions that cost over a tenth of a live 1-rpp frame on a CPU.
  if (n == 1u) {
    return vec2(cmj_randfloat(0u, p * 0x967a889bu), cmj_randfloat(0u, p * 0x368cc8b7u));
  }
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

// ---------------------------------------------------------------- Sobol'

// The low-discrepancy alternative for the camera ray (SAMPLER_SOBOL): the
// first four dimensions of Sobol' (Joe and Kuo's direction numbers), Owen-
// scrambled per pixel with a hash (Burley 2020, "Practical Hash-based Owen
// Scrambling"), the pixel jitter in the first two and the aperture point in
// the last two, so that pixel and lens are stratified jointly in 4-D rather
// than each in 2-D. Progressive: a sample does not depend on n, and the
// first 2^k samples of a pixel are a scrambled aligned block of the sequence.

// Sobol' dimension d (0..3) of sample i, as 32-bit fixed point. The
// direction numbers come from their recurrences (primitive polynomials 1,
// x + 1, x^2 + x + 1, x^3 + x + 1; initial m = {1}, {1, 3}, {1, 3, 1}), one
// per bit of i, so no table is needed in either language.
uint sobol_u32(uint i, uint d) {
  if (d == 0u) {
    return bitfieldReverse(i);
  }
  uint result = 0u;
  uint v1 = 0u; // V_{k-1}
  uint v2 = 0u; // V_{k-2}
  uint v3 = 0u; // V_{k-3}
  if (i == 0u) {
    return result;
  }
  uint k = 1u;
  do { // bottom-tested, as every loop here (kernel.glsl)
    uint v;
    if (k == 1u) {
      v = 0x80000000u;
    } else if (d == 1u) {
      v = v1 ^ (v1 >> 1u);
    } else if (k == 2u) {
      v = 0xc0000000u;
    } else if (d == 2u) {
      v = v2 ^ (v2 >> 2u) ^ v1;
    } else if (k == 3u) {
      v = 0x20000000u;
    } else {
      v = v3 ^ (v3 >> 3u) ^ v2;
    }
    if ((i & 1u) != 0u) {
      result ^= v;
    }
    v3 = v2;
    v2 = v1;
    v1 = v;
    i >>= 1u;
    ++k;
  } while (i != 0u);
  return result;
}

// Laine and Karras' hash, an Owen scramble of the bit-reversed value.
uint laine_karras_permutation(uint x, uint seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

uint nested_uniform_scramble(uint x, uint seed) {
  return bitfieldReverse(laine_karras_permutation(bitfieldReverse(x), seed));
}

// Sample s of the pixel pattern p as a point of [0, 1)^4: x, y the pixel
// jitter, z, w the aperture. The index is scrambled too (Burley's shuffle),
// which keeps aligned blocks aligned and decorrelates neighbouring pixels.
vec4 sobol_owen_4d(uint s, uint p) {
  uint i = nested_uniform_scramble(s, hash_u32(p ^ 0x3c6ef372u));
  float scale = 1.0f / 4294967296.0f;
  float x = float(nested_uniform_scramble(sobol_u32(i, 0u), hash_u32(p + 0x9e3779b9u)) >> 8u);
  float y = float(nested_uniform_scramble(sobol_u32(i, 1u), hash_u32(p + 0x7f4a7c15u)) >> 8u);
  float z = float(nested_uniform_scramble(sobol_u32(i, 2u), hash_u32(p + 0xf39cc060u)) >> 8u);
  float w = float(nested_uniform_scramble(sobol_u32(i, 3u), hash_u32(p + 0x5ced1fb7u)) >> 8u);
  // 24 bits each, so that the float is exact and below 1.
  return vec4(x, y, z, w) * (256.0f * scale);
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

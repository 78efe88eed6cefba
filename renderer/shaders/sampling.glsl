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
// scrambled with a hash (Burley 2020, "Practical Hash-based Owen
// Scrambling") and shifted by a key of each pixel's (SobolPixel, below),
// the pixel jitter in the first two and the aperture point in the last two,
// so that pixel and lens are stratified jointly in 4-D rather than each in
// 2-D. Progressive: a sample does not depend on n, and the first 2^k
// samples of a pixel are a scrambled aligned block of the sequence.

// Sobol' dimensions 1, 2 and 3 of sample i, as 32-bit fixed point
// (dimension 0 is the bit reversal of i): the XOR of the direction numbers
// of i's set bits. The numbers are those of the primitive polynomials
// x + 1, x^2 + x + 1 and x^3 + x + 1 with initial m = {1}, {1, 3},
// {1, 3, 1} (Joe and Kuo), 32 a dimension; the C++ loop visits the set
// bits only, and the three dimensions share it.
#ifdef __cplusplus
KERNEL_TABLE uint SOBOL_DIRECTIONS[96] = {
    0x80000000u, 0xc0000000u, 0xa0000000u, 0xf0000000u, 0x88000000u, 0xcc000000u,
    0xaa000000u, 0xff000000u, 0x80800000u, 0xc0c00000u, 0xa0a00000u, 0xf0f00000u,
    0x88880000u, 0xcccc0000u, 0xaaaa0000u, 0xffff0000u, 0x80008000u, 0xc000c000u,
    0xa000a000u, 0xf000f000u, 0x88008800u, 0xcc00cc00u, 0xaa00aa00u, 0xff00ff00u,
    0x80808080u, 0xc0c0c0c0u, 0xa0a0a0a0u, 0xf0f0f0f0u, 0x88888888u, 0xccccccccu,
    0xaaaaaaaau, 0xffffffffu, 0x80000000u, 0xc0000000u, 0x60000000u, 0x90000000u,
    0xe8000000u, 0x5c000000u, 0x8e000000u, 0xc5000000u, 0x68800000u, 0x9cc00000u,
    0xee600000u, 0x55900000u, 0x80680000u, 0xc09c0000u, 0x60ee0000u, 0x90550000u,
    0xe8808000u, 0x5cc0c000u, 0x8e606000u, 0xc5909000u, 0x6868e800u, 0x9c9c5c00u,
    0xeeee8e00u, 0x5555c500u, 0x8000e880u, 0xc0005cc0u, 0x60008e60u, 0x9000c590u,
    0xe8006868u, 0x5c009c9cu, 0x8e00eeeeu, 0xc5005555u, 0x80000000u, 0xc0000000u,
    0x20000000u, 0x50000000u, 0xf8000000u, 0x74000000u, 0xa2000000u, 0x93000000u,
    0xd8800000u, 0x25400000u, 0x59e00000u, 0xe6d00000u, 0x78080000u, 0xb40c0000u,
    0x82020000u, 0xc3050000u, 0x208f8000u, 0x51474000u, 0xfbea2000u, 0x75d93000u,
    0xa0858800u, 0x914e5400u, 0xdbe79e00u, 0x25db6d00u, 0x58800080u, 0xe54000c0u,
    0x79e00020u, 0xb6d00050u, 0x800800f8u, 0xc00c0074u, 0x200200a2u, 0x50050093u,
};

uvec3 sobol_u32_123(uint i) {
  uvec3 result = uvec3(0u, 0u, 0u);
  if (i == 0u) {
    return result;
  }
  do { // bottom-tested, as every loop here (kernel.glsl)
    uint k = uint(findLSB(i));
    result.x ^= SOBOL_DIRECTIONS[k];
    result.y ^= SOBOL_DIRECTIONS[32u + k];
    result.z ^= SOBOL_DIRECTIONS[64u + k];
    i &= i - 1u;
  } while (i != 0u);
  return result;
}
#else
// The same numbers on the GPU, made as the loop goes by the polynomials'
// recurrences (Bratley and Fox: v_k = a_1 v_(k-1) ^ ... ^ v_(k-s) ^
// v_(k-s) >> s) rather than read from the table: a table indexed per lane
// is a gather, and lavapipe spent over ten times a CMJ frame's time on it
// (bench/RESULTS.md, "The GPU executor reconstructs; its history in
// Sobol'"). Every bit of i, in registers alone.
uvec3 sobol_u32_123(uint i) {
  uvec3 result = uvec3(0u, 0u, 0u);
  uint d1 = 0x80000000u;                           // x + 1: v_k
  uint d2 = 0x80000000u, d2_before = 0u;           // x^2 + x + 1: v_k, v_(k-1)
  uint d3 = 0x80000000u, d3_1 = 0u, d3_2 = 0u;     // x^3 + x + 1: v_k, v_(k-1), v_(k-2)
  uint k = 0u;
  do {
    uint bit = 0u - ((i >> k) & 1u);
    result ^= uvec3(d1, d2, d3) & uvec3(bit);
    // The next direction numbers; the first ones of dimensions 2 and 3 are
    // their initial m (3 and 3, then 1 for dimension 3), not the recurrence's.
    d1 ^= d1 >> 1u;
    uint d2_next = k == 0u ? 0xc0000000u : d2 ^ d2_before ^ (d2_before >> 2u);
    d2_before = d2;
    d2 = d2_next;
    uint d3_next = k == 0u ? 0xc0000000u
                   : k == 1u ? 0x20000000u
                             : d3_1 ^ d3_2 ^ (d3_2 >> 3u);
    d3_2 = d3_1;
    d3_1 = d3;
    d3 = d3_next;
    ++k;
  } while (k < 32u);
  return result;
}
#endif

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

// The pixel's index on a Z-order (Morton) curve: the bits of x and y
// (each below 2^16) interleaved, so that every aligned run of 4^j indices
// is an aligned 2^j x 2^j block of pixels.
uint morton_index(uint x, uint y) {
  uvec2 v = uvec2(x, y) & uvec2(0xffffu);
  v = (v | (v << 8u)) & uvec2(0x00ff00ffu);
  v = (v | (v << 4u)) & uvec2(0x0f0f0f0fu);
  v = (v | (v << 2u)) & uvec2(0x33333333u);
  v = (v | (v << 1u)) & uvec2(0x55555555u);
  return v.x | (v.y << 1u);
}

// What one pixel's Sobol' samples are made of in one pass: the scramble
// every pixel shares, and the pixel's own digital shift (an XOR of each
// dimension's bits).
//
// A pixel's points are the pass's Owen-scrambled sequence shifted by its
// own key: an XOR maps every dyadic box onto one of the same size, so each
// pixel's first 2^k samples are as stratified as an Owen-scrambled net
// (and, the scramble being random, distributed as one), and sample i is
// still the same whatever the count (progressive). Across pixels, the keys
// are themselves Sobol' points taken in Z order (Ahmed and Wonka 2020,
// "Screen-Space Blue-Noise Diffusion of Monte Carlo Sampling Error via
// Hierarchical Ordering of Pixels"), so that sample i of the pixels of any
// aligned 2^j x 2^j block, the same sequence point shifted by each key, is
// a stratified set of 4^j points: one ray a pixel lands on 4^j different
// parts of the aperture, where independent pixels' rays clump. A blur
// circle's pixels, which the reconstruction averages (defocus_filter.h),
// take in parts of several such blocks: their rays are spread over the
// aperture rather than stratified exactly, and only where the pixels are
// at the same sample index (a fresh frame, or a history whose pixels took
// alike shares). Like Heitz et al.'s (2019) per-pixel XOR keys, built here
// rather than optimized.
struct SobolPixel {
  uint seed;   // the pass's: its index shuffle and Owen scrambles
  uvec4 shift; // the pixel's key: jitter x, y, aperture u, v
};

// Sobol' dimension 1 of index i, bit-reversed: i through the Pascal matrix
// mod 2, whose columns are the dimension's direction numbers. By Lucas'
// theorem bit k of i reaches bit j of the value where j's bits are among
// k's, so the product is a sum over bit supersets: five shifts, where
// sobol_u32_123 loops over i's bits.
uint sobol_reversed_dimension_1(uint i) {
  i ^= (i >> 1u) & 0x55555555u;
  i ^= (i >> 2u) & 0x33333333u;
  i ^= (i >> 4u) & 0x0f0f0f0fu;
  i ^= (i >> 8u) & 0x00ff00ffu;
  i ^= (i >> 16u) & 0x0000ffffu;
  return i;
}

// Sobol' dimensions 0 and 1 of index i as 32-bit fixed point, each Owen-
// scrambled with its own seed: nested_uniform_scramble(), whose first step
// is a reversal, of values found reversed (dimension 0 reversed is i).
uvec2 sobol_owen_2d(uint i, uint seed) {
  return uvec2(
      bitfieldReverse(laine_karras_permutation(i, hash_u32(seed + 0x2545f491u))),
      bitfieldReverse(
          laine_karras_permutation(sobol_reversed_dimension_1(i), hash_u32(seed + 0x9e3779b9u))));
}

SobolPixel sobol_pixel_for(uint x, uint y, uint seed) {
  uint z = morton_index(x, y);
  SobolPixel pixel;
  pixel.seed = seed;
  // The Z order shuffled as a tree (Burley's index scramble keeps aligned
  // runs aligned), once for the jitter's keys and once for the aperture's,
  // so that which quarter of a block takes which pair of strata changes
  // with the pass, and the pixel and aperture strata pair differently.
  uvec2 jitter = sobol_owen_2d(nested_uniform_scramble(z, hash_u32(seed ^ 0x1b873593u)),
                               hash_u32(seed ^ 0xcc9e2d51u));
  uvec2 aperture = sobol_owen_2d(nested_uniform_scramble(z, hash_u32(seed ^ 0xe6546b64u)),
                                 hash_u32(seed ^ 0x27d4eb2fu));
  pixel.shift = uvec4(jitter, aperture);
  return pixel;
}

// Sample s of a pass's sequence, before the pixels' keys, as 32-bit fixed
// point. The index is shuffled (Burley's shuffle keeps aligned blocks
// aligned), the same for every pixel, so that sample s of every pixel is
// one point of the sequence under the pixels' keys.
uvec4 sobol_scrambled_point(uint s, uint seed) {
  uint i = nested_uniform_scramble(s, hash_u32(seed ^ 0x3c6ef372u));
  uvec3 d123 = sobol_u32_123(i);
  return uvec4(nested_uniform_scramble(bitfieldReverse(i), hash_u32(seed + 0x9e3779b9u)),
               nested_uniform_scramble(d123.x, hash_u32(seed + 0x7f4a7c15u)),
               nested_uniform_scramble(d123.y, hash_u32(seed + 0xf39cc060u)),
               nested_uniform_scramble(d123.z, hash_u32(seed + 0x5ced1fb7u)));
}

#ifndef CAMHEAD_SOBOL_PASS_TABLE
// The GPU makes each point where a pixel needs it; the CPU frame renderer
// makes a pass's points once and the kernel reads them (cpu_kernel.h
// defines the macro and its own sobol_pass_point).
uvec4 sobol_pass_point(uint s, uint seed) {
  return sobol_scrambled_point(s, seed);
}
#endif

// Sample s of a pixel as a point of [0, 1)^4: x, y the pixel jitter, z, w
// the aperture.
vec4 sobol_owen_4d(uint s, SobolPixel pixel) {
  // 24 bits each, so that the float is exact and below 1.
  return vec4((sobol_pass_point(s, pixel.seed) ^ pixel.shift) >> 8u) * (1.0f / 16777216.0f);
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

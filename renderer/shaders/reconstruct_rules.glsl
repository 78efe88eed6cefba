// The reconstruction's rules for one pixel, written once for both
// executors: the CPU reference's defocus_filter.cpp includes this file as
// C++ (glm's functions for GLSL's), the GPU's reconstruct.glsl as GLSL.
// renderer/src/defocus_filter.h says what each rule is and why.
// The includer defines CUBE_ROOT(x): std::cbrt on the CPU, pow on the GPU.
#ifndef CUBE_ROOT
#error "reconstruct_rules.glsl: define CUBE_ROOT(x) before including it"
#endif

// A pixel's signed blur radius in pixels at its mean depth, from its
// accumulated depth sum and hit count (aux.x, aux.y; no hit: at infinity),
// for a lens blurring `blur_per_dioptre` (A f) pixels a dioptre, focused at
// 1 / inverse_focus.
float reconstruct_blur(vec4 aux, float blur_per_dioptre, float inverse_focus) {
  float inverse_depth = aux.y > 0.0f ? aux.y / aux.x : 0.0f;
  return blur_per_dioptre * (inverse_depth - inverse_focus);
}

// The pixel's Gaussian, sigma = strength sqrt(|blur|) / samples^(1/3): at
// most half the widest reach, so that it is cut at 2 sigma (and a hit at
// depth 0, an infinite blur, is bounded). Where the blur is NaN the CPU's
// sigma is NaN, which no comparison with the least sigma passes; a GPU's min
// may give the bound instead, whose pass then finds no neighbour alike.
float reconstruct_sigma_of(float blur, float samples, float strength, float max_reach) {
  return min(strength * sqrt(abs(blur)) / CUBE_ROOT(max(samples, 1.0f)), 0.5f * max_reach);
}

// How many pixels either side a pass reaches: 2 sigma, at most max_reach.
int reconstruct_reach_of(float sigma, float max_reach) {
  return int(min(ceil(2.0f * sigma), max_reach));
}

// Whether a neighbour of blur radius `c` may lend its samples to a pixel of
// blur radius `b`: their blurs differ by no more than the larger of the two
// (or a pixel).
bool reconstruct_blurs_alike(float b, float c) {
  return abs(c - b) <= max(max(1.0f, abs(b)), abs(c));
}

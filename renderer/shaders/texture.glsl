// Albedo textures (layout.h, BINDING_SURFACES): the texture coordinates of a
// point on a textured triangle, and the texture's trilinear mip-mapped value
// there, at the level whose texels are as wide as the patch of surface that
// one camera sample stands for. Shared by GLSL and C++ (kernel.glsl's rules).
//
// Expects: surface_texel_at(), frame (FrameParams).

// Where level `level` of a texture starts, and its size.
void texture_level(uint base, uint width, uint height, uint level, OUT(uint) start,
                   OUT(uint) w, OUT(uint) h) {
  start = base;
  w = width;
  h = height;
  if (level > 0u) {
    uint l = 0u;
    do {
      start += (w * h + 1u) / 2u;
      w = max(w / 2u, 1u);
      h = max(h / 2u, 1u);
      ++l;
    } while (l < level);
  }
}

// Pixel (x, y) of a level, clamped to its edge.
vec3 texture_pixel(uint start, uint w, uint h, int x, int y) {
  uint i = uint(clamp(y, 0, int(h) - 1)) * w + uint(clamp(x, 0, int(w) - 1));
  uvec4 word = surface_texel_at(start + i / 2u);
  bool odd = (i & 1u) != 0u;
  vec2 rg = unpackHalf2x16(odd ? word.z : word.x);
  vec2 b = unpackHalf2x16(odd ? word.w : word.y);
  return vec3(rg.x, rg.y, b.x);
}

// A level read between its pixels' centres at (u, v), (0, 0) its top-left
// corner and (1, 1) its bottom-right one.
vec3 texture_bilinear(uint start, uint w, uint h, float u, float v) {
  float px = u * float(w) - 0.5f;
  float py = v * float(h) - 0.5f;
  // Clamped first: the edge pixel is as far as a read goes, and a float out
  // of int's range (or NaN) must not reach the conversion.
  px = px > -1.0f ? min(px, float(w)) : -1.0f;
  py = py > -1.0f ? min(py, float(h)) : -1.0f;
  float fx = floor(px);
  float fy = floor(py);
  int x = int(fx);
  int y = int(fy);
  vec3 top = mix(texture_pixel(start, w, h, x, y), texture_pixel(start, w, h, x + 1, y), px - fx);
  vec3 bottom =
      mix(texture_pixel(start, w, h, x, y + 1), texture_pixel(start, w, h, x + 1, y + 1), px - fx);
  return mix(top, bottom, py - fy);
}

// The albedo of `material` at point p of primitive `prim` (p and n, the unit
// normal, in the compiled frame), met along a ray of direction `dir` that
// has travelled `travelled` metres from the lens. Untextured: its colour.
//
// A camera sample stands for 1 / samples of its pixel, a square
// filter_width / sqrt(samples) pixels wide, which a ray that has travelled
// t metres spreads to t / focal_px times that on a surface facing it; a
// surface at angle theta to the ray stretches it by 1 / cos(theta) one way
// alone, so the level is chosen for the square of the same area. The
// samples of a pixel then integrate the texture over the pixel, as a sensor
// does, with little more blur than the pixel's own.
vec3 surface_albedo(Material material, Primitive prim, vec3 p, vec3 n, vec3 dir, float travelled) {
  uint width = floatBitsToUint(material.params.y);
  uint record = floatBitsToUint(prim.p1.w);
  if (!KERNEL_HAS(KERNEL_TEXTURES) || width == 0u || record == 0u) {
    return vec3(material.color);
  }
  uint height = floatBitsToUint(material.params.z);
  uvec4 r0 = surface_texel_at((record - 1u) * SURFACE_UV_TEXELS);
  uvec4 r1 = surface_texel_at((record - 1u) * SURFACE_UV_TEXELS + 1u);
  // p's barycentric coordinates (b1, b2) on the triangle v0 + b1 e1 + b2 e2.
  vec3 e1 = vec3(prim.p1);
  vec3 e2 = vec3(prim.p2);
  vec3 d = p - vec3(prim.p0);
  float d00 = dot(e1, e1);
  float d01 = dot(e1, e2);
  float d11 = dot(e2, e2);
  float d20 = dot(d, e1);
  float d21 = dot(d, e2);
  float inv = 1.0f / (d00 * d11 - d01 * d01);
  float b1 = (d11 * d20 - d01 * d21) * inv;
  float b2 = (d00 * d21 - d01 * d20) * inv;
  float u0 = uintBitsToFloat(r0.x);
  float v0 = uintBitsToFloat(r0.y);
  float u = u0 + b1 * (uintBitsToFloat(r0.z) - u0) + b2 * (uintBitsToFloat(r1.x) - u0);
  float v = v0 + b1 * (uintBitsToFloat(r0.w) - v0) + b2 * (uintBitsToFloat(r1.y) - v0);

  float sample_px = frame.lens.w / sqrt(float(max(frame.sampling.z, 1u)));
  float footprint_m =
      travelled * sample_px / (frame.lens.z * sqrt(max(abs(dot(n, dir)), 1e-3f)));
  float texels = footprint_m * uintBitsToFloat(r1.z) * sqrt(float(width) * float(height));
  uint levels = uint(findMSB(max(width, height))) + 1u;
  float lod = clamp(log2(max(texels, 1e-6f)), 0.0f, float(levels - 1u));
  uint level = uint(lod);
  uint start = 0u;
  uint w = 0u;
  uint h = 0u;
  texture_level(floatBitsToUint(material.color.w), width, height, level, start, w, h);
  vec3 albedo = texture_bilinear(start, w, h, u, v);
  float blend = lod - float(level);
  if (blend > 0.0f) {
    uint next_start = start + (w * h + 1u) / 2u;
    albedo = mix(albedo,
                 texture_bilinear(next_start, max(w / 2u, 1u), max(h / 2u, 1u), u, v), blend);
  }
  return vec3(material.color) * albedo;
}

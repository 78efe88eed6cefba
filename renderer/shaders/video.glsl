// Video code values <-> linear light, shared by GLSL and C++ (as kernel.glsl:
// C++ includes it with glm supplying the vocabulary, renderer/src/video_codec.h).
//
// A camera frame becomes the plate I_c in linear RGB, and the composite goes
// back into each output's code values, by the same functions on both
// executors. Pass-through (a pixel nothing virtual touches leaves as it came)
// holds because every step here is inverted exactly in float before rounding:
// - no clamping before the last step: a Y'CbCr triple outside the RGB cube
//   decodes to negative or >1 values, which the sign-symmetric transfer curve
//   and the inverse matrix take back to the same codes;
// - chroma is upsampled by repetition (each pixel takes its pair's or its
//   2x2 block's Cb Cr), and downsampled by the mean, which gives back a
//   repeated value exactly;
// - codes are rounded half up once, at the end.
// The transfer curve is sRGB's (IEC 61966-2-1) for every format: BT.709 and
// sRGB share primaries, and webcams and capture cards encode with it.
#ifndef CAMHEAD_RENDERER_VIDEO_GLSL
#define CAMHEAD_RENDERER_VIDEO_GLSL

#define VIDEO_MATRIX_BT601 0u
#define VIDEO_MATRIX_BT709 1u
#define VIDEO_RANGE_LIMITED 0u
#define VIDEO_RANGE_FULL 1u

// Kr, Kb of the matrix (BT.601-7, BT.709-6).
vec2 video_kr_kb(uint matrix) {
  return matrix == VIDEO_MATRIX_BT601 ? vec2(0.299f, 0.114f) : vec2(0.2126f, 0.0722f);
}

float srgb_decode(float v) {
  float a = abs(v);
  float lin = a <= 0.04045f ? a / 12.92f : pow((a + 0.055f) / 1.055f, 2.4f);
  return v < 0.0f ? -lin : lin;
}

float srgb_encode(float v) {
  float a = abs(v);
  float enc = a <= 0.0031308f ? 12.92f * a : 1.055f * pow(a, 1.0f / 2.4f) - 0.055f;
  return v < 0.0f ? -enc : enc;
}

// The curve as the conversions below apply it: these functions on the GPU;
// on the CPU (video_codec.cpp) tables of them, within 1e-6 of the values and
// many times faster than pow (the round trip's budget is half a code value).
#ifndef VIDEO_SRGB_DECODE
#define VIDEO_SRGB_DECODE srgb_decode
#define VIDEO_SRGB_ENCODE srgb_encode
#endif

vec3 srgb_decode3(vec3 v) {
  return vec3(VIDEO_SRGB_DECODE(v.x), VIDEO_SRGB_DECODE(v.y), VIDEO_SRGB_DECODE(v.z));
}

vec3 srgb_encode3(vec3 v) {
  return vec3(VIDEO_SRGB_ENCODE(v.x), VIDEO_SRGB_ENCODE(v.y), VIDEO_SRGB_ENCODE(v.z));
}

// Y'CbCr codes (0..255) -> Y' and Pb Pr (Y' 0..1, Pb Pr -0.5..0.5 in range).
vec3 video_normalise_ycbcr(vec3 codes, uint range) {
  return range == VIDEO_RANGE_FULL
             ? vec3(codes.x / 255.0f, (codes.y - 128.0f) / 255.0f, (codes.z - 128.0f) / 255.0f)
             : vec3((codes.x - 16.0f) / 219.0f, (codes.y - 128.0f) / 224.0f,
                    (codes.z - 128.0f) / 224.0f);
}

// Y' Pb Pr -> codes, before rounding.
vec3 video_code_ycbcr(vec3 ypbpr, uint range) {
  return range == VIDEO_RANGE_FULL
             ? vec3(ypbpr.x * 255.0f, ypbpr.y * 255.0f + 128.0f, ypbpr.z * 255.0f + 128.0f)
             : vec3(ypbpr.x * 219.0f + 16.0f, ypbpr.y * 224.0f + 128.0f,
                    ypbpr.z * 224.0f + 128.0f);
}

// Y' Pb Pr -> linear RGB.
vec3 video_ypbpr_to_linear(vec3 ypbpr, uint matrix) {
  vec2 k = video_kr_kb(matrix);
  float r = ypbpr.x + 2.0f * (1.0f - k.x) * ypbpr.z;
  float b = ypbpr.x + 2.0f * (1.0f - k.y) * ypbpr.y;
  float g = (ypbpr.x - k.x * r - k.y * b) / (1.0f - k.x - k.y);
  return srgb_decode3(vec3(r, g, b));
}

// Linear RGB -> Y' Pb Pr.
vec3 video_linear_to_ypbpr(vec3 linear, uint matrix) {
  vec2 k = video_kr_kb(matrix);
  vec3 e = srgb_encode3(linear);
  float y = k.x * e.x + (1.0f - k.x - k.y) * e.y + k.y * e.z;
  return vec3(y, (e.z - y) / (2.0f * (1.0f - k.y)), (e.x - y) / (2.0f * (1.0f - k.x)));
}

// An 8-bit R'G'B' code triple -> linear RGB, and back (before rounding).
vec3 video_rgb_codes_to_linear(vec3 codes) {
  return srgb_decode3(codes / 255.0f);
}

vec3 video_linear_to_rgb_codes(vec3 linear) {
  return srgb_encode3(linear) * 255.0f;
}

// The one rounding step: half up, into 0..255.
uint video_round_code(float code) {
  return uint(clamp(floor(code + 0.5f), 0.0f, 255.0f));
}

#endif

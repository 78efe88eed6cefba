#version 450
// The camera frame (BINDING_VIDEO_IN, video.frames[0]) into the linear plate,
// a block of 4 x 2 pixels per invocation: the steps of video_codec.cpp's
// decode_row, so both executors see the same plate.
#extension GL_GOOGLE_include_directive : require
#define CAMHEAD_WRITES_PLATE
#include "buffers.glsl"
#include "video.glsl"

layout(local_size_x = VIDEO_LOCAL_SIZE, local_size_y = VIDEO_LOCAL_SIZE) in;

// The camera frame's format (VIDEO_*, layout.h), one pipeline per format:
// lavapipe runs both sides of every branch, so a run-time switch would
// decode each pixel in all five.
layout(constant_id = 1) const uint VIDEO_FORMAT = VIDEO_YUYV;

uint byte_in(uint first_word, uint offset) {
  uint word = texelFetch(video_in_words, int(first_word + offset / 4u)).x;
  return (word >> (8u * (offset % 4u))) & 0xffu;
}

vec3 ycbcr(VideoParams f, uint y, uint cb, uint cr) {
  vec3 ypbpr = video_normalise_ycbcr(vec3(float(y), float(cb), float(cr)), f.format.z);
  return video_ypbpr_to_linear(ypbpr, f.format.y);
}

void main() {
  uvec3 id;
  if (!grid_invocation(group_list_video(), uvec2(VIDEO_LOCAL_SIZE), id)) {
    return;
  }
  VideoParams f = video.frames[0];
  uint width = f.size.x;
  uint x0 = 4u * id.x;
  uint y0 = 2u * id.y;
  if (x0 >= width || y0 >= f.size.y) {
    return;
  }
  uint stride = f.size.z;
  uint base = f.format.w;
  for (uint dy = 0u; dy < 2u; ++dy) {
    uint y = y0 + dy;
    uint row = y * stride;
    for (uint dx = 0u; dx < 4u; ++dx) {
      uint x = x0 + dx;
      vec3 rgb;
      if (VIDEO_FORMAT == VIDEO_YUYV) {
        uint pair = row + 4u * (x / 2u);
        rgb = ycbcr(f, byte_in(base, pair + 2u * (x % 2u)), byte_in(base, pair + 1u),
                    byte_in(base, pair + 3u));
      } else if (VIDEO_FORMAT == VIDEO_NV12) {
        uint chroma = stride * f.size.y + (y / 2u) * stride + 2u * (x / 2u);
        rgb = ycbcr(f, byte_in(base, row + x), byte_in(base, chroma), byte_in(base, chroma + 1u));
      } else if (VIDEO_FORMAT == VIDEO_XRGB8888) {
        uint p = row + 4u * x; // B G R X
        rgb = video_rgb_codes_to_linear(vec3(float(byte_in(base, p + 2u)),
                                             float(byte_in(base, p + 1u)), float(byte_in(base, p))));
      } else {
        uint p = row + 3u * x;
        vec3 codes = vec3(float(byte_in(base, p)), float(byte_in(base, p + 1u)),
                          float(byte_in(base, p + 2u)));
        rgb = video_rgb_codes_to_linear(VIDEO_FORMAT == VIDEO_BGR24 ? codes.zyx : codes);
      }
      imageStore(plate, int(y * width + x), vec4(rgb, 0.0f));
    }
  }
}

#version 450
// The composite (BINDING_OUT_COMPOSITE) into output gl_GlobalInvocationID.z
// (video.frames[1 + z], BINDING_VIDEO_OUT), a block of 4 x 2 pixels per
// invocation, whole uints only: the steps of video_codec.cpp's encode_rows,
// so both executors give the same codes (within the last float bit).
#extension GL_GOOGLE_include_directive : require
#define CAMHEAD_READS_COMPOSITE
#include "buffers.glsl"
#include "video.glsl"

layout(local_size_x = VIDEO_LOCAL_SIZE, local_size_y = VIDEO_LOCAL_SIZE) in;

// The output's format (VIDEO_*, layout.h), one pipeline per format and a
// dispatch per output: lavapipe runs both sides of every branch, so a
// run-time switch would encode each block in all five.
layout(constant_id = 1) const uint VIDEO_FORMAT = VIDEO_YUYV;

uint pack4(uint a, uint b, uint c, uint d) {
  return a | (b << 8u) | (c << 16u) | (d << 24u);
}

void main() {
  uvec3 id;
  if (!grid_invocation(group_list_video(), uvec2(VIDEO_LOCAL_SIZE), id)) {
    return;
  }
  uint z = id.z;
  if (z >= video.count.x) {
    return;
  }
  VideoParams f = video.frames[1u + z];
  uint width = f.size.x;
  uint x0 = 4u * id.x;
  uint y0 = 2u * id.y;
  if (x0 >= width || y0 >= f.size.y) {
    return;
  }
  uint stride = f.size.z;
  uint base = f.format.w;
  uint matrix = f.format.y;
  uint range = f.format.z;

  vec3 px[8]; // row-major: (dx, dy) at dy * 4 + dx
  for (uint i = 0u; i < 8u; ++i) {
    px[i] = vec3(imageLoad(out_composite, int((y0 + i / 4u) * width + x0 + i % 4u)));
  }

  if (VIDEO_FORMAT == VIDEO_YUYV) {
    for (uint dy = 0u; dy < 2u; ++dy) {
      for (uint pair = 0u; pair < 2u; ++pair) {
        vec3 a = video_linear_to_ypbpr(px[dy * 4u + 2u * pair], matrix);
        vec3 b = video_linear_to_ypbpr(px[dy * 4u + 2u * pair + 1u], matrix);
        vec3 chroma = video_code_ycbcr(vec3(0.0f, 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)), range);
        uint word = ((y0 + dy) * stride + 2u * (x0 + 2u * pair)) / 4u;
        video_out[base + word] =
            pack4(video_round_code(video_code_ycbcr(a, range).x), video_round_code(chroma.y),
                  video_round_code(video_code_ycbcr(b, range).x), video_round_code(chroma.z));
      }
    }
  } else if (VIDEO_FORMAT == VIDEO_NV12) {
    vec3 v[8];
    for (uint i = 0u; i < 8u; ++i) {
      v[i] = video_linear_to_ypbpr(px[i], matrix);
    }
    for (uint dy = 0u; dy < 2u; ++dy) {
      uint l[4];
      for (uint dx = 0u; dx < 4u; ++dx) {
        l[dx] = video_round_code(video_code_ycbcr(v[dy * 4u + dx], range).x);
      }
      video_out[base + ((y0 + dy) * stride + x0) / 4u] = pack4(l[0], l[1], l[2], l[3]);
    }
    uint c[4];
    for (uint block = 0u; block < 2u; ++block) {
      // The order of the CPU's sum: (0,0), (1,0), (0,1), (1,1).
      vec3 sum = v[2u * block] + v[2u * block + 1u] + v[4u + 2u * block] + v[4u + 2u * block + 1u];
      vec3 codes = video_code_ycbcr(vec3(0.0f, 0.25f * sum.y, 0.25f * sum.z), range);
      c[2u * block] = video_round_code(codes.y);
      c[2u * block + 1u] = video_round_code(codes.z);
    }
    video_out[base + (stride * f.size.y + (y0 / 2u) * stride + x0) / 4u] =
        pack4(c[0], c[1], c[2], c[3]);
  } else if (VIDEO_FORMAT == VIDEO_XRGB8888) {
    for (uint i = 0u; i < 8u; ++i) {
      vec3 codes = video_linear_to_rgb_codes(px[i]);
      video_out[base + ((y0 + i / 4u) * stride + 4u * (x0 + i % 4u)) / 4u] =
          pack4(video_round_code(codes.z), video_round_code(codes.y), video_round_code(codes.x),
                255u);
    }
  } else {
    bool bgr = VIDEO_FORMAT == VIDEO_BGR24;
    for (uint dy = 0u; dy < 2u; ++dy) {
      uint b[12];
      for (uint dx = 0u; dx < 4u; ++dx) {
        vec3 codes = video_linear_to_rgb_codes(px[dy * 4u + dx]);
        if (bgr) {
          codes = codes.zyx;
        }
        b[3u * dx] = video_round_code(codes.x);
        b[3u * dx + 1u] = video_round_code(codes.y);
        b[3u * dx + 2u] = video_round_code(codes.z);
      }
      uint word = ((y0 + dy) * stride + 3u * x0) / 4u;
      for (uint k = 0u; k < 3u; ++k) {
        video_out[base + word + k] = pack4(b[4u * k], b[4u * k + 1u], b[4u * k + 2u], b[4u * k + 3u]);
      }
    }
  }
}

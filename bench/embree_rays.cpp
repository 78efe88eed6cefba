#include "embree_rays.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include <pmmintrin.h>
#include <xmmintrin.h>

namespace camhead::bench {
namespace {

using Clock = std::chrono::steady_clock;
using renderer::cpu::CpuKernel;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr int kBlock = 4; // pixels per side of a block; 16 = one packet

void set_ray(RTCRayHit &rh, const CpuKernel::Ray &ray) {
  rh.ray.org_x = ray.origin.x;
  rh.ray.org_y = ray.origin.y;
  rh.ray.org_z = ray.origin.z;
  rh.ray.tnear = 0.0f;
  rh.ray.dir_x = ray.dir.x;
  rh.ray.dir_y = ray.dir.y;
  rh.ray.dir_z = ray.dir.z;
  rh.ray.time = 0.0f;
  rh.ray.tfar = CAMHEAD_NO_HIT;
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

// Camera rays of one 4 x 4 block, sample-major: rays[s * 16 + lane]. Lanes
// outside the image get tfar = -inf (Embree skips them) and valid = 0.
// rtcIntersect16 reads the valid mask with aligned loads.
using ValidMask = std::array<int, kBlock * kBlock>;

void make_block_rays(CpuKernel &kernel, int bx, int by, std::vector<RTCRayHit> &rays,
                     ValidMask &valid) {
  const auto width = int(kernel.frame.image.x), height = int(kernel.frame.image.y);
  const uint32_t n = kernel.frame.sampling.z;
  for (int lane = 0; lane < kBlock * kBlock; ++lane) {
    const int x = bx * kBlock + lane % kBlock, y = by * kBlock + lane / kBlock;
    const bool inside = x < width && y < height;
    valid[lane] = inside ? -1 : 0;
    const uint32_t pattern =
        inside ? kernel.pixel_pattern_for(uint32_t(x), uint32_t(y), uint32_t(width),
                                          kernel.frame.sampling.w)
               : 0u;
    const CpuKernel::SobolPixel sobol =
        inside ? kernel.camera_sobol_pixel(uint32_t(x), uint32_t(y), kernel.frame.sampling.w)
               : CpuKernel::SobolPixel{};
    for (uint32_t s = 0; s < n; ++s) {
      RTCRayHit &rh = rays[s * kBlock * kBlock + lane];
      if (inside) {
        set_ray(rh, kernel.camera_ray(uint32_t(x), uint32_t(y), s, n, pattern, sobol));
      } else {
        set_ray(rh, CpuKernel::Ray{glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, 1.0f)});
        rh.ray.tfar = -INFINITY;
      }
    }
  }
}

struct Tally {
  double gen_s = 0.0;
  double trace_s = 0.0;
  std::uint64_t hits = 0;
};

void count_hit(const RTCRayHit &rh, Tally &tally) {
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    ++tally.hits;
  }
}

void trace_block(RTCScene scene, Mode mode, std::vector<RTCRayHit> &rays, const ValidMask &valid,
                 Tally &tally) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const std::size_t lanes = kBlock * kBlock;
  if (mode == Mode::single) {
    for (RTCRayHit &rh : rays) {
      if (rh.ray.tfar >= 0.0f) {
        rtcIntersect1(scene, &context, &rh);
      }
    }
  } else if (mode == Mode::stream) {
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect1M(scene, &context, rays.data(), unsigned(rays.size()), sizeof(RTCRayHit));
  } else {
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(64) RTCRayHit16 packet;
    for (std::size_t base = 0; base < rays.size(); base += lanes) {
      for (std::size_t l = 0; l < lanes; ++l) {
        const RTCRay &r = rays[base + l].ray;
        packet.ray.org_x[l] = r.org_x;
        packet.ray.org_y[l] = r.org_y;
        packet.ray.org_z[l] = r.org_z;
        packet.ray.tnear[l] = r.tnear;
        packet.ray.dir_x[l] = r.dir_x;
        packet.ray.dir_y[l] = r.dir_y;
        packet.ray.dir_z[l] = r.dir_z;
        packet.ray.time[l] = 0.0f;
        packet.ray.tfar[l] = r.tfar;
        packet.ray.mask[l] = ~0u;
        packet.ray.id[l] = unsigned(l);
        packet.ray.flags[l] = 0;
        packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid.data(), scene, &context, &packet);
      for (std::size_t l = 0; l < lanes; ++l) {
        rays[base + l].ray.tfar = packet.ray.tfar[l];
        rays[base + l].hit.geomID = packet.hit.geomID[l];
      }
    }
  }
  for (const RTCRayHit &rh : rays) {
    count_hit(rh, tally);
  }
}

} // namespace

const char *mode_name(Mode mode) {
  switch (mode) {
  case Mode::single:
    return "rtcIntersect1";
  case Mode::packet16:
    return "rtcIntersect16";
  case Mode::stream:
    return "rtcIntersect1M";
  }
  return "?";
}

EmbreeFrame embree_frame(RTCScene scene, CpuKernel &kernel, Mode mode, int threads) {
  const int bw = (int(kernel.frame.image.x) + kBlock - 1) / kBlock;
  const int bh = (int(kernel.frame.image.y) + kBlock - 1) / kBlock;
  std::atomic<int> next{0};
  std::vector<Tally> tallies(static_cast<std::size_t>(threads));
  auto worker = [&](int t) {
    // Flush denormals to zero, as Embree's documentation asks of every
    // thread that traces.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    std::vector<RTCRayHit> rays(std::size_t(kBlock * kBlock) * kernel.frame.sampling.z);
    alignas(64) ValidMask valid{};
    Tally &tally = tallies[std::size_t(t)];
    for (int b = next.fetch_add(1); b < bw * bh; b = next.fetch_add(1)) {
      const auto t0 = Clock::now();
      make_block_rays(kernel, b % bw, b / bw, rays, valid);
      const auto t1 = Clock::now();
      trace_block(scene, mode, rays, valid, tally);
      tally.gen_s += std::chrono::duration<double>(t1 - t0).count();
      tally.trace_s += seconds_since(t1);
    }
  };
  const auto start = Clock::now();
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    pool.emplace_back(worker, t);
  }
  worker(0);
  for (std::thread &thread : pool) {
    thread.join();
  }
  EmbreeFrame frame;
  frame.wall_s = seconds_since(start);
  for (const Tally &tally : tallies) {
    frame.trace_s += tally.trace_s;
    frame.hits += tally.hits;
  }
  return frame;
}

// ---------------------------------------------------------------- checks

double hit_agreement(RTCScene scene, CpuKernel &kernel, int step) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const uint32_t width = kernel.frame.image.x, height = kernel.frame.image.y;
  const uint32_t n = kernel.frame.sampling.z;
  std::uint64_t agree = 0, total = 0;
  for (uint32_t y = 0; y < height; y += uint32_t(step)) {
    for (uint32_t x = 0; x < width; x += uint32_t(step)) {
      const uint32_t pattern = kernel.pixel_pattern_for(x, y, width, kernel.frame.sampling.w);
      const CpuKernel::SobolPixel sobol = kernel.camera_sobol_pixel(x, y, kernel.frame.sampling.w);
      for (uint32_t s = 0; s < n; ++s) {
        const CpuKernel::Ray ray = kernel.camera_ray(x, y, s, n, pattern, sobol);
        RTCRayHit rh;
        set_ray(rh, ray);
        rtcIntersect1(scene, &context, &rh);
        const CpuKernel::Hit hit = kernel.closest_hit(ray, 0.0f, CAMHEAD_NO_HIT, false);
        const bool embree_hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        const bool camhead_hit = hit.t != CAMHEAD_NO_HIT;
        agree += embree_hit == camhead_hit &&
                 (!embree_hit || std::abs(rh.ray.tfar - hit.t) <= 1e-3f * std::max(1.0f, hit.t));
        ++total;
      }
    }
  }
  return double(agree) / double(std::max<std::uint64_t>(total, 1));
}

} // namespace camhead::bench

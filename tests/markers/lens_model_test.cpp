// The renderer's lens model (renderer/shaders/lens_model.glsl) against
// OpenCV's: a virtual point lands where cv::projectPoints puts a real point
// at the same place through the same coefficients (issue 25, test 4), for
// barrel, pincushion and tangential lenses with an off-centre principal
// point and non-square pixels, on the host's projection and on both
// executors' renders.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <opencv2/calib3d.hpp>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/gpu_tracer.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

struct Lens {
  const char *name;
  renderer::LensModel model;
};

// Strong enough that a pinhole would be tens of pixels off at the corners.
std::vector<Lens> lenses() {
  renderer::LensModel barrel;
  barrel.k1 = -0.28f;
  barrel.k2 = 0.09f;
  barrel.principal_point = {0.52f, 0.47f};
  renderer::LensModel pincushion;
  pincushion.k1 = 0.22f;
  pincushion.k2 = -0.05f;
  pincushion.k3 = 0.02f;
  pincushion.fy_over_fx = 1.01f;
  renderer::LensModel tangential;
  tangential.k1 = -0.05f;
  tangential.p1 = 0.012f;
  tangential.p2 = -0.009f;
  tangential.principal_point = {0.49f, 0.515f};
  return {{"barrel", barrel}, {"pincushion", pincushion}, {"tangential", tangential}};
}

// A camera at the origin looking down -Z at a 320x240 frame, 0.8 rad wide.
renderer::Scene empty_scene() {
  renderer::Scene scene;
  scene.render.width = 320;
  scene.render.height = 240;
  scene.camera.focal_length_mm = 40.0f;
  scene.camera.sensor_width_mm = 36.0f;
  scene.materials.push_back({"grey", renderer::MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  return scene;
}

renderer::gpu::FrameParams frame_of(const renderer::Scene &scene, const renderer::LensModel &lens,
                                    int rpp) {
  renderer::FrameCamera camera = renderer::scene_camera(scene);
  camera.lens_model = lens;
  return renderer::make_frame_params(scene, camera, rpp);
}

// Where OpenCV puts world points seen by `frame`'s camera: its axes are
// right, down and forward.
std::vector<cv::Point2d> opencv_projection(const renderer::gpu::FrameParams &frame,
                                           const std::vector<glm::dvec3> &world) {
  const glm::dvec3 right(frame.cam_right), up(frame.cam_up), forward(frame.cam_forward);
  const glm::dvec3 pupil(frame.cam_position);
  std::vector<cv::Point3d> in_camera;
  for (const glm::dvec3 &p : world)
    in_camera.emplace_back(glm::dot(p - pupil, right), -glm::dot(p - pupil, up),
                           glm::dot(p - pupil, forward));
  const cv::Matx33d k(frame.lens.z, 0.0, frame.projection.x, 0.0,
                      double(frame.lens.z) * double(frame.projection.z), frame.projection.y, 0.0,
                      0.0, 1.0);
  const std::vector<double> distortion{frame.distortion.x, frame.distortion.y, frame.distortion.z,
                                       frame.distortion.w, frame.projection.w};
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(in_camera, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, distortion, pixels);
  return pixels;
}

TEST(LensModel, HostProjectionIsOpenCvs) {
  const renderer::Scene scene = empty_scene();
  for (const Lens &lens : lenses()) {
    const renderer::gpu::FrameParams frame = frame_of(scene, lens.model, 1);
    ASSERT_TRUE(renderer::has_lens_model(frame)) << lens.name;
    // Points across the whole view, out to its corners, at several depths.
    std::vector<glm::dvec3> world;
    for (const double depth : {0.7, 3.0, 40.0})
      for (double v = 0.0; v <= 240.0; v += 30.0)
        for (double u = 0.0; u <= 320.0; u += 40.0) {
          const glm::vec2 ideal = renderer::pixel_to_ideal(frame, glm::vec2(u, v));
          world.push_back(depth * glm::dvec3(ideal.x, -ideal.y, -1.0));
        }
    const std::vector<cv::Point2d> expected = opencv_projection(frame, world);
    double worst = 0.0;
    for (std::size_t i = 0; i < world.size(); ++i) {
      const auto pixel = renderer::project_to_pixel(frame, glm::vec3(world[i]));
      ASSERT_TRUE(pixel);
      worst = std::max(worst, std::hypot(pixel->x - expected[i].x, pixel->y - expected[i].y));
    }
    std::printf("%s: the host's projection is %.2e px from OpenCV's at worst\n", lens.name, worst);
    EXPECT_LT(worst, 0.05) << lens.name;
  }
}

// The preimage the kernels trace through is the one lens_distort takes back
// to the pixel: Newton's six steps have converged over the whole frame.
TEST(LensModel, PreimagesGoBackToTheirPixels) {
  const renderer::Scene scene = empty_scene();
  for (const Lens &lens : lenses()) {
    const renderer::gpu::FrameParams frame = frame_of(scene, lens.model, 1);
    double worst = 0.0;
    for (float v = -2.0f; v <= 242.0f; v += 2.0f)
      for (float u = -2.0f; u <= 322.0f; u += 2.0f) {
        const glm::vec2 back =
            renderer::ideal_to_pixel(frame, renderer::pixel_to_ideal(frame, {u, v}));
        worst = std::max(worst, double(glm::length(back - glm::vec2(u, v))));
      }
    EXPECT_LT(worst, 1e-3) << lens.name;
  }
}

// Small squares facing the camera, over the frame and into its corners:
// the centroid of each one's coverage (the mask) is where OpenCV projects
// its centre. A square's image centroid and its centre's image part by the
// lens's curvature over the square, under a thousandth of a pixel here.
TEST(LensModel, RenderedPointsLandWhereOpenCvProjectsThem) {
  constexpr double kDepth = 4.0, kSide = 0.08; // about 7 px
  constexpr int kRpp = 64;
  for (const Lens &lens : lenses()) {
    renderer::Scene scene = empty_scene();
    const renderer::gpu::FrameParams frame = frame_of(scene, lens.model, kRpp);
    std::vector<glm::dvec3> centres;
    for (float v = 24.0f; v <= 216.0f; v += 48.0f)
      for (float u = 24.0f; u <= 296.0f; u += 68.0f) {
        const glm::vec2 ideal = renderer::pixel_to_ideal(frame, {u, v});
        centres.push_back(kDepth * glm::dvec3(ideal.x, -ideal.y, -1.0));
        renderer::Object square;
        square.type = renderer::ShapeType::plane;
        square.center = glm::vec3(centres.back());
        square.rotation_deg = {90.0f, 0.0f, 0.0f}; // facing the camera
        square.size = glm::vec3(float(kSide), 1.0f, float(kSide));
        scene.objects.push_back(square);
      }
    const renderer::CompiledScene compiled = renderer::compile_scene(scene);
    const std::vector<cv::Point2d> expected = opencv_projection(frame, centres);
    std::vector<std::pair<std::string, renderer::RenderResult>> renders;
    renders.emplace_back("CPU reference", renderer::render_cpu(compiled, frame));
    if (test::have_vulkan()) {
      renderer::GpuTracer tracer;
      tracer.load(compiled);
      renders.emplace_back("GPU tracer", tracer.render(frame));
    }
    for (const auto &[executor, result] : renders) {
      double worst = 0.0;
      for (const cv::Point2d &at : expected) {
        // The coverage within 8 px of where the square should be.
        double sum = 0.0, su = 0.0, sv = 0.0;
        for (int y = int(at.y) - 8; y <= int(at.y) + 8; ++y)
          for (int x = int(at.x) - 8; x <= int(at.x) + 8; ++x) {
            if (x < 0 || y < 0 || x >= 320 || y >= 240)
              continue;
            const double m = result.mask.data[std::size_t(y) * 320 + std::size_t(x)];
            sum += m;
            su += m * (x + 0.5);
            sv += m * (y + 0.5);
          }
        ASSERT_GT(sum, 20.0) << lens.name << " " << executor << ": no square near " << at;
        worst = std::max(worst, std::hypot(su / sum - at.x, sv / sum - at.y));
      }
      std::printf("%s, %s: the squares' centroids are %.3f px from OpenCV's at worst\n", lens.name,
                  executor.c_str(), worst);
      EXPECT_LT(worst, 0.05) << lens.name << " " << executor;
    }
  }
}

} // namespace
} // namespace camhead

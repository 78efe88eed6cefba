// Scenes for the tests: small ones built in code for the physics tests,
// random ones, and the reference scenes made small.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/image.h"
#include "camhead/renderer/scene.h"

namespace camhead::test {

// A camera at the origin looking down -Z (f = 50 mm, 36 mm sensor) at an
// empty scene with a black world, named `name` in messages.
[[nodiscard]] renderer::Scene empty_scene(const char *name, float f_number, float focus_m,
                                          int width, int height);

// Scene objects, made in one line.
[[nodiscard]] renderer::Object sphere(const char *name, glm::vec3 center, float radius,
                                      int material, bool real);
[[nodiscard]] renderer::Object box(const char *name, glm::vec3 center, glm::vec3 size, int material,
                                   bool real, glm::vec3 rotation_deg = glm::vec3(0.0f));
// A plane through `center`, normal +Y, of `size_m` x `size_m`.
[[nodiscard]] renderer::Object plane(const char *name, glm::vec3 center, float size_m, int material,
                                     bool real);
// A white point light of `power_W` at `position`.
[[nodiscard]] renderer::Light point_light(glm::vec3 position, float power_W);

// empty_scene() with a radiance-1 emitter that fills the half-plane x > 0 at depth `depth_m`,
// against a black world: a vertical edge on the image's centre column.
[[nodiscard]] renderer::Scene edge_scene(float f_number, float focus_m, float depth_m,
                                         int width = 256, int height = 16);

// The thin-lens blur-circle diameter in pixels (scene-format.md):
// CoC_px = f_px * (f / N) * |1/d_f - 1/d|.
[[nodiscard]] double coc_px(const renderer::Scene &scene, float depth_m);

// Pixel position of a world point through the pinhole of the scene camera.
[[nodiscard]] glm::vec2 project(const renderer::Scene &scene, glm::vec3 world);

// Mean over the rows of channel `c`: the profile across a vertical edge.
[[nodiscard]] std::vector<double> row_average(const renderer::Image &image, int c = 0);

// Blur diameter (px) from the edge profile of a uniform disk. The
// differences of the profile are the disk's line spread function (variance
// D^2/16) convolved with the pixel box filter twice over, a triangle of
// half-width 1 px (variance 1/6): D = 4 sqrt(var - 1/6).
[[nodiscard]] double measured_blur_diameter(const std::vector<double> &profile);

// A plate of noise: every pixel differs from its neighbours and from what
// the proxy renders, so a pixel composited from a wrong I_m - I_r shows.
[[nodiscard]] renderer::Image noise_plate(int width, int height, std::uint32_t seed);
// `scene` with a noise plate of its size.
[[nodiscard]] renderer::Scene with_noise_plate(renderer::Scene scene, std::uint32_t seed);

// A random scene: a ground most of the time, real and virtual spheres and
// boxes of every material, one to three lights of any kind, the camera
// anywhere within 10 m looking roughly at the objects, a pinhole or a lens
// from f/1 to f/16 focused anywhere from 0.3 m to 20 m; 48 x 36 pixels.
[[nodiscard]] renderer::Scene random_scene(std::uint32_t seed);

// A virtual glass ball (IOR 1.5, radius 0.3 m, 4 m away) before a real lamp
// that fills the view, 4 bounces, 32 x 32, with a noise plate: light
// through glass, many bounces deep.
[[nodiscard]] renderer::Scene glass_ball_before_lamp(float f_number, float focus_m);

// The reference scenes ar_basic and boxes, the demo and the simulated rig's
// scene at a quarter of their size, each with its plate or a noise plate.
[[nodiscard]] std::vector<renderer::Scene> small_reference_scenes();

} // namespace camhead::test

#include "tracking/camera_profile.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/lens_profile.h"

namespace camhead::pipeline {
namespace {

using Json = nlohmann::ordered_json;

double diopters_of(const Json &distance) {
  return distance.is_string() ? 0.0 : 1.0 / distance.get<double>();
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

} // namespace

std::string profile_with_camera(const std::string &profile, const std::string &source,
                                const CameraPointPlace &place, const CameraModel &camera) {
  const lens_control::LensProfile lens = lens_control::LensProfile::parse(profile, source);
  Json j = Json::parse(profile);
  const bool v3 = j.at("version").get<int>() == 3;
  const bool zoom = j.contains("zoom");

  // The zoom point: the prime, or the zoom point at the counts given.
  Json *point = nullptr;
  if (!zoom) {
    if (place.zoom_counts)
      throw CameraProfileError("--at zoom=" + number(*place.zoom_counts) + ": " + source +
                               " is a prime; give the focus alone");
    point = &j.at("prime");
  } else {
    if (!place.zoom_counts)
      throw CameraProfileError("--at: " + source +
                               " is a zoom; give the zoom point the views were taken at, "
                               "--at focus=COUNTS,zoom=COUNTS");
    for (Json &z : j.at("zoom"))
      if (z.at("counts").get<double>() == *place.zoom_counts)
        point = &z;
    if (point == nullptr)
      throw CameraProfileError("--at zoom=" + number(*place.zoom_counts) + ": " + source +
                               " has no zoom point at those counts (a camera model is "
                               "calibrated at a zoom point of the profile)");
    // Version 3 wants a camera model on every zoom point: the first one
    // calibrated would leave the others without.
    if (!v3)
      throw CameraProfileError(
          source + ": a zoom lens's profile gets a camera model on every zoom point at once "
                   "(version 3); calibrating one zoom point at a time starts from a version 3 "
                   "profile, which this is not");
  }

  // The image and the sensor.
  if (v3) {
    const Json &image = j.at("image");
    if (image.at("width_px").get<int>() != place.width_px ||
        image.at("height_px").get<int>() != place.height_px)
      throw CameraProfileError(
          "the views are " + std::to_string(place.width_px) + "x" +
          std::to_string(place.height_px) + ", but " + source + "'s camera model is in " +
          std::to_string(image.at("width_px").get<int>()) + "x" +
          std::to_string(image.at("height_px").get<int>()) + " pixels (image)");
    if (place.sensor_width_mm &&
        *place.sensor_width_mm != image.at("sensor_width_mm").get<double>())
      throw CameraProfileError(
          "--sensor-width-mm " + number(*place.sensor_width_mm) + ": " + source + " says " +
          number(image.at("sensor_width_mm").get<double>()) + " mm (image.sensor_width_mm)");
  } else {
    if (!place.sensor_width_mm)
      throw CameraProfileError("--sensor-width-mm: " + source +
                               " has no camera model yet, so nothing says how wide the sensor "
                               "is that the views' pixels span; give its width");
    j["version"] = 3;
    j["image"] = {{"width_px", place.width_px},
                  {"height_px", place.height_px},
                  {"sensor_width_mm", *place.sensor_width_mm}};
    j.erase("distortion");
  }
  point->erase("projection_focal_length_mm");

  // The focus distance the views were taken at, from the profile itself.
  const lens_control::LensProfile::Lookup focus =
      place.zoom_counts ? lens.focus_distance_m(*place.zoom_counts, place.focus_counts)
                        : lens.focus_distance_m(place.focus_counts);
  if (focus.clamped)
    throw CameraProfileError("--at focus=" + number(place.focus_counts) +
                             ": outside the focus table of " + source +
                             " (a camera point needs the distance the lens was focused at)");
  const double d = std::isinf(focus.value) ? 0.0 : 1.0 / focus.value;
  Json entry = Json::object();
  entry["distance_m"] = std::isinf(focus.value) ? Json("infinity") : Json(focus.value);
  entry["fx"] = camera.fx;
  entry["fy"] = camera.fy;
  entry["cx"] = camera.cx;
  entry["cy"] = camera.cy;
  const char *names[5] = {"k1", "k2", "p1", "p2", "k3"};
  for (int i = 0; i < 5; ++i)
    entry[names[i]] = camera.distortion[std::size_t(i)];

  // Replaces a point at the same distance; near to far.
  Json table = point->contains("camera") ? point->at("camera") : Json::array();
  Json kept = Json::array();
  for (const Json &p : table)
    if (std::abs(diopters_of(p.at("distance_m")) - d) > 1e-9 * std::max(1.0, d))
      kept.push_back(p);
  kept.push_back(entry);
  std::vector<Json> points(kept.begin(), kept.end());
  std::sort(points.begin(), points.end(), [](const Json &a, const Json &b) {
    return diopters_of(a.at("distance_m")) > diopters_of(b.at("distance_m"));
  });
  (*point)["camera"] = points;
  return j.dump(2) + "\n";
}

} // namespace camhead::pipeline

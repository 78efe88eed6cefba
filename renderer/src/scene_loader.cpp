// The strict scene reader. It mirrors read_scene() and Checker in
// shared/reference/blender_scene.py check for check and in the same order, so
// that a file is accepted by camhead exactly when the reference renderer
// accepts it, and the first problem reported is the same one.
#include "camhead/renderer/scene_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/image_io.h"
#include "camhead/renderer/mesh_io.h"
#include "scene_json.h"

namespace camhead::renderer {

SceneError::SceneError(std::string file, std::string field, std::string reason)
    : std::runtime_error(file + ": " + (field.empty() ? "" : field + ": ") + reason),
      file_(std::move(file)), field_(std::move(field)), reason_(std::move(reason)) {}

namespace {

using detail::Checker;
using detail::Json;
using detail::Vec;

glm::vec3 v3(const Vec &v) {
  return {float(v[0]), float(v[1]), float(v[2])};
}

// Scaled before normalising so that tiny but non-zero vectors, which the
// reference accepts, keep their direction instead of underflowing to 0/0.
glm::vec3 unit(const Vec &v) {
  const double scale = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
  const glm::dvec3 d = glm::dvec3(v[0], v[1], v[2]) / scale;
  return glm::vec3(d / glm::length(d));
}

class SceneReader {
public:
  SceneReader(const std::filesystem::path &source)
      : check_(source.string()), source_(source), base_(base_dir(source)) {}

  Scene read(const Json &S) {
    if (!S.is_object())
      check_.fail("", "the scene must be a JSON object");
    check_.keys(S, "", {"render", "camera", "materials", "objects"}, {"lights", "plate"});
    Scene scene;
    scene.source = source_;
    scene.render = render(S.at("render"));
    scene.camera = camera(S.at("camera"));
    std::optional<std::string> plate;
    if (S.contains("plate"))
      plate = check_.string(S, "plate", "");
    scene.materials = materials(S.at("materials"));
    objects(S.at("objects"), scene);
    lights(S.contains("lights") ? S.at("lights") : Json::array(), scene);
    if (plate)
      scene.plate = load_plate(*plate, scene.render);
    return scene;
  }

private:
  static std::filesystem::path base_dir(const std::filesystem::path &source) {
    std::error_code ec;
    const std::filesystem::path abs = std::filesystem::absolute(source, ec);
    return (ec ? source : abs).parent_path();
  }

  RenderSettings render(const Json &r) const {
    check_.keys(r, "render", {"width", "height", "samples"},
                {"seed", "pixel_filter", "max_bounces", "world_color"});
    RenderSettings out;
    out.width = int(check_.integer(r, "width", "render", 1, 65536));
    out.height = int(check_.integer(r, "height", "render", 1, 65536));
    out.samples = int(check_.integer(r, "samples", "render", 1, 1 << 24));
    out.seed = std::uint32_t(check_.integer(r, "seed", "render", 0, (1ll << 31) - 1, 0));
    out.max_bounces = int(check_.integer(r, "max_bounces", "render", 0, 1024, 0));
    out.world_color = v3(check_.vec(r, "world_color", "render", 3, {0.0}, Vec{0, 0, 0}));
    const Json pf = r.contains("pixel_filter") ? r.at("pixel_filter")
                                               : Json{{"type", "BOX"}, {"width_px", 1.0}};
    check_.keys(pf, "render.pixel_filter", {"type"}, {"width_px"});
    check_.string(pf, "type", "render.pixel_filter", {"BOX"});
    out.pixel_filter_width_px =
        float(check_.number(pf, "width_px", "render.pixel_filter", {0.01, 10.0}, 1.0));
    return out;
  }

  CameraDesc camera(const Json &c) const {
    check_.keys(c, "camera", {"position", "look_at", "focal_length_mm", "sensor_width_mm"},
                {"up", "sensor_fit", "f_number", "focus_distance_m"});
    const Vec position = check_.vec(c, "position", "camera");
    const Vec look_at = check_.vec(c, "look_at", "camera");
    const Vec up = check_.vec(c, "up", "camera", 3, {}, Vec{0, 1, 0}, true);
    CameraDesc out;
    out.position = v3(position);
    out.look_at = v3(look_at);
    out.up = v3(up);
    out.focal_length_mm = float(check_.number(c, "focal_length_mm", "camera", {0.0, 1e4, true}));
    out.sensor_width_mm = float(check_.number(c, "sensor_width_mm", "camera", {0.0, 1e3, true}));
    check_.string(c, "sensor_fit", "camera", {"HORIZONTAL"}, "HORIZONTAL");
    const double f_number = check_.number(c, "f_number", "camera", {0.0, 1e3}, 0.0);
    out.f_number = float(f_number);
    if (position == look_at)
      check_.fail("camera.look_at", "equals camera.position");
    // The reference does this test on float32 vectors (Blender's mathutils),
    // so a direction that vanishes in float is parallel to anything.
    const glm::dvec3 fwd(out.look_at - out.position), u(out.up);
    const auto normalized = [](glm::dvec3 v) {
      const double len = glm::length(v);
      return len > 0.0 ? v / len : v;
    };
    if (glm::length(glm::cross(normalized(fwd), normalized(u))) < 1e-6)
      check_.fail("camera.up", "parallel to the viewing direction");
    if (f_number > 0.0 || c.contains("focus_distance_m"))
      out.focus_distance_m =
          float(check_.number(c, "focus_distance_m", "camera", {0.0, 1e6, true}));
    return out;
  }

  std::vector<Material> materials(const Json &M) const {
    if (!M.is_object() || M.empty())
      check_.fail("materials", "must be a non-empty object");
    std::vector<Material> out;
    for (const auto &[name, m] : M.items()) {
      const std::string f = "materials." + name;
      Material mat;
      mat.name = name;
      const std::string t = check_.string(m.is_object() ? m : Json::object(), "type", f,
                                          {"diffuse", "mirror", "glass", "emission"});
      if (t == "diffuse") {
        check_.keys(m, f, {"type", "albedo"});
        mat.type = MaterialType::diffuse;
        mat.color = v3(check_.vec(m, "albedo", f, 3, {0.0, 1.0}));
      } else if (t == "mirror") {
        check_.keys(m, f, {"type"}, {"tint"});
        mat.type = MaterialType::mirror;
        mat.color = v3(check_.vec(m, "tint", f, 3, {0.0, 1.0}, Vec{1, 1, 1}));
      } else if (t == "glass") {
        check_.keys(m, f, {"type", "ior"});
        mat.type = MaterialType::glass;
        mat.color = glm::vec3(1.0f); // Blender's glass colour is white
        mat.ior = float(check_.number(m, "ior", f, {1.0, 10.0}));
      } else {
        check_.keys(m, f, {"type", "radiance"});
        mat.type = MaterialType::emission;
        mat.color = v3(check_.vec(m, "radiance", f, 3, {0.0}));
      }
      out.push_back(std::move(mat));
    }
    return out;
  }

  void objects(const Json &O, Scene &scene) {
    if (!O.is_array())
      check_.fail("objects", "must be an array");
    std::set<std::string> names;
    for (std::size_t i = 0; i < O.size(); ++i) {
      const Json &o = O[i];
      const std::string f = "objects[" + std::to_string(i) + "]";
      const std::string t = check_.string(o.is_object() ? o : Json::object(), "type", f,
                                          {"plane", "box", "sphere", "mesh"});
      if (t == "mesh")
        check_.keys(o, f, {"type", "file", "material"},
                    {"name", "rotation_deg", "real", "center", "scale"});
      else
        check_.keys(o, f, {"type", "center", t == "sphere" ? "radius" : "size", "material"},
                    {"name", "rotation_deg", "real"});
      Object ob;
      ob.type = t == "plane"    ? ShapeType::plane
                : t == "box"    ? ShapeType::box
                : t == "sphere" ? ShapeType::sphere
                                : ShapeType::mesh;
      ob.name = check_.string(o, "name", f, {}, t + std::to_string(i));
      ob.center = v3(check_.vec(o, "center", f, 3, {}, Vec{0, 0, 0}));
      ob.rotation_deg = v3(check_.vec(o, "rotation_deg", f, 3, {}, Vec{0, 0, 0}));
      const std::string material = check_.string(o, "material", f);
      if (!names.insert(ob.name).second)
        check_.fail(f + ".name", "duplicate name " + ob.name);
      const auto m = std::find_if(scene.materials.begin(), scene.materials.end(),
                                  [&](const Material &x) { return x.name == material; });
      if (m == scene.materials.end())
        check_.fail(f + ".material", "no material named " + material);
      ob.material = int(m - scene.materials.begin());
      if (o.contains("real") && !o.at("real").is_boolean())
        check_.fail(f + ".real", "must be true or false");
      ob.real = o.contains("real") && o.at("real").get<bool>();
      if (t == "plane") {
        const Vec size = check_.vec(o, "size", f, 2, {1e-9});
        ob.size = glm::vec3(float(size[0]), 1.0f, float(size[1]));
      } else if (t == "box") {
        ob.size = v3(check_.vec(o, "size", f, 3, {1e-9}));
      } else if (t == "sphere") {
        ob.radius = float(check_.number(o, "radius", f, {0.0, 1e6, true}));
      } else {
        ob.scale = float(check_.number(o, "scale", f, {0.0, 1e6, true}, 1.0));
        mesh(check_.string(o, "file", f), f + ".file", ob);
      }
      scene.objects.push_back(std::move(ob));
    }
  }

  void mesh(const std::string &file, const std::string &field, Object &ob) {
    std::string lower = file;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (!lower.ends_with(".obj") && !lower.ends_with(".ply"))
      check_.fail(field, "must be an .obj or .ply file");
    ob.mesh_file = (base_ / file).lexically_normal();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(ob.mesh_file, ec))
      check_.fail(field, "cannot read " + ob.mesh_file.string());
    // Objects that share a file share its triangles.
    auto &cached = meshes_[ob.mesh_file];
    try {
      if (!cached)
        cached = std::make_shared<const TriangleMesh>(load_mesh(ob.mesh_file));
    } catch (const MeshError &e) {
      check_.fail(field, e.what());
    }
    ob.mesh = cached;
  }

  void lights(const Json &L, Scene &scene) const {
    if (!L.is_array())
      check_.fail("lights", "must be an array");
    for (std::size_t i = 0; i < L.size(); ++i) {
      const Json &l = L[i];
      const std::string f = "lights[" + std::to_string(i) + "]";
      const std::string t =
          check_.string(l.is_object() ? l : Json::object(), "type", f, {"point", "area", "sun"});
      if (t == "point")
        check_.keys(l, f, {"type", "position", "power_W"}, {"name", "color"});
      else if (t == "area")
        check_.keys(l, f, {"type", "position", "size", "power_W", "normal"}, {"name", "color"});
      else
        check_.keys(l, f, {"type", "direction", "irradiance_W_m2"}, {"name", "color"});
      Light light;
      light.name = check_.string(l, "name", f, {}, "light" + std::to_string(i));
      light.color = v3(check_.vec(l, "color", f, 3, {0.0}, Vec{1, 1, 1}));
      if (t == "point") {
        light.type = LightType::point;
        light.position = v3(check_.vec(l, "position", f));
        light.power_W = float(check_.number(l, "power_W", f, {0.0}));
      } else if (t == "area") {
        light.type = LightType::area;
        light.position = v3(check_.vec(l, "position", f));
        const Vec size = check_.vec(l, "size", f, 2, {1e-9});
        light.size = glm::vec2(float(size[0]), float(size[1]));
        light.power_W = float(check_.number(l, "power_W", f, {0.0}));
        light.normal = unit(check_.vec(l, "normal", f, 3, {}, std::nullopt, true));
      } else {
        light.type = LightType::sun;
        light.direction = unit(check_.vec(l, "direction", f, 3, {}, std::nullopt, true));
        light.irradiance_W_m2 = float(check_.number(l, "irradiance_W_m2", f, {0.0}));
      }
      scene.lights.push_back(std::move(light));
    }
  }

  Image load_plate(const std::string &file, const RenderSettings &r) const {
    const std::filesystem::path path = (base_ / file).lexically_normal();
    Image plate;
    try {
      plate = read_image(path);
    } catch (const ImageError &e) {
      check_.fail("plate", e.what());
    }
    if (plate.width != r.width || plate.height != r.height)
      check_.fail("plate", path.string() + " is " + std::to_string(plate.width) + "x" +
                               std::to_string(plate.height) + ", the render is " +
                               std::to_string(r.width) + "x" + std::to_string(r.height));
    return plate;
  }

  Checker check_;
  std::filesystem::path source_, base_;
  std::map<std::filesystem::path, std::shared_ptr<const TriangleMesh>> meshes_;
};

} // namespace

Scene parse_scene(std::string_view json_text, const std::filesystem::path &source) {
  const std::string file = source.string();
  try {
    return SceneReader(source).read(detail::parse_json(json_text, file));
  } catch (const SceneError &) {
    throw;
  } catch (const std::exception &e) {
    // Only a bug in the checks above can get here; still report it as a
    // problem with this file rather than let a foreign exception escape.
    throw SceneError(file, "", std::string("cannot be read: ") + e.what());
  }
}

Scene load_scene(const std::filesystem::path &path) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  if (!in || std::filesystem::is_directory(path, ec))
    throw SceneError(path.string(), "", "cannot open");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad())
    throw SceneError(path.string(), "", "read error");
  return parse_scene(text, path);
}

} // namespace camhead::renderer

// The strict scene reader. It mirrors read_scene() and Checker in
// shared/reference/blender_scene.py check for check and in the same order, so
// that a file is accepted by camhead exactly when the reference renderer
// accepts it, and the first problem reported is on the same field. The
// checks themselves are base's strict JSON reader (config_json.h), which
// parses as Python's json does; only the float range of the scene model is
// the renderer's own rule.
#include "camhead/renderer/scene_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camhead/base/config_json.h"
#include "camhead/renderer/frame_camera.h"
#include "camhead/renderer/image_io.h"
#include "camhead/renderer/mesh_io.h"

namespace camhead::renderer {

namespace {

using base::JsonValue;
using base::Range;
using Vec = std::vector<double>;

// The scene model is float (std430 on the GPU): a finite double beyond
// float's range would turn into inf there.
bool fits_float(double v) {
  return std::abs(v) <= double(std::numeric_limits<float>::max());
}

double number(const JsonValue &v, const Range &r) {
  const double x = v.number(r);
  if (!fits_float(x))
    v.fail("exceeds the float range");
  return x;
}

Vec vec(const JsonValue &v, std::size_t n = 3, const Range &r = {}, bool nonzero = false) {
  const Vec out = v.numbers(n, r);
  if (nonzero && std::all_of(out.begin(), out.end(), [](double x) { return x == 0.0; }))
    v.fail("must not be zero");
  if (!std::all_of(out.begin(), out.end(), fits_float))
    v.fail("components exceed the float range");
  return out;
}

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
  explicit SceneReader(const std::filesystem::path &source) : source_(source) {}

  Scene read(const JsonValue &S) {
    S.object({"render", "camera", "materials", "objects"}, {"lights", "plate"});
    Scene scene;
    scene.source = source_;
    scene.render = render(S.at("render"));
    scene.camera = camera(S.at("camera"));
    std::optional<JsonValue> plate = S.find("plate");
    if (plate)
      (void)plate->string();
    scene.materials = materials(S.at("materials"));
    objects(S.at("objects"), scene);
    if (S.has("lights"))
      lights(S.at("lights"), scene);
    if (plate) {
      scene.plate = load_plate(*plate, scene.render);
      scene.plate_file = plate->path();
    }
    return scene;
  }

private:
  static RenderSettings render(const JsonValue &r) {
    r.object({"width", "height", "samples"},
             {"seed", "pixel_filter", "max_bounces", "world_color"});
    RenderSettings out;
    out.width = int(r.at("width").integer(1, 65536));
    out.height = int(r.at("height").integer(1, 65536));
    out.samples = int(r.at("samples").integer(1, 1 << 24));
    out.seed = r.has("seed") ? std::uint32_t(r.at("seed").integer(0, (1ll << 31) - 1)) : 0;
    out.max_bounces = r.has("max_bounces") ? int(r.at("max_bounces").integer(0, 1024)) : 0;
    out.world_color =
        r.has("world_color") ? v3(vec(r.at("world_color"), 3, Range::at_least(0.0))) : glm::vec3(0);
    out.pixel_filter_width_px = 1.0f;
    if (const auto pf = r.find("pixel_filter")) {
      pf->object({"type"}, {"width_px"});
      (void)pf->at("type").string({"BOX"});
      if (pf->has("width_px"))
        out.pixel_filter_width_px = float(number(pf->at("width_px"), Range::within(0.01, 10.0)));
    }
    return out;
  }

  static CameraDesc camera(const JsonValue &c) {
    c.object({"position", "look_at", "focal_length_mm", "sensor_width_mm"},
             {"up", "sensor_fit", "f_number", "focus_distance_m"});
    const Vec position = vec(c.at("position"));
    const Vec look_at = vec(c.at("look_at"));
    const Vec up = c.has("up") ? vec(c.at("up"), 3, {}, true) : Vec{0, 1, 0};
    CameraDesc out;
    out.position = v3(position);
    out.look_at = v3(look_at);
    out.up = v3(up);
    out.focal_length_mm = float(number(c.at("focal_length_mm"), Range::above(0.0, 1e4)));
    out.sensor_width_mm = float(number(c.at("sensor_width_mm"), Range::above(0.0, 1e3)));
    if (c.has("sensor_fit"))
      (void)c.at("sensor_fit").string({"HORIZONTAL"});
    const double f_number =
        c.has("f_number") ? number(c.at("f_number"), Range::within(0.0, 1e3)) : 0.0;
    out.f_number = float(f_number);
    if (position == look_at)
      c.fail_member("look_at", "equals camera.position");
    switch (view_problem(out.position, out.look_at, out.up)) {
    case ViewProblem::none:
      break;
    case ViewProblem::no_direction:
      c.fail_member("look_at", "too close to camera.position for the float32 the renderer "
                               "works in");
    case ViewProblem::no_orientation:
      c.fail_member("up", "parallel to the viewing direction");
    }
    if (f_number > 0.0 || c.has("focus_distance_m"))
      out.focus_distance_m = float(number(c.at("focus_distance_m"), Range::above(0.0, 1e6)));
    return out;
  }

  std::vector<Material> materials(const JsonValue &M) {
    if (!M.json().is_object() || M.json().empty())
      M.fail("must be a non-empty object");
    std::vector<Material> out;
    for (const auto &[name, m] : M.members()) {
      Material mat;
      mat.name = name;
      const std::string t = m.at("type").string({"diffuse", "mirror", "glass", "emission"});
      if (t == "diffuse") {
        m.object({"type"}, {"albedo", "albedo_texture"});
        mat.type = MaterialType::diffuse;
        if (!m.has("albedo") && !m.has("albedo_texture"))
          m.fail_member("albedo", "missing (or an albedo_texture)");
        // With a texture, albedo tints it: white unless given.
        mat.color =
            m.has("albedo") ? v3(vec(m.at("albedo"), 3, Range::within(0.0, 1.0))) : glm::vec3(1.0f);
        if (m.has("albedo_texture")) {
          mat.albedo_texture = {texture(m.at("albedo_texture")), m.at("albedo_texture").path()};
        }
      } else if (t == "mirror") {
        m.object({"type"}, {"tint"});
        mat.type = MaterialType::mirror;
        mat.color =
            m.has("tint") ? v3(vec(m.at("tint"), 3, Range::within(0.0, 1.0))) : glm::vec3(1.0f);
      } else if (t == "glass") {
        m.object({"type", "ior"});
        mat.type = MaterialType::glass;
        mat.color = glm::vec3(1.0f); // Blender's glass colour is white
        mat.ior = float(number(m.at("ior"), Range::within(1.0, 10.0)));
      } else {
        m.object({"type", "radiance"});
        mat.type = MaterialType::emission;
        mat.color = v3(vec(m.at("radiance"), 3, Range::at_least(0.0)));
      }
      out.push_back(std::move(mat));
    }
    return out;
  }

  void objects(const JsonValue &O, Scene &scene) {
    std::set<std::string> names;
    const std::vector<JsonValue> list = O.elements();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const JsonValue &o = list[i];
      const std::string t = o.at("type").string({"plane", "box", "sphere", "mesh"});
      if (t == "mesh")
        o.object({"type", "file", "material"}, {"name", "rotation_deg", "real", "center", "scale"});
      else
        o.object({"type", "center", t == "sphere" ? "radius" : "size", "material"},
                 {"name", "rotation_deg", "real"});
      Object ob;
      ob.type = t == "plane"    ? ShapeType::plane
                : t == "box"    ? ShapeType::box
                : t == "sphere" ? ShapeType::sphere
                                : ShapeType::mesh;
      ob.name = o.has("name") ? o.at("name").string() : t + std::to_string(i);
      ob.center = o.has("center") ? v3(vec(o.at("center"))) : glm::vec3(0);
      ob.rotation_deg = o.has("rotation_deg") ? v3(vec(o.at("rotation_deg"))) : glm::vec3(0);
      const std::string material = o.at("material").string();
      if (!names.insert(ob.name).second)
        o.fail_member("name", "duplicate name " + ob.name);
      const auto m = std::find_if(scene.materials.begin(), scene.materials.end(),
                                  [&](const Material &x) { return x.name == material; });
      if (m == scene.materials.end())
        o.at("material").fail("no material named " + material);
      ob.material = int(m - scene.materials.begin());
      ob.real = o.has("real") && o.at("real").boolean();
      if (m->albedo_texture.image && (t == "sphere" || t == "mesh"))
        o.at("material")
            .fail("'" + material + "' has an albedo_texture, and a " + t +
                  " has no texture coordinates (planes and boxes have)");
      if (t == "plane") {
        const Vec size = vec(o.at("size"), 2, Range::at_least(1e-9));
        ob.size = glm::vec3(float(size[0]), 1.0f, float(size[1]));
      } else if (t == "box") {
        ob.size = v3(vec(o.at("size"), 3, Range::at_least(1e-9)));
      } else if (t == "sphere") {
        ob.radius = float(number(o.at("radius"), Range::above(0.0, 1e6)));
      } else {
        ob.scale = o.has("scale") ? float(number(o.at("scale"), Range::above(0.0, 1e6))) : 1.0f;
        mesh(o.at("file"), ob);
      }
      scene.objects.push_back(std::move(ob));
    }
  }

  void mesh(const JsonValue &file, Object &ob) {
    std::string lower = file.string();
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (!lower.ends_with(".obj") && !lower.ends_with(".ply"))
      file.fail("must be an .obj or .ply file");
    ob.mesh_file = file.path();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(ob.mesh_file, ec))
      file.fail("cannot read " + ob.mesh_file.string());
    // Objects that share a file share its triangles.
    auto &cached = meshes_[ob.mesh_file];
    try {
      if (!cached)
        cached = std::make_shared<const TriangleMesh>(load_mesh(ob.mesh_file));
    } catch (const MeshError &e) {
      file.fail(e.what());
    }
    ob.mesh = cached;
  }

  static void lights(const JsonValue &L, Scene &scene) {
    const std::vector<JsonValue> list = L.elements();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const JsonValue &l = list[i];
      const std::string t = l.at("type").string({"point", "area", "sun"});
      if (t == "point")
        l.object({"type", "position", "power_W"}, {"name", "color"});
      else if (t == "area")
        l.object({"type", "position", "size", "power_W", "normal"}, {"name", "color"});
      else
        l.object({"type", "direction", "irradiance_W_m2"}, {"name", "color"});
      Light light;
      light.name = l.has("name") ? l.at("name").string() : "light" + std::to_string(i);
      light.color = l.has("color") ? v3(vec(l.at("color"), 3, Range::at_least(0.0))) : glm::vec3(1);
      if (t == "point") {
        light.type = LightType::point;
        light.position = v3(vec(l.at("position")));
        light.power_W = float(number(l.at("power_W"), Range::at_least(0.0)));
      } else if (t == "area") {
        light.type = LightType::area;
        light.position = v3(vec(l.at("position")));
        const Vec size = vec(l.at("size"), 2, Range::at_least(1e-9));
        light.size = glm::vec2(float(size[0]), float(size[1]));
        light.power_W = float(number(l.at("power_W"), Range::at_least(0.0)));
        light.normal = unit(vec(l.at("normal"), 3, {}, true));
      } else {
        light.type = LightType::sun;
        light.direction = unit(vec(l.at("direction"), 3, {}, true));
        light.irradiance_W_m2 = float(number(l.at("irradiance_W_m2"), Range::at_least(0.0)));
      }
      scene.lights.push_back(std::move(light));
    }
  }

  // An albedo image, read once however many materials name it. Its albedo
  // must be physical (within [0, 1]), as a colour's is.
  std::shared_ptr<const Image> texture(const JsonValue &file) {
    (void)file.string();
    const std::filesystem::path path = file.path();
    if (const auto known = textures_.find(path); known != textures_.end())
      return known->second;
    Image image;
    try {
      image = read_image(path, ImageSize{kLargestTexture, kLargestTexture, true});
    } catch (const ImageError &e) {
      file.fail(e.what());
    }
    for (std::size_t i = 0; i < image.data.size(); ++i)
      if (!(image.data[i] >= 0.0f && image.data[i] <= 1.0f)) {
        const std::size_t px = i / std::size_t(image.channels);
        file.fail(path.string() + ": pixel (" + std::to_string(px % std::size_t(image.width)) +
                  ", " + std::to_string(px / std::size_t(image.width)) + ") has " +
                  std::to_string(image.data[i]) + ", and an albedo must be within [0, 1]");
      }
    auto shared = std::make_shared<const Image>(std::move(image));
    textures_.emplace(path, shared);
    return shared;
  }

  static Image load_plate(const JsonValue &file, const RenderSettings &r) {
    const std::filesystem::path path = file.path();
    Image plate;
    try {
      plate = read_image(path, ImageSize{r.width, r.height});
    } catch (const ImageError &e) {
      file.fail(e.what());
    }
    if (plate.width != r.width || plate.height != r.height)
      file.fail(path.string() + " is " + std::to_string(plate.width) + "x" +
                std::to_string(plate.height) + ", the render is " + std::to_string(r.width) + "x" +
                std::to_string(r.height));
    return plate;
  }

  std::filesystem::path source_;
  std::map<std::filesystem::path, std::shared_ptr<const TriangleMesh>> meshes_;
  std::map<std::filesystem::path, std::shared_ptr<const Image>> textures_;
  // 4096 x 4096: 200 MB of floats read, 180 MB of texels with its levels.
  static constexpr int kLargestTexture = 4096;
};

} // namespace

Scene parse_scene(std::string_view json_text, const std::filesystem::path &source) {
  const std::string file = source.string();
  // Python's json refuses a byte order mark; nlohmann would skip it.
  if (json_text.substr(0, 3) == "\xEF\xBB\xBF")
    throw SceneError(file, "(JSON)", "unexpected UTF-8 byte order mark");
  try {
    const base::JsonFile json(json_text, file);
    return SceneReader(source).read(json.root());
  } catch (const base::ConfigError &e) {
    throw SceneError(e);
  } catch (const std::exception &e) {
    // Only a bug in the checks above can get here; still report it as a
    // problem with this file rather than let a foreign exception escape.
    throw SceneError(file, "", std::string("cannot be read: ") + e.what());
  }
}

Scene load_scene(const std::filesystem::path &path) {
  std::string text;
  try {
    text = base::read_config_file(path);
  } catch (const base::ConfigError &e) {
    throw SceneError(e);
  }
  return parse_scene(text, path);
}

} // namespace camhead::renderer

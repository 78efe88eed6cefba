// See board_reload.h.
#include "board_reload.h"

#include <string>

#include "camhead/base/config_json.h"

namespace camhead::pipeline {
namespace {

using base::Json;

// The board's JSON without what a reload may change.
Json fixed_part(const Board &board) {
  Json root = base::JsonFile(board.text, board.file.string()).root().json();
  for (const char *key : {"name", "description", "scene"})
    root.erase(key);
  if (root.contains("lens") && root["lens"].is_object())
    root["lens"].erase("profile");
  if (root.contains("render") && root["render"].is_object()) {
    Json &render = root["render"];
    for (auto it = render.begin(); it != render.end();)
      it = it.key() == "executor" ? std::next(it) : render.erase(it);
  }
  // A static pose is only numbers for the renderer; any other names a
  // source that runs.
  if (root.contains("pose") && root["pose"].is_object() &&
      root["pose"].value("type", std::string("static")) == "static")
    root.erase("pose");
  return root;
}

// The field path of the first difference ("lens.sources[0].port"), empty
// when there is none; `path` is where the two values are.
std::string first_difference(const Json &was, const Json &now, const std::string &path) {
  if (was.is_object() && now.is_object()) {
    for (const auto &[key, value] : was.items()) {
      const std::string field = path.empty() ? key : path + "." + key;
      if (!now.contains(key))
        return field;
      if (std::string d = first_difference(value, now[key], field); !d.empty())
        return d;
    }
    for (const auto &[key, value] : now.items())
      if (!was.contains(key))
        return path.empty() ? key : path + "." + key;
    return {};
  }
  if (was.is_array() && now.is_array()) {
    for (std::size_t i = 0; i < was.size() && i < now.size(); ++i)
      if (std::string d = first_difference(was[i], now[i], path + "[" + std::to_string(i) + "]");
          !d.empty())
        return d;
    return was.size() == now.size() ? std::string() : path;
  }
  return was == now ? std::string() : path;
}

} // namespace

Board reread_board(const Board &running) {
  Board next = load_board(running.file);
  const std::string changed = first_difference(fixed_part(running), fixed_part(next), "");
  if (!changed.empty())
    throw ReloadRefused(running.file.string() + ": " + changed +
                        ": changed: a reload takes the scene, the lens profile, the render "
                        "settings and a static pose; the camera, the outputs, the lens sources, "
                        "a tracked pose and the executor take a restart");
  return next;
}

} // namespace camhead::pipeline

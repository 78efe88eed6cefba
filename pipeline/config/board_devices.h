// A board's devices (board.h): its camera, and each of its lens sources,
// read by the kind their "type" names from a table of {type, reader}. The
// board reader (board.cpp) reads the rest of the file.
#pragma once

#include "camhead/base/config_json.h"
#include "config/board.h"

namespace camhead::pipeline {

// A board's "camera" object; throws base::ConfigError naming the field.
[[nodiscard]] CameraConfig read_camera_config(const base::JsonValue &d);
// One of a board's "lens": "sources"; throws as read_camera_config does.
[[nodiscard]] LensSourceConfig read_lens_source_config(const base::JsonValue &d);

} // namespace camhead::pipeline

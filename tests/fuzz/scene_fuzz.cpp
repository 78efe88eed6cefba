// libFuzzer target for the scene reader (renderer/scene_loader.h): any text
// must be refused with a SceneError naming a field, or parsed; any other
// exception, and the reader's last-resort "cannot be read" for a foreign
// exception, is a finding. The scene sits in tests/assets, so that the
// meshes the dictionary names (quad.obj, pentagon.ply) are read too.
#include <cstddef>
#include <cstdint>
#include <string>

#include "camhead/renderer/scene_loader.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const std::string text = camhead::fuzz::text_of(data, size);
  // The files of this machine are not the reader's input: /dev/zero or
  // /dev/stdin would only exhaust libFuzzer's memory or time limits. JSON
  // spells a '/' only as itself, "\/" or "\u002f".
  for (const char *machine : {"/dev", "/proc", "/sys", "\\/", "\\u"})
    if (text.find(machine) != std::string::npos)
      return 0;
  try {
    (void)camhead::renderer::parse_scene(text, CAMHEAD_FUZZ_ASSETS "/fuzz_scene.json");
  } catch (const camhead::renderer::SceneError &e) {
    camhead::fuzz::check(!e.field().empty());
  }
  return 0;
}

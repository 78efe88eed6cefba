#include "output_watchdog.h"

namespace camhead::pipeline {

bool output_advanced(const OutputProgress &before, const OutputProgress &now) {
  if (now.composites > before.composites)
    return true;
  return now.camera_lost && !now.renderer_lost && now.placeholders > before.placeholders;
}

} // namespace camhead::pipeline

// What a reload (SIGHUP to `camhead run` as a service) may change in a
// running board, and the check that nothing else changed.
//
// A reload replaces what a frame is rendered with: the scene file (its
// virtual and real objects, its camera), the lens profile, the render
// settings other than the executor, and a static pose; and the board's
// name and description. Everything else would take an output down or a
// device away for a moment (the camera, the outputs, the lens sources, a
// tracked or marker pose, the executor's device), which a reload promises
// not to do: a board that changes any of it is refused, naming the first
// field that changed, and the run goes on as it was until a restart.
#pragma once

#include <stdexcept>

#include "config/board.h"

namespace camhead::pipeline {

// "FILE: FIELD: changed (...): ...": what a reload cannot take.
class ReloadRefused : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// The board at `running.file` as it reads now, checked whole. Throws
// BoardError for a board that does not load, and ReloadRefused for one that
// changes what only a restart may change.
[[nodiscard]] Board reread_board(const Board &running);

} // namespace camhead::pipeline

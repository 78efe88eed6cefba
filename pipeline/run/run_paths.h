// Every file and device a run reads or writes, in one place, checked against
// each other by their real identity before anything is opened for writing.
// An output or the statistics file that is one of the run's inputs would
// destroy it: `file:take.y4m` with a file camera playing take.y4m replaces
// the take when the run ends, `--record-stats take.y4m` empties it at once,
// a loopback device that is both the camera and an output feeds itself.
// Two outputs on one file or device would interleave their frames.
//
// Identity is the device and inode after following links, for what exists;
// for what a run will create, the path made absolute with its links
// resolved (std::filesystem::weakly_canonical). A PNG sequence is its
// folder: no PNG the run writes may lie in the folder of a sequence it
// reads or writes, nor any PNG it reads in the folder of a sequence it
// writes (the camera's own frames, a plate, a PNG named as the statistics
// file), since numbered names cannot be told from theirs; and a sequence
// written needs a folder no other sequence uses.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/renderer/scene.h"
#include "config/board.h"
#include "output_uri.h"

namespace camhead::pipeline {

// A run's files that clash; what() names both and what they are.
class RunPathError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct RunPath {
  std::string role;           // "the camera", "--record-stats", "output file:x.y4m", ...
  std::filesystem::path path; // a file, a device node, or a PNG sequence's pattern
  bool written = false;       // an output or the statistics file
  bool sequence = false;      // a PNG sequence (pattern or folder): its folder counts
};

// The files a scene was read from: the scene file, its plate and meshes
// (none for a scene not loaded).
[[nodiscard]] std::vector<RunPath> scene_inputs(const renderer::Scene &scene);

// The files and devices a board's run reads: the board itself, its scene and
// the scene's meshes and plate (none for a scene not loaded, as the lens
// commands have), the lens profile and traces, the camera's file or device.
[[nodiscard]] std::vector<RunPath> run_inputs(const Board &board, const renderer::Scene &scene);

// The outputs that are files or devices (null and DRM cards are neither).
[[nodiscard]] std::vector<RunPath> run_outputs(const std::vector<OutputSpec> &outputs);

// Throws RunPathError on the first written path that is another path of the
// run, or where one of them is a PNG sequence, a PNG in its folder (or
// another sequence in that folder).
void check_run_paths(const std::vector<RunPath> &paths);

} // namespace camhead::pipeline

#include "run_paths.h"

#include <cctype>
#include <optional>
#include <system_error>
#include <variant>

#include <sys/stat.h>

#include "camhead/hal/video_file/frame_pattern.h"

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

// What a path is on this machine, as far as it can be told now.
struct Identity {
  std::optional<struct stat> node; // it exists: stat() after following links
  fs::path canonical;              // absolute, links resolved as far as they exist
};

Identity identity_of(const fs::path &path) {
  Identity id;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0)
    id.node = st;
  std::error_code error;
  id.canonical = fs::weakly_canonical(path, error);
  if (error)
    id.canonical = fs::absolute(path, error).lexically_normal();
  return id;
}

bool same(const Identity &a, const Identity &b) {
  if (a.node && b.node) {
    // One device, whatever node names it: stat() follows a by-id link, and
    // a second node made with mknod has the same st_rdev.
    if (S_ISCHR(a.node->st_mode) && S_ISCHR(b.node->st_mode))
      return a.node->st_rdev == b.node->st_rdev;
    return a.node->st_dev == b.node->st_dev && a.node->st_ino == b.node->st_ino;
  }
  return a.canonical == b.canonical;
}

// The folder a file is in; "." for a bare name.
fs::path folder_of(const fs::path &path) {
  const fs::path parent = path.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// The folder a PNG sequence's frames are in: the pattern's, or the folder
// named.
fs::path sequence_folder(const fs::path &path) {
  std::error_code error;
  if (!hal::video_file::FramePattern::is_pattern(path.string()) && fs::is_directory(path, error))
    return path;
  return folder_of(path);
}

bool is_png(const fs::path &path) {
  std::string ext = path.extension().string();
  for (char &c : ext)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png";
}

// Whether `a` and `b` are one file, or one lies among the numbered frames
// the other (a PNG sequence) reads or writes: in its folder, and a PNG.
bool clash(const RunPath &a, const RunPath &b) {
  if (a.sequence && b.sequence)
    return same(identity_of(sequence_folder(a.path)), identity_of(sequence_folder(b.path)));
  if (a.sequence || b.sequence) {
    const RunPath &sequence = a.sequence ? a : b, &file = a.sequence ? b : a;
    return is_png(file.path) &&
           same(identity_of(sequence_folder(sequence.path)), identity_of(folder_of(file.path)));
  }
  return same(identity_of(a.path), identity_of(b.path));
}

[[noreturn]] void refuse(const RunPath &written, const RunPath &other) {
  const char *does = other.written ? "writes" : "reads";
  if (written.sequence && other.sequence)
    throw RunPathError(written.role + ": writes its frames into " +
                       identity_of(sequence_folder(written.path)).canonical.string() + ", where " +
                       other.role + " " + does +
                       " its own; give each sequence a folder of its own");
  if (written.sequence)
    throw RunPathError(written.role + ": writes its frames into " +
                       identity_of(sequence_folder(written.path)).canonical.string() +
                       ", which holds " + other.role + " (" + other.path.string() +
                       ") that this run " + does + "; give the sequence a folder of its own");
  if (other.sequence)
    throw RunPathError(written.role + ": writes " + written.path.string() + " among the frames " +
                       other.role + " " + does + " (" + other.path.string() +
                       "); write somewhere else");
  if (other.written)
    throw RunPathError(written.role + ": writes to " + written.path.string() + " as " + other.role +
                       " does; give each output its own file or device");
  throw RunPathError(written.role + ": writes to " + written.path.string() + ", which is " +
                     other.role +
                     " that this run reads; writing there would destroy it: write somewhere else");
}

} // namespace

std::vector<RunPath> scene_inputs(const renderer::Scene &scene) {
  std::vector<RunPath> inputs;
  const auto add = [&](std::string role, const fs::path &path) {
    if (!path.empty()) // a scene not loaded (the lens commands)
      inputs.push_back({std::move(role), path, false, false});
  };
  add("the scene", scene.source);
  add("the scene's plate", scene.plate_file);
  for (const renderer::Object &object : scene.objects)
    add("the scene's mesh \"" + object.name + "\"", object.mesh_file);
  return inputs;
}

std::vector<RunPath> run_inputs(const Board &board, const renderer::Scene &scene) {
  std::vector<RunPath> inputs;
  const auto add = [&](std::string role, const fs::path &path, bool sequence = false) {
    inputs.push_back({std::move(role), path, false, sequence});
  };
  add("the board", board.file);
  for (RunPath &input : scene_inputs(scene))
    inputs.push_back(std::move(input));
  if (board.lens.profile)
    add("the lens profile", *board.lens.profile);
  if (board.pose && board.pose->type == PoseType::marker)
    add("the pose's marker board", board.pose->file);
  if (board.pose && board.pose->type == PoseType::trace)
    add("the pose's camera path", board.pose->file);
  for (const LensSourceConfig &source : board.lens.sources) {
    const std::string role = "lens source \"" + source.name + "\"'s trace";
    if (const auto *trace = std::get_if<TraceSourceConfig>(&source.kind))
      add(role, trace->file);
    else if (const auto *usb = std::get_if<UsbSourceConfig>(&source.kind); usb && usb->simulate)
      add(role, *usb->simulate);
    else if (const auto *gpio = std::get_if<GpioSourceConfig>(&source.kind); gpio && gpio->simulate)
      add(role, *gpio->simulate);
  }
  if (board.camera) {
    if (const auto *file = std::get_if<FileCameraConfig>(&board.camera->kind)) {
      std::error_code error;
      const bool sequence = hal::video_file::FramePattern::is_pattern(file->path.string()) ||
                            fs::is_directory(file->path, error);
      add("the camera's take", file->path, sequence);
    } else if (const auto *sim = std::get_if<SimCameraConfig>(&board.camera->kind);
               sim && sim->path) {
      add("the simulated camera's path", *sim->path);
    } else if (const auto *v4l2 = std::get_if<V4l2CameraConfig>(&board.camera->kind)) {
      add("the camera", v4l2->device);
    }
  }
  return inputs;
}

std::vector<RunPath> run_outputs(const std::vector<OutputSpec> &outputs) {
  std::vector<RunPath> paths;
  for (const OutputSpec &spec : outputs)
    if (spec.kind == OutputKind::y4m || spec.kind == OutputKind::v4l2 ||
        spec.kind == OutputKind::png)
      paths.push_back({spec.uri, spec.target, true, spec.kind == OutputKind::png});
  return paths;
}

void check_run_paths(const std::vector<RunPath> &paths) {
  // Every pair with a written path in it; of two written, the later is the
  // one refused.
  for (std::size_t j = 0; j < paths.size(); ++j)
    for (std::size_t i = 0; i < j; ++i) {
      const RunPath &a = paths[i], &b = paths[j];
      if ((a.written || b.written) && clash(a, b))
        refuse(b.written ? b : a, b.written ? a : b);
    }
}

} // namespace camhead::pipeline

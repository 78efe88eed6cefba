// camhead calibrate: a lens profile from measured (counts, value) pairs, and
// `calibrate camera`: the camera model of a lens from pictures of a ChArUco
// board. The fits live in lens_control (calibration.h) and in the marker
// module (tracking/marker_tracker.h); this file is the command line and the
// careful write: the profile is parsed back before any file is touched,
// written to a temporary file next to the output, loaded back from there,
// and only then renamed into place, so a failed run never leaves a profile
// that would not load, nor half of one.
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

#include "camhead/base/config_error.h"
#include "camhead/base/partial_file.h"
#include "camhead/lens_control/calibration.h"
#include "camhead/lens_control/lens_profile.h"
#include "cli/commands.h"
#include "run/run_paths.h"
#include "tracking/calibration_views.h"
#include "tracking/camera_profile.h"
#include "tracking/marker_board.h"

namespace camhead::cli {
namespace {

namespace fs = std::filesystem;

struct CalibrateArgs {
  std::string measurements;
  std::string output;
  std::string name;
  std::string description;
  bool prime = false;
};

constexpr const char *kFormatHelp = R"(Measurements CSV:
  A header row naming the columns (any order), then one measurement per row.
  '#' starts a comment; blank lines are skipped; no quoting.
    axis             focus, iris or zoom
    counts           raw encoder counts (integer)
    distance_m       focus rows: distance in metres, or inf
    f_number         iris rows: f-number
    t_stop           iris rows, optional: T-stop (on every iris row or on none)
    focal_length_mm  zoom rows: focal length in mm (a prime: one row and --prime)
    zoom_counts      focus rows, optional: the zoom counts (of a zoom row) the mark
                     was measured at; on every focus row or on none. Given, each
                     zoom point gets its own focus table (profile version 2).
  A row fills only its own axis's value columns. Repeats at the same counts are
  averaged in diopters / stops / log f; points that are not strictly monotone
  (measurement noise) are pooled by an isotonic fit. The residual report goes
  to stdout. Example: scenes/lenses/example_35mm_measurements.csv

Exit status: 0 profile written; 2 bad measurements, too few points, or -o
naming the measurements file;
3 the fitted profile does not load (nothing written); 4 the output cannot be
written; 1 any other error.
)";

// Removes the temporary file unless the run got as far as renaming it.
int run_calibrate(const CalibrateArgs &args) {
  using namespace camhead::lens_control;
  const fs::path output(args.output);
  const fs::path dir = output.parent_path();
  if (!dir.empty() && !fs::is_directory(dir)) {
    std::fprintf(stderr, "output %s: folder %s does not exist\n", args.output.c_str(),
                 dir.string().c_str());
    return 4;
  }
  if (fs::is_directory(output)) {
    std::fprintf(stderr, "output %s: is a folder; give a file name\n", args.output.c_str());
    return 4;
  }
  try {
    // The profile written over its own measurements would destroy them.
    pipeline::check_run_paths({{"the measurements", args.measurements, false, false},
                               {"-o " + args.output, output, true, false}});
  } catch (const pipeline::RunPathError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  try {
    const MeasurementSet measurements = read_measurements(args.measurements);
    const CalibrationOptions options{args.name, args.description, args.prime};
    const Calibration fit = fit_calibration(measurements, options);
    const std::string json = profile_json(fit, options);
    // Round trip before touching the disk: the strict reader is the judge of
    // what a profile is, not the writer.
    (void)LensProfile::parse(json, output);

    // Beside the output and renamed over it in one step (base/partial_file.h).
    std::string error;
    std::optional<base::PartialFile> file = base::PartialFile::create(output, error);
    if (!file ||
        !file->write(std::span(reinterpret_cast<const std::uint8_t *>(json.data()), json.size()),
                     error)) {
      std::fprintf(stderr, "output %s: %s\n", args.output.c_str(), error.c_str());
      return 4;
    }
    // The residuals use the profile as loaded from the bytes on disk: the
    // profile a rig will use.
    const LensProfile profile = LensProfile::load(file->partial_path());
    const std::vector<Residuals> residuals = compute_residuals(measurements, profile);
    if (!file->commit(true, error)) {
      std::fprintf(stderr, "output %s: %s\n", args.output.c_str(), error.c_str());
      return 4;
    }
    std::fputs(format_report(fit, residuals).c_str(), stdout);
    const std::string zoom =
        fit.prime ? "prime" : std::to_string(fit.zoom.points.size()) + " zoom points";
    const std::string focus =
        fit.zoom_focus.empty() ? std::to_string(fit.focus.points.size()) + " focus"
                               : std::to_string(fit.zoom_focus.size()) + " per-zoom focus tables";
    std::fprintf(stderr, "%s: profile \"%s\" written (%s, %zu iris points, %s)\n",
                 args.output.c_str(), args.name.c_str(), focus.c_str(), fit.iris.points.size(),
                 zoom.c_str());
    return 0;
  } catch (const CalibrationError &e) {
    std::fprintf(stderr, "measurements error: %s\n", e.what());
    return 2;
  } catch (const ProfileError &e) {
    std::fprintf(stderr, "the fitted profile does not load, nothing written: %s\n", e.what());
    return 3;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

struct CameraArgs {
  std::vector<std::string> views;
  std::string board;
  std::string profile;
  std::string at;
  double sensor_width_mm = 0.0;
};

constexpr const char *kCameraHelp = R"(The views:
  PNG pictures of the board (one view each), or Y4M videos (at most 40 frames
  of each, spread over it), all of one size: the board filling much of the
  picture in some, tilted by 20-50 degrees in most, reaching into the corners
  in several, sharp (stopped down, in focus). 10-30 views do.

What is written:
  The camera point (fx fy cx cy in the views' pixels, k1 k2 p1 p2 k3) at the
  focus distance that FOCUS counts give in PROFILE, on its prime or on the zoom
  point at ZOOM counts; a point there before is replaced. The profile becomes
  version 3 (lens_control/README.md), which needs the sensor's width once;
  the zoom point's breathing table gives way to its camera points' fx, so
  calibrate at several focus distances to keep the breathing.

Exit status: 0 profile written; 2 bad views, board, profile or --at;
3 the calibration failed (too few usable views: each one's reason printed);
4 the profile cannot be written; 1 any other error.
)";

// "focus=COUNTS[,zoom=COUNTS]".
bool parse_at(const std::string &text, pipeline::CameraPointPlace &place, std::string &error) {
  bool focus = false;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t end = std::min(text.find(',', at), text.size());
    const std::string part = text.substr(at, end - at);
    const std::size_t eq = part.find('=');
    const std::string key = part.substr(0, eq);
    double value = 0.0;
    try {
      std::size_t used = 0;
      value = std::stod(part.substr(eq == std::string::npos ? part.size() : eq + 1), &used);
      if (eq == std::string::npos || used != part.size() - eq - 1 || !std::isfinite(value))
        throw std::invalid_argument(part);
    } catch (const std::exception &) {
      error = "--at " + text + ": \"" + part + "\" is not NAME=COUNTS";
      return false;
    }
    if (key == "focus") {
      place.focus_counts = value;
      focus = true;
    } else if (key == "zoom") {
      place.zoom_counts = value;
    } else {
      error = "--at " + text + ": \"" + key + "\" is not focus or zoom";
      return false;
    }
    at = end + 1;
  }
  if (!focus)
    error = "--at " + text + ": give the focus counts the views were taken at (focus=COUNTS)";
  return focus;
}

int run_calibrate_camera(const CameraArgs &args) {
  using namespace camhead::pipeline;
  pipeline::CameraPointPlace place;
  std::string error;
  if (!parse_at(args.at, place, error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 2;
  }
  if (args.sensor_width_mm > 0.0)
    place.sensor_width_mm = args.sensor_width_mm;
  std::vector<CalibrationPicture> pictures;
  MarkerBoard board;
  std::string profile_text;
  try {
    board = load_marker_board(args.board);
    std::vector<fs::path> files(args.views.begin(), args.views.end());
    pictures = read_calibration_views(files, 40);
    profile_text = base::read_config_file(args.profile);
    (void)lens_control::LensProfile::parse(profile_text, args.profile);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  if (!pictures.empty()) {
    place.width_px = pictures.front().width;
    place.height_px = pictures.front().height;
  }
  // --at and --sensor-width-mm against the profile before the fit, which
  // takes a while: the point written into it with a nominal camera.
  try {
    const double w = place.width_px, h = place.height_px;
    (void)profile_with_camera(profile_text, args.profile, place,
                              CameraModel{w, w, 0.5 * w, 0.5 * h, {}});
  } catch (const CameraProfileError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  std::fprintf(stderr, "camhead calibrate camera: %zu views of %s...\n", pictures.size(),
               board.name.c_str());
  std::vector<LumaImage> views;
  for (const CalibrationPicture &p : pictures)
    views.push_back(p.image());
  CameraCalibration fit;
  try {
    fit = calibrate_camera(board, views);
  } catch (const MarkerModuleError &e) {
    std::fprintf(stderr, "the calibration failed: %s\n", e.what());
    return 3;
  }
  int used = 0;
  for (std::size_t i = 0; i < pictures.size(); ++i) {
    const CalibrationView &v = fit.views[i];
    if (v.used)
      std::printf("  %-32s %3d corners  %.3f px\n", pictures[i].name.c_str(), v.corners, v.rms_px);
    else
      std::printf("  %-32s left out: %s\n", pictures[i].name.c_str(), v.why_not.c_str());
    used += v.used ? 1 : 0;
  }
  const CameraModel &c = fit.camera;
  std::printf("RMS reprojection error %.3f px over %d of %zu views\n", fit.rms_px, used,
              pictures.size());
  std::printf("fx %.2f  fy %.2f  cx %.2f  cy %.2f px (OpenCV's pixel centres)\n"
              "k1 %.5f  k2 %.5f  p1 %.6f  p2 %.6f  k3 %.5f\n",
              c.fx, c.fy, c.cx, c.cy, c.distortion[0], c.distortion[1], c.distortion[2],
              c.distortion[3], c.distortion[4]);
  std::string json;
  try {
    json = profile_with_camera(profile_text, args.profile, place, c);
    (void)lens_control::LensProfile::parse(json, args.profile);
  } catch (const CameraProfileError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const lens_control::ProfileError &e) {
    std::fprintf(stderr, "the profile with this camera point does not load, nothing written: %s\n",
                 e.what());
    return 3;
  }
  const fs::path output(args.profile);
  std::optional<base::PartialFile> file = base::PartialFile::create(output, error);
  if (!file ||
      !file->write(std::span(reinterpret_cast<const std::uint8_t *>(json.data()), json.size()),
                   error)) {
    std::fprintf(stderr, "%s: %s\n", args.profile.c_str(), error.c_str());
    return 4;
  }
  try {
    (void)lens_control::LensProfile::load(file->partial_path());
  } catch (const lens_control::ProfileError &e) {
    std::fprintf(stderr, "the profile written does not load back, nothing replaced: %s\n",
                 e.what());
    return 3;
  }
  if (!file->commit(true, error)) {
    std::fprintf(stderr, "%s: %s\n", args.profile.c_str(), error.c_str());
    return 4;
  }
  std::fprintf(stderr, "%s: camera point written (profile version 3)\n", args.profile.c_str());
  return 0;
}

} // namespace

void add_calibrate_command(CLI::App &app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App *cmd = app.add_subcommand(
      "calibrate", "Fit a lens profile (lens_control/README.md) to measured encoder counts and\n"
                   "print the residuals of the measurements against it.\n"
                   "Example: camhead calibrate scenes/lenses/example_35mm_measurements.csv\n"
                   "           --name \"35 mm T1.5\" --prime -o lens.json");
  cmd->add_option("measurements", args->measurements, "Measurements CSV (format below)")
      ->check(path_text() & CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output,
                  "Profile JSON to write (replaced only when the new one loads)")
      ->check(path_text());
  cmd->add_option("--name", args->name, "The profile's name");
  cmd->add_option("--description", args->description,
                  "The profile's description (default: names the measurements file)");
  cmd->add_flag("--prime", args->prime,
                "A prime lens: the zoom rows (all at one counts value) give its one\n"
                "focal length, written as \"prime\" instead of a \"zoom\" table");
  cmd->footer(kFormatHelp);

  auto camera = std::make_shared<CameraArgs>();
  CLI::App *cam = cmd->add_subcommand(
      "camera", "Fit the camera model of a lens (OpenCV's fx fy cx cy and distortion) to\n"
                "pictures of a ChArUco board, print each view's part and the RMS\n"
                "reprojection error, and write it into the lens profile at the focus the\n"
                "pictures were taken at.\n"
                "Example: camhead calibrate camera views/*.png --board charuco.json\n"
                "           --profile lens.json --at focus=9400 --sensor-width-mm 23.5");
  cam->add_option("views", camera->views, "PNG pictures or Y4M videos of the board")
      ->required()
      ->check(path_text() & CLI::ExistingPath);
  cam->add_option("--board", camera->board, "The ChArUco board's file (camhead-markers v1)")
      ->required()
      ->check(path_text() & CLI::ExistingFile);
  cam->add_option("--profile", camera->profile,
                  "The lens profile to write the camera point into (replaced whole, only\n"
                  "when the new one loads)")
      ->required()
      ->check(path_text() & CLI::ExistingFile);
  cam->add_option("--at", camera->at,
                  "Where the lens was: focus=COUNTS (and zoom=COUNTS on a zoom)")
      ->required();
  cam->add_option("--sensor-width-mm", camera->sensor_width_mm,
                  "The width of the sensor the pictures span; needed once, when the\n"
                  "profile has no camera model yet")
      ->check(CLI::PositiveNumber);
  cam->footer(kCameraHelp);
  cam->callback([camera] { set_exit_code(run_calibrate_camera(*camera)); });

  cmd->callback([args, cmd] {
    if (cmd->got_subcommand("camera"))
      return;
    if (args->measurements.empty() || args->output.empty() || args->name.empty()) {
      std::fprintf(stderr, "camhead calibrate: give MEASUREMENTS.csv, --name and -o (or "
                           "`camhead calibrate camera`); --help says more\n");
      set_exit_code(2);
      return;
    }
    set_exit_code(run_calibrate(*args));
  });
}

} // namespace camhead::cli

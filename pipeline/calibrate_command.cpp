// camhead calibrate: a lens profile from measured (counts, value) pairs. The
// fit and the report live in lens_control (calibration.h); this file is the
// command line and the careful write: the profile is parsed back before any
// file is touched, written to a temporary file next to the output, loaded
// back from there, and only then renamed into place, so a failed run never
// leaves a profile that would not load, nor half of one.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <system_error>

#include <unistd.h>

#include "camhead/base/partial_file.h"
#include "camhead/lens_control/calibration.h"
#include "camhead/lens_control/lens_profile.h"
#include "commands.h"
#include "run/run_paths.h"

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

} // namespace

void add_calibrate_command(CLI::App &app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App *cmd = app.add_subcommand(
      "calibrate", "Fit a lens profile (lens_control/README.md) to measured encoder counts and\n"
                   "print the residuals of the measurements against it.\n"
                   "Example: camhead calibrate scenes/lenses/example_35mm_measurements.csv\n"
                   "           --name \"35 mm T1.5\" --prime -o lens.json");
  cmd->add_option("measurements", args->measurements, "Measurements CSV (format below)")
      ->required()
      ->check(path_text() & CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output,
                  "Profile JSON to write (replaced only when the new one loads)")
      ->required()
      ->check(path_text());
  cmd->add_option("--name", args->name, "The profile's name")->required();
  cmd->add_option("--description", args->description,
                  "The profile's description (default: names the measurements file)");
  cmd->add_flag("--prime", args->prime,
                "A prime lens: the zoom rows (all at one counts value) give its one\n"
                "focal length, written as \"prime\" instead of a \"zoom\" table");
  cmd->footer(kFormatHelp);
  cmd->callback([args] { set_exit_code(run_calibrate(*args)); });
}

} // namespace camhead::cli

// camhead run: the live pipeline. A board's camera and lens in, composited
// video out (pipeline/run/run_loop.h).
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/base/config_error.h"
#include "camhead/hal/camera/file/file_camera.h"
#include "camhead/hal/output/file/file_sink.h"
#include "camhead/lens_control/lens_profile.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/scene_loader.h"
#include "cli/commands.h"
#include "config/board.h"
#include "run/output_uri.h"
#include "run/run_loop.h"
#include "run/run_paths.h"
#include "service/service_notifier.h"
#include "web/web_access.h"
#include "web/web_server.h"

namespace camhead::cli {
namespace {

struct RunArgs {
  std::string board = "sim";
  std::vector<std::string> outputs;
  double duration_s = 0.0;
  std::uint64_t frames = 0;
  std::string stats;
  std::string executor;
  int threads = 0;
  bool no_influence_region = false;
  std::string http;          // ADDR:PORT of the operator page; empty: the board's, if any
  std::string http_password; // its password file
};

std::atomic<bool> stop_requested{false};
std::atomic<bool> reload_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

// The first signal asks the run to stop and finish its outputs; the handler
// then steps aside, so that a second one ends a run that does not stop.
extern "C" void on_stop_signal(int signal) {
  stop_requested = true;
  std::signal(signal, SIG_DFL);
}

// Under systemd, SIGHUP (`systemctl reload`) reloads the board; the handler
// stays for the next one.
extern "C" void on_reload_signal(int) {
  reload_requested = true;
}

// The summary, a line for the run and one for each output, and the exit
// status (docs/input-errors.md): 3 when frames could not be rendered (the
// GPU failed), 4 when a file output lost frames or could not be completed
// (a full disk, a size limit), 5 when a device or stream failed (the
// camera's take broke off, a webcam or display output failed); where more
// than one applies, the smallest, and every cause is said.
std::string reloads(const pipeline::RunSummary &s) {
  if (s.reloads + s.reloads_refused == 0)
    return {};
  return "; reloads " + std::to_string(s.reloads) + ", refused " +
         std::to_string(s.reloads_refused);
}

int report(const pipeline::RunSummary &s) {
  std::fprintf(stderr,
               "camhead run: %llu frames in, %llu out in %.1f s (%.1f fps out); dropped: "
               "camera %llu, render busy %llu, output busy %llu; render failures %llu, "
               "repeated frames %llu, placeholder frames %llu, output errors %llu, camera "
               "errors %llu, camera reconnects %llu, frames without their lens state %llu%s\n",
               (unsigned long long)s.frames_in, (unsigned long long)s.frames_out, s.seconds,
               s.seconds > 0 ? double(s.frames_out) / s.seconds : 0.0,
               (unsigned long long)s.camera_dropped, (unsigned long long)s.render_busy,
               (unsigned long long)s.output_busy, (unsigned long long)s.render_failed,
               (unsigned long long)s.repeats, (unsigned long long)s.placeholders,
               (unsigned long long)s.sink_errors, (unsigned long long)s.camera_errors,
               (unsigned long long)s.camera_reconnects, (unsigned long long)s.lens_late,
               reloads(s).c_str());
  bool file_failed = false, device_failed = !s.camera_failure.empty();
  for (const pipeline::OutputSummary &o : s.outputs) {
    // A file output no frame reached (a run stopped while it started) keeps
    // an earlier file of its name: no failure, and its close says so.
    (o.file ? file_failed : device_failed) |=
        o.failed > 0 || (!o.closed && (!o.file || o.written > 0));
    // Each failed frame's error was said as it happened; a failed close
    // (a file not completed) is said here.
    std::fprintf(stderr, "camhead run: %s: frames written %llu, lost %llu%s%s\n", o.name.c_str(),
                 (unsigned long long)o.written, (unsigned long long)o.failed, o.closed ? "" : "; ",
                 o.closed ? "" : o.detail.c_str());
  }
  if (!s.camera_failure.empty())
    std::fprintf(stderr, "camhead run: the camera failed: %s\n", s.camera_failure.c_str());
  if (!s.stats_failure.empty())
    std::fprintf(stderr, "camhead run: %s\n", s.stats_failure.c_str());
  if (s.render_failed > 0)
    std::fprintf(stderr, "camhead run: %llu frames could not be rendered%s; the first: %s\n",
                 (unsigned long long)s.render_failed,
                 s.offline ? " (the take composited offline is short of them)" : "",
                 s.render_failure.c_str());
  if (s.render_failed > 0)
    return 3;
  if (file_failed || !s.stats_failure.empty())
    return 4;
  return device_failed ? 5 : 0;
}

int run(const RunArgs &args) {
  pipeline::RunOptions options;
  try {
    options.board = pipeline::load_board(pipeline::resolve_board(args.board));
  } catch (const std::exception &e) {
    std::fprintf(stderr, "board error: %s\n", e.what());
    return 2;
  }
  options.outputs = args.outputs;
  options.duration_s = args.duration_s;
  options.frames = args.frames;
  if (!args.stats.empty())
    options.stats_file = args.stats;
  if (args.executor == "cpu")
    options.executor = pipeline::Executor::cpu;
  else if (args.executor == "gpu")
    options.executor = pipeline::Executor::gpu;
  else if (args.executor == "auto")
    options.executor = pipeline::Executor::automatic;
  options.threads = args.threads;
  options.influence_region = !args.no_influence_region;
  options.stop = &stop_requested;
  try {
    // The board's page, its address and password file replaced by the flags.
    if (!args.http.empty() || options.board.http) {
      options.web = options.board.http.value_or(pipeline::web::WebOptions{});
      if (!args.http.empty())
        options.web->listen = pipeline::web::parse_listen(args.http, "--http");
      if (!args.http_password.empty())
        options.web->password_file = args.http_password;
    }
  } catch (const pipeline::web::WebAccessError &e) {
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    return 2;
  }
  // Under systemd (systemd/camhead@.service): its notification socket.
  const pipeline::ServiceNotifier service = pipeline::ServiceNotifier::from_environment();
  options.service = &service;

  stop_requested = false;
  reload_requested = false;
  for (const int signal : kStopSignals)
    std::signal(signal, on_stop_signal);
  // A service's SIGHUP is a reload (systemd/camhead@.service's ExecReload);
  // in a terminal it is a hangup, and stops the run as Ctrl-C does.
  if (service.active()) {
    options.reload = &reload_requested;
    std::signal(SIGHUP, on_reload_signal);
  }
  // The operator page's reload button.
  if (options.web)
    options.reload = &reload_requested;
  int status = 0;
  try {
    status = report(pipeline::run_pipeline(options));
  } catch (const renderer::SceneError &e) {
    std::fprintf(stderr, "scene error: %s\n", e.what());
    status = 2;
  } catch (const lens_control::ProfileError &e) {
    std::fprintf(stderr, "lens profile error: %s\n", e.what());
    status = 2;
  } catch (const base::ConfigError &e) { // a lens trace, a board's source, ...
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 2;
  } catch (const pipeline::OutputError &e) { // an output URI
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 2;
  } catch (const pipeline::RunPathError &e) { // an output over an input
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 2;
  } catch (const hal::camera::FileCameraError &e) { // the camera's take
    std::fprintf(stderr, "camhead run: camera: %s\n", e.what());
    status = 2;
  } catch (const hal::output::FileSinkError &e) {
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 4;
  } catch (const pipeline::StatsFileError &e) {
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 4;
  } catch (const pipeline::web::WebAccessError &e) { // the page's address or password
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 2;
  } catch (const pipeline::web::WebError &e) { // the page's module or port
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 2;
  } catch (const renderer::GpuError &e) {
    std::fprintf(stderr,
                 "camhead run: Vulkan error: %s\n(--executor cpu renders with the CPU reference "
                 "instead)\n",
                 e.what());
    status = 3;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "camhead run: %s\n", e.what());
    status = 3;
  }
  for (const int signal : kStopSignals)
    std::signal(signal, SIG_DFL);
  return status;
}

// A number above 0 and at most `most` ("--duration 0" would otherwise mean
// "no limit" without a word, and NaN compares false with every bound).
CLI::Validator positive(const char *unit, double most, const char *flag) {
  return CLI::Validator(
      [=](std::string &text) -> std::string {
        char *end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(value) || value <= 0 ||
            value > most)
          return text + " is not a number of " + unit + " above 0 and at most " +
                 std::to_string(std::llround(most)) + " (leave " + flag +
                 " out to run until stopped)";
        return {};
      },
      "> 0");
}

} // namespace

void add_run_command(CLI::App &app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App *cmd = app.add_subcommand(
      "run", "The live pipeline: the board's camera and lens in, the virtual objects rendered\n"
             "with the lens's depth of field at each frame's mid-exposure and composited into\n"
             "the camera frame, out to every output. Stops at Ctrl-C (or SIGTERM, SIGHUP),\n"
             "after --duration or --frames, or when a camera file played once ends; a\n"
             "second Ctrl-C ends it at once. Under systemd (camhead@.service) SIGHUP,\n"
             "`systemctl reload`, reloads the board instead: its scene, lens profile, render\n"
             "settings and static pose are taken between two frames, without a gap; a\n"
             "board that does not load, or that changes the camera, outputs, lens sources,\n"
             "a tracked pose or the executor, is refused with its error and the run goes on.\n"
             "Outputs:\n"
             "  file:PATH.y4m[?format=yuyv|nv12]  Y4M video (ffplay PATH.y4m, mpv PATH.y4m)\n"
             "  file:DIR/%05d.png                 one PNG a frame\n"
             "  v4l2:/dev/videoN[?format=nv12]    the virtual webcam (v4l2loopback; YUYV default)\n"
             "  drm:CARD[:CONNECTOR][?mode=WxH@Hz] HDMI through DRM/KMS (no compositor running)\n"
             "  null                              nothing (to measure the pipeline)\n"
             "`camhead devices` lists the cameras and outputs this machine has.\n"
             "Examples:\n"
             "  camhead run --duration 5 --output file:sim.y4m\n"
             "  camhead run --output v4l2:/dev/video10 --output drm:card0:HDMI-A-1\n"
             "  camhead run --board my-rig.json --frames 250 --record-stats stats.jsonl\n"
             "Exit status: 0 done; 2 a wrong board, scene, take, output or option (nothing\n"
             "written); 3 frames could not be rendered; 4 a file output lost frames (a full\n"
             "disk, a size limit; what it holds is kept); 5 the camera's take broke off or a\n"
             "device failed. The summary says what each output took.");
  cmd->add_option("--board", args->board,
                  "Board name in board/ (sim, ...; an installed camhead looks in\n"
                  "/etc/camhead/board first) or a board file; its camera, scene, lens and\n"
                  "outputs")
      ->capture_default_str()
      ->check(path_text());
  cmd->add_option("--output", args->outputs,
                  "Output URI (repeat for more); replaces the board's outputs");
  cmd->add_option("--duration", args->duration_s,
                  "Stop after this many seconds (omit it to run until stopped)")
      ->check(positive("seconds", 1e7, "--duration"));
  cmd->add_option("--frames", args->frames,
                  "Stop after this many composited frames (omit it to run until stopped). The\n"
                  "outputs may also get fillers, counted apart in the summary: the placeholder\n"
                  "until the camera's first frame, the last frame again when one is late")
      ->check(positive("frames", double(std::uint64_t(1) << 40), "--frames"));
  cmd->add_option("--record-stats", args->stats,
                  "Write one JSON object per output frame to FILE.jsonl: sequence, capture,\n"
                  "exposure-middle and output times, the lens state (and how long the frame\n"
                  "waited for it), rays per pixel, drops and each stage's time")
      ->check(path_text());
  cmd->add_option("--executor", args->executor,
                  "auto (the board's default: a hardware GPU if there is one that takes the\n"
                  "scene, else the CPU reference), cpu, or gpu (the Vulkan tracer, lavapipe\n"
                  "included)")
      ->check(CLI::IsMember({"auto", "cpu", "gpu"}));
  cmd->add_option("--threads", args->threads, "CPU executor threads (0: one per core)")
      ->check(CLI::Range(0, 256));
  cmd->add_flag("--no-influence-region", args->no_influence_region,
                "Trace every pixel, not only where the virtual objects, their shadows and\n"
                "their reflections can change the frame (the same video, bit for bit; for\n"
                "comparing the cost)");
  cmd->add_option("--http", args->http,
                  "Serve the operator page on ADDR:PORT (8080 alone: 127.0.0.1:8080): the\n"
                  "live preview, the lens and pose, each stage's latency, the devices' health,\n"
                  "freeze, record and reload; /api/state, /api/events, /metrics (Prometheus),\n"
                  "/stream.mjpeg. An address other machines reach needs --http-password.\n"
                  "Replaces the board's \"http\" \"listen\"")
      ->type_name("ADDR:PORT"); // parse_listen() checks it
  cmd->add_option("--http-password", args->http_password,
                  "The operator page's password file (mode 0600, from `camhead web-password\n"
                  "FILE`): every request must give its password (the browser asks once).\n"
                  "Replaces the board's \"http\" \"password_file\"")
      ->check(path_text())
      ->type_name("FILE");
  cmd->callback([args] { set_exit_code(run(*args)); });
}

} // namespace camhead::cli

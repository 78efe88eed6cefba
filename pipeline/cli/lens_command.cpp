// camhead lens monitor | record: the lens chain of a board, live.
//
// monitor: a text view of every lens source of the board, raw counts and the
// calibrated lens state, redrawn in place on a terminal and printed as
// blocks once a second into logs; optionally the first source's lens state is
// sent on as OpenTrackIO, so that other tools see the same lens. record: one source's readings into
// a lens trace (the format the simulated rig replays), through hal's TraceRecorder.
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "camhead/hal/lens/monotonic_clock.h"
#include "camhead/hal/lens/network/opentrackio_sender.h"
#include "camhead/hal/lens/trace/trace_recorder.h"
#include "camhead/lens_control/lens_profile.h"
#include "cli/commands.h"
#include "config/board.h"
#include "config/lens_sources.h"
#include "run/run_paths.h"
#include "tracking/tracker_axes.h"

namespace camhead::cli {
namespace {

using namespace std::chrono_literals;
using pipeline::LensChannel;

std::atomic<bool> stop_requested{false};

extern "C" void on_interrupt(int) {
  stop_requested = true;
}

// Runs `step` until Ctrl-C or `duration_s` (0: no limit) has passed.
template <typename Step> void run_until_stopped(double duration_s, Step step) {
  stop_requested = false;
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  const auto start = std::chrono::steady_clock::now();
  while (!stop_requested) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (duration_s > 0.0 && elapsed >= duration_s)
      break;
    step(elapsed);
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

std::string counts(const std::optional<std::int32_t> &v) {
  return v ? std::to_string(*v) : "-";
}

std::string distance(const lens_control::Measured &m) {
  char text[32];
  if (std::isinf(m.value))
    return "infinity";
  std::snprintf(text, sizeof text, "%.3f m", m.value);
  return text;
}

std::string flags(const lens_control::Measured &m) {
  return std::string(m.fresh ? "" : " (stale)") + (m.clamped ? " (beyond calibration)" : "");
}

void print_channel(std::FILE *out, const LensChannel &channel, std::int64_t now_ns) {
  const hal::lens::EncoderStatus status = channel.encoder().status();
  std::fprintf(out, "%s  [%s]  %s\n", channel.config().name.c_str(),
               channel.encoder().name().c_str(), status.connected ? "connected" : "NOT CONNECTED");
  if (!status.detail.empty())
    std::fprintf(out, "  status  %s\n", status.detail.c_str());
  std::fprintf(out,
               "  counts  readings %llu  malformed %llu  lost %llu  missed edges %llu  "
               "reconnects %llu\n",
               (unsigned long long)status.readings, (unsigned long long)status.malformed,
               (unsigned long long)status.lost, (unsigned long long)status.missed_edges,
               (unsigned long long)status.reconnects);
  const auto &raw = channel.last_reading();
  if (!raw) {
    std::fprintf(out, "  raw     (no reading yet)\n\n");
    return;
  }
  std::fprintf(out, "  raw     focus %s  iris %s  zoom %s  (%.0f ms ago)\n",
               counts(raw->focus).c_str(), counts(raw->iris).c_str(), counts(raw->zoom).c_str(),
               double(now_ns - raw->t_ns) * 1e-6);
  if (raw->focus_distance_m || raw->f_stop || raw->focal_length_mm)
    std::fprintf(out, "  sent    focus %s  f/%s  focal %s mm (the source's own calibration)\n",
                 raw->focus_distance_m ? std::to_string(*raw->focus_distance_m).c_str() : "-",
                 raw->f_stop ? std::to_string(*raw->f_stop).c_str() : "-",
                 raw->focal_length_mm ? std::to_string(*raw->focal_length_mm).c_str() : "-");
  if (raw->pose)
    std::fprintf(out,
                 "  pose    X %.3f  Y %.3f  Z %.3f m  pan %.2f  tilt %.2f  roll %.2f deg "
                 "(the tracker's axes)\n",
                 raw->pose->x_m, raw->pose->y_m, raw->pose->z_m, raw->pose->pan_deg,
                 raw->pose->tilt_deg, raw->pose->roll_deg);
  if (!raw->focus && !raw->iris && !raw->zoom) {
    std::fprintf(out, "  lens    (no encoder counts to map through the profile)\n\n");
    return;
  }
  const lens_control::LensState s = channel.state_at(now_ns);
  std::fprintf(out, "  lens    focus %s%s  f/%.2f%s  %.1f mm (projection %.2f mm)%s%s\n\n",
               distance(s.focus_distance_m).c_str(), flags(s.focus_distance_m).c_str(),
               s.f_number.value, flags(s.f_number).c_str(), s.focal_length_mm.value,
               s.projection_focal_length_mm.value, flags(s.focal_length_mm).c_str(),
               s.calibrated ? "" : "  UNCALIBRATED");
}

struct LensArgs {
  std::string board = "sim";
  double duration_s = 0.0;
  int interval_ms = 0; // 0: 100 ms on a terminal, 1000 ms otherwise
  std::string source;
  std::string output;
  std::string send_opentrackio; // HOST or HOST:PORT
};

// The lens state as OpenTrackIO carries it. Infinity has no OpenTrackIO
// spelling (focusDistance is a finite distance), so it is left out.
hal::lens::OpenTrackIoState opentrackio_state(const lens_control::LensState &s) {
  hal::lens::OpenTrackIoState out;
  if (std::isfinite(s.focus_distance_m.value))
    out.focus_distance_m = s.focus_distance_m.value;
  out.f_stop = s.f_number.value;
  out.focal_length_mm = s.projection_focal_length_mm.value;
  return out;
}

// The board's camera pose in OpenTrackIO's axes: a static pose as given, a
// tracker's as it is now (none before its first pose); none for a board
// without a pose (the scene's camera is not loaded here) or with a marker
// pose (found in `camhead run`'s frames, not here).
std::optional<hal::lens::TrackedPose> sent_pose(const pipeline::Board &board,
                                                const std::vector<LensChannel> &channels,
                                                std::int64_t now_ns) {
  if (!board.pose)
    return std::nullopt;
  if (board.pose->type == pipeline::PoseType::fixed) {
    const pipeline::PoseVectors v = pipeline::pose_vectors(*board.pose);
    renderer::FrameCamera camera;
    camera.position = v.position;
    camera.look_at = v.look_at;
    camera.up = v.up;
    return pipeline::to_opentrackio(pipeline::pose_of(camera));
  }
  for (const LensChannel &channel : channels)
    if (const std::optional<pipeline::PoseAt> at = channel.pose_at(now_ns))
      return pipeline::to_opentrackio(at->pose);
  return std::nullopt;
}

std::unique_ptr<hal::lens::OpenTrackIoSender> open_sender(const std::string &destination) {
  hal::lens::OpenTrackIoSenderConfig config;
  const std::size_t colon = destination.rfind(':');
  config.host = destination.substr(0, colon);
  if (colon != std::string::npos) {
    const std::string port = destination.substr(colon + 1);
    char *end = nullptr;
    const unsigned long value = std::strtoul(port.c_str(), &end, 10);
    if (port.empty() || *end != '\0' || value == 0 || value > 65535)
      throw std::invalid_argument("--send-opentrackio " + destination +
                                  ": the port must be 1 .. 65535");
    config.port = static_cast<std::uint16_t>(value);
  }
  return std::make_unique<hal::lens::OpenTrackIoSender>(config);
}

// Loads the board and its profile, reporting errors; empty on failure.
std::optional<pipeline::Board> load(const LensArgs &args) {
  try {
    return pipeline::load_board(pipeline::resolve_board(args.board));
  } catch (const std::exception &e) {
    std::fprintf(stderr, "board error: %s\n", e.what());
    set_exit_code(2);
    return std::nullopt;
  }
}

void monitor(const LensArgs &args) {
  const auto board = load(args);
  if (!board)
    return;
  std::vector<LensChannel> channels;
  std::unique_ptr<hal::lens::OpenTrackIoSender> sender;
  std::string profile;
  try {
    // Loaded once: a second load could see another file (or fail) outside
    // this error handling.
    const lens_control::LensProfile loaded = pipeline::load_board_profile(*board);
    profile = loaded.name();
    channels = pipeline::open_lens_channels(*board, loaded);
    if (board->pose && pipeline::pose_from_lens_source(board->pose->type))
      for (LensChannel &channel : channels)
        if (channel.config().name == board->pose->source)
          channel.track_pose(board->pose->type, board->pose->delay_ms);
    if (!args.send_opentrackio.empty())
      sender = open_sender(args.send_opentrackio);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "%s\n", e.what());
    set_exit_code(5);
    return;
  }
  const bool terminal = isatty(STDOUT_FILENO) != 0;
  const auto interval = std::chrono::milliseconds(args.interval_ms > 0 ? args.interval_ms
                                                  : terminal           ? 100
                                                                       : 1000);
  auto next_draw = std::chrono::steady_clock::now();
  auto next_send = next_draw;
  run_until_stopped(args.duration_s, [&](double elapsed) {
    for (LensChannel &channel : channels)
      channel.pump(channels.size() > 1 ? 2ms : 10ms);
    if (sender && std::chrono::steady_clock::now() >= next_send) {
      next_send += 10ms; // 100 Hz, a common lens-data rate
      const std::int64_t now = hal::lens::monotonic_ns();
      hal::lens::OpenTrackIoState state = opentrackio_state(channels.front().state_at(now));
      state.camera = sent_pose(*board, channels, now);
      static_cast<void>(sender->send(state));
    }
    if (std::chrono::steady_clock::now() < next_draw)
      return;
    next_draw += interval;
    if (terminal)
      std::fputs("\x1b[H\x1b[J", stdout); // home, clear: redraw in place
    std::printf("camhead lens monitor  board \"%s\" (%s)  profile \"%s\"  t = %.1f s%s\n\n",
                board->name.c_str(), board->file.c_str(), profile.c_str(), elapsed,
                terminal ? "  (Ctrl-C stops)" : "");
    const std::int64_t now = hal::lens::monotonic_ns();
    for (const LensChannel &channel : channels)
      print_channel(stdout, channel, now);
    if (sender)
      std::printf(
          "OpenTrackIO out  %s: %llu samples sent, %llu failed%s%s\n", sender->name().c_str(),
          (unsigned long long)sender->sent(), (unsigned long long)sender->failed(),
          sender->last_error().empty() ? "" : "; last error: ", sender->last_error().c_str());
    std::fflush(stdout);
  });
}

void record(const LensArgs &args) {
  const auto board = load(args);
  if (!board)
    return;
  const pipeline::LensSourceConfig *chosen = nullptr;
  for (const pipeline::LensSourceConfig &s : board->lens.sources)
    if (args.source.empty() || s.name == args.source) {
      chosen = &s;
      break;
    }
  if (chosen == nullptr) {
    std::string names;
    for (const pipeline::LensSourceConfig &s : board->lens.sources)
      names += (names.empty() ? "\"" : ", \"") + s.name + "\"";
    std::fprintf(stderr, "board %s has no lens source \"%s\" (it has %s)\n", board->file.c_str(),
                 args.source.c_str(), names.c_str());
    set_exit_code(2);
    return;
  }
  try {
    // The trace written over one the board reads (its replay, its profile)
    // would destroy it.
    std::vector<pipeline::RunPath> paths = pipeline::run_inputs(*board, renderer::Scene{});
    paths.push_back({"-o " + args.output, args.output, true, false});
    pipeline::check_run_paths(paths);
  } catch (const pipeline::RunPathError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    set_exit_code(2);
    return;
  }
  try {
    // Every input first: nothing is opened for writing before the profile
    // and the source have been checked.
    auto profile = pipeline::load_board_profile(*board);
    auto source = pipeline::open_lens_source(*chosen);
    auto recorder = std::make_unique<hal::lens::TraceRecorder>(
        std::move(source), args.output,
        hal::lens::TraceRecorderOptions{.comment = "recorded by camhead lens record from board " +
                                                   board->name + ", source " + chosen->name});
    hal::lens::TraceRecorder &file = *recorder;
    LensChannel channel(*chosen, std::move(recorder), std::move(profile));
    std::fprintf(stderr, "recording %s into %s%s\n", file.name().c_str(), args.output.c_str(),
                 args.duration_s > 0 ? "" : " (Ctrl-C stops)");
    double next_report = 1.0;
    run_until_stopped(args.duration_s, [&](double elapsed) {
      channel.pump(50ms);
      if (elapsed >= next_report) {
        std::fprintf(stderr, "  %.0f s: %llu readings\n", elapsed,
                     (unsigned long long)file.recorded());
        next_report += 1.0;
      }
    });
    file.close();
    std::fprintf(stderr, "%s: %llu readings recorded\n", args.output.c_str(),
                 (unsigned long long)file.recorded());
  } catch (const std::exception &e) {
    std::fprintf(stderr, "%s\n", e.what());
    set_exit_code(5);
  }
}

void add_common(CLI::App *cmd, LensArgs &args) {
  cmd->add_option("--board", args.board,
                  "Board name in board/ (sim, example-rig, ...) or a board file")
      ->capture_default_str()
      ->check(path_text());
  cmd->add_option("--duration", args.duration_s, "Stop after this many seconds (0: at Ctrl-C)")
      ->check(finite_within(0.0, 1e6))
      ->capture_default_str();
}

} // namespace

void add_lens_command(CLI::App &app) {
  auto args = std::make_shared<LensArgs>();
  CLI::App *lens = app.add_subcommand("lens", "The lens chain of a board: watch it or record it");
  lens->require_subcommand(1);

  CLI::App *mon = lens->add_subcommand(
      "monitor", "Live view of every lens source of a board: raw encoder counts, source\n"
                 "health, and the calibrated lens state (focus distance, f-number, focal\n"
                 "length) through the board's lens profile.");
  add_common(mon, *args);
  mon->add_option("--interval", args->interval_ms,
                  "Milliseconds between views (default 100 on a terminal, 1000 otherwise)")
      ->check(CLI::Range(10, 60000));
  mon->add_option("--send-opentrackio", args->send_opentrackio,
                  "Send the first source's lens state on as OpenTrackIO (100 Hz) to\n"
                  "HOST[:PORT] (IPv4, unicast or multicast; port 55555 by default),\n"
                  "with the board's camera pose (static, or its tracker's) as the\n"
                  "transform \"Camera\"");
  mon->callback([args] { monitor(*args); });

  CLI::App *rec = lens->add_subcommand(
      "record", "Record one lens source of a board to a lens trace (CSV), the format the\n"
                "simulated rig replays. Written to FILE.partial and renamed when done.");
  add_common(rec, *args);
  rec->add_option("--source", args->source, "Source name in the board (default: the first)");
  rec->add_option("-o,--output", args->output, "Trace file to write")
      ->required()
      ->check(path_text());
  rec->callback([args] { record(*args); });
}

} // namespace camhead::cli

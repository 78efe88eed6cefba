// camhead markers draw: the page of a ChArUco board file, to print (or to
// put on a surface of a scene, as the simulated rig's floor board is).
#include <cstdio>
#include <memory>
#include <string>

#include "camhead/renderer/image.h"
#include "camhead/renderer/image_io.h"
#include "cli/commands.h"
#include "tracking/marker_board.h"
#include "tracking/marker_tracker.h"

namespace camhead::cli {
namespace {

struct DrawArgs {
  std::string board;
  std::string output;
  int pixels_per_square = 200;
};

int run_draw(const DrawArgs &args) {
  using namespace camhead::pipeline;
  MarkerBoard board;
  try {
    board = load_marker_board(args.board);
  } catch (const MarkerBoardError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  BoardPage page;
  try {
    page = draw_board_page(board, args.pixels_per_square);
  } catch (const MarkerModuleError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  // Grey 0 and 255 are sRGB 0 and 1, which PNG keeps exactly.
  renderer::Image image(page.width, page.height, 1);
  for (std::size_t i = 0; i < page.grey.size(); ++i)
    image.data[i] = renderer::srgb_to_linear(float(page.grey[i]) / 255.0f);
  try {
    renderer::write_image(args.output, image);
  } catch (const renderer::ImageError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 4;
  }
  const double width_mm = board.squares_x * board.square_m * 1000.0;
  const double height_mm = board.squares_y * board.square_m * 1000.0;
  std::fprintf(stderr,
               "%s: %s, %dx%d squares, %dx%d px; print it %.0f x %.0f mm (%.0f dpi at that "
               "size), check a square measures %.1f mm, and say so in the board file if not\n",
               args.output.c_str(), board.name.c_str(), board.squares_x, board.squares_y,
               page.width, page.height, width_mm, height_mm,
               args.pixels_per_square / (board.square_m * 1000.0 / 25.4), board.square_m * 1000.0);
  return 0;
}

} // namespace

void add_markers_command(CLI::App &app) {
  CLI::App *cmd = app.add_subcommand("markers", "Marker boards (camhead-markers files)");
  cmd->require_subcommand(1);
  auto args = std::make_shared<DrawArgs>();
  CLI::App *draw = cmd->add_subcommand(
      "draw", "Draw a ChArUco board's page as OpenCV's detector expects it (even row\n"
              "counts included), its edges the board's outer edges, to print or to put on\n"
              "a plane of a scene (a diffuse material's albedo_texture).\n"
              "Example: camhead markers draw scenes/markers/floor_board.json -o board.png");
  draw->add_option("board", args->board, "The board's file (camhead-markers v1, type charuco)")
      ->required()
      ->check(path_text() & CLI::ExistingFile);
  draw->add_option("-o,--output", args->output, "The page: a PNG (replaced whole)")
      ->required()
      ->check(path_text());
  draw->add_option("--pixels-per-square", args->pixels_per_square,
                   "Pixels along a square's side (default 200: 500 dpi for 1 cm squares)")
      ->check(CLI::Range(1, 4096));
  draw->callback([args] { set_exit_code(run_draw(*args)); });
}

} // namespace camhead::cli

// The camera's pose from the markers in its own picture: a ChArUco board or
// a marker field (marker_board.h) found in the luma plane of the frame that
// is rendered, with that frame's lens.
//
// The detection and the pose solve are OpenCV's (aruco, calib3d), in a
// module opened at run time (libcamhead_markers.so, built where Debian's
// libopencv-contrib-dev is installed), so that camhead starts without
// OpenCV where a board does not ask for markers, as it does without
// libcamera. Nothing here includes an OpenCV header.
//
// Thread safety: a tracker is used by one thread at a time.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "camera_pose.h"
#include "marker_board.h"

namespace camhead::pipeline {

// A module that cannot be opened, or a board it cannot track.
class MarkerModuleError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// A frame's luma plane, as captured: 8-bit, rows `stride` bytes apart; its
// codes are sRGB's encoding of the light (as the renderer decodes a
// camera's video), over 16-235 (`limited_range`, as Y'CbCr video most
// often is) or 0-255. The tracker reads and aligns the board in light,
// decoded (marker_module.cpp).
struct LumaImage {
  const std::uint8_t *data = nullptr;
  int width = 0, height = 0;
  std::ptrdiff_t stride = 0;
  bool limited_range = false;
};

// The lens at that frame, in pixels of the luma plane: OpenCV's camera
// matrix and Brown-Conrady coefficients in its order (k1 k2 p1 p2 k3).
struct CameraModel {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  std::array<double, 5> distortion{};
  // Its defocus (thin lens): a point z metres ahead of the lens, along its
  // axis, is a disc of defocus_px * |1 / focus_m - 1 / z| pixels across.
  // 0: not known, taken as sharp.
  double focus_m = std::numeric_limits<double>::infinity();
  double defocus_px = 0.0;
};

struct MarkerPose {
  bool found = false;           // enough of the board seen for a pose
  CameraPose pose;              // the camera in the scene's world, when found
  double reprojection_px = 0.0; // RMS distance of the points used from where the pose puts them
  int markers_seen = 0;         // the board's markers detected (0 where aligned first)
  int points_used = 0;          // corners the pose was solved from
  // A planar target seen nearly head on has two poses that fit almost
  // equally well (the mirror flip): the one nearer the previous pose was
  // kept, and the frame is flagged.
  bool ambiguous = false;
  // The board's markers were too blurred (defocus, motion) to read, and its
  // chessboard corners were followed from where the previous pose put them.
  bool followed = false;
  // Neither its markers nor its corners could be read, and the whole board,
  // drawn as the previous pose and the lens's defocus show it, was aligned
  // with the picture.
  bool aligned = false;
};

class MarkerTracker {
public:
  virtual ~MarkerTracker() = default;
  // The camera's pose in one picture. `previous`, where there is one (the
  // pose predicted for this picture from the last ones found), picks
  // between the two poses of an ambiguous planar view, and lets a ChArUco
  // board be followed where its markers cannot be read: its corners, or,
  // blurred by `camera`'s defocus by 2 px or more there, the whole board
  // aligned. Never throws.
  virtual MarkerPose track(const LumaImage &luma, const CameraModel &camera,
                           const CameraPose *previous) = 0;
};

// One view of a camera calibration: the ChArUco corners found in it, and
// whether the fit used it (else why not) with its reprojection error.
struct CalibrationView {
  int corners = 0;
  bool used = false;
  double rms_px = 0.0; // in the final fit, of the views used
  std::string why_not;
};

// A camera's model fitted to views of a ChArUco board (OpenCV's
// calibrateCamera): its matrix and distortion in the views' pixels, the RMS
// reprojection error over the views used, and each view's part.
struct CameraCalibration {
  CameraModel camera;
  double rms_px = 0.0;
  std::vector<CalibrationView> views;
};

// A ChArUco board's printed page, as OpenCV 4.6 draws it (the layout its
// detector expects, even row counts included: opencv_contrib issue 3291):
// 8-bit grey, black 0 and white 255, row-major from the top; its top-left
// corner is the board's origin and its edges are the board's outer edges
// (marker_board.h), each square `pixels_per_square` pixels.
struct BoardPage {
  std::vector<std::uint8_t> grey;
  int width = 0, height = 0;
};

// Opens the module (once per process) and makes a tracker for `board`.
// Throws MarkerModuleError saying what is missing: the module, OpenCV's
// packages, or a build for another camhead.
[[nodiscard]] std::unique_ptr<MarkerTracker> open_marker_tracker(const MarkerBoard &board);

// Fits the camera that took `views` (all of one size) of the ChArUco board
// `board`: views where too few corners are found, and those whose error is
// far above the rest (a blurred or misdetected view), are left out and the
// fit repeated. Throws MarkerModuleError: the module missing, a board that
// is not ChArUco, or too few usable views (each view's reason given).
[[nodiscard]] CameraCalibration calibrate_camera(const MarkerBoard &board,
                                                 const std::vector<LumaImage> &views);

// Draws the page of the ChArUco board `board`. Throws MarkerModuleError:
// the module missing, a marker field (its markers are printed one by one),
// or a page too large (over 16384 pixels a side).
[[nodiscard]] BoardPage draw_board_page(const MarkerBoard &board, int pixels_per_square);

// "libcamhead_markers.so".
[[nodiscard]] const char *marker_module_name();
// Why marker tracking cannot run here (the module or OpenCV missing, a
// module of another build), or empty where it can: opens the module.
[[nodiscard]] std::string marker_module_problem();

} // namespace camhead::pipeline

#pragma once
// `gsa calibrate`: intrinsics and lens distortion of each camera, and the poses of a rig's
// cameras relative to camera 0, from photographs of a flat calibration target (OpenCV
// calib3d).
//
// Each camera's images are calibrated on their own (cv::calibrateCamera: focal lengths,
// principal point, k1 k2 p1 p2 [k3]); then each camera c > 0 is placed relative to camera 0
// by cv::stereoCalibrate with the intrinsics fixed, from the views where both found the
// target. The images of different cameras are paired by their position in each camera's
// sorted list (take them at the same time, name them so they sort alike). A chessboard's
// corner order can come out rotated by 180 degrees in one camera and not the other; pairs
// whose board poses disagree with the others are tried with the order reversed and dropped
// (reported) if they still disagree.

#include <functional>
#include <string>
#include <vector>

#include "gsa/digitise/camera.hpp"
#include "gsa/digitise/image.hpp"

namespace sf::gsa::digitise {

enum class TargetKind { kChessboard, kCircles, kAsymmetricCircles };

struct CalibrationTarget {
  TargetKind kind = TargetKind::kChessboard;
  int cols = 0, rows = 0;  // inner corners (chessboard) or circles per row / rows
  double spacing = 0;      // square size or circle spacing, in the rig's units (mm)
  // Target points in the order OpenCV's detectors report them (z = 0).
  std::vector<Vec3> points() const;
  std::string describe(const std::string& units = "mm") const;  // "chessboard 11x8 inner corners, 12 mm squares"
};

struct CalibrateOptions {
  CalibrationTarget target;
  bool fix_k3 = true;  // estimate k1 k2 p1 p2 only (k3 = 0), the usual for normal lenses
  bool zero_tangential = false;
  bool fix_aspect = false;  // fx = fy
  int min_views = 3;        // per camera
  void validate() const;    // throws sf::UsageError naming the option
};

struct ImageReport {
  std::string name;
  bool found = false;
  double rms_px = 0;  // reprojection error of the target points (when found)
  std::string note;   // why not found / why left out
};

struct CameraReport {
  std::string name;
  int width = 0, height = 0;
  std::vector<ImageReport> images;
  int n_used = 0;
  double rms_px = 0;  // overall reprojection error of the camera's calibration
};

struct StereoReport {
  Index camera = 0;  // camera c, placed relative to camera 0
  int n_pairs = 0;
  double rms_px = 0;
  double baseline = 0;               // distance between the camera centres (rig units)
  std::vector<std::string> dropped;  // pairs left out, with why
};

struct CalibrationResult {
  Rig rig;  // world frame = camera 0
  std::vector<CameraReport> cameras;
  std::vector<StereoReport> stereo;
};

// Loads image k of camera c (one at a time: a rig's calibration images need not fit in memory).
using ImageLoader = std::function<GreyImage(std::size_t camera, std::size_t k)>;

// names[c] = camera c's image names (sorted; names[c][k] is what load(c, k) returns).
// Throws sf::InputError naming the image for images of different sizes within a camera, and
// naming the camera when fewer than min_views images show the target, or when a camera
// shares no view with camera 0. Images are searched in parallel on `threads` threads (0: the
// hardware's count).
CalibrationResult calibrate_rig(const std::vector<std::vector<std::string>>& names, const ImageLoader& load,
                                const CalibrateOptions& options, int threads = 0);
// Same with the images in memory.
CalibrationResult calibrate_rig(const std::vector<std::vector<NamedImage>>& images, const CalibrateOptions& options);

// The calibration report that goes into the rig file ("calibration" object).
nlohmann::json calibration_report(const CalibrationResult& result, const CalibrateOptions& options);

}  // namespace sf::gsa::digitise

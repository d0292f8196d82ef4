#pragma once
// The standard synthetic study of `gsa digitise`: a two- or three-camera rig looking at a
// 155 mm square sheet with a 5 mm grid (dots or lines, with a reference mark), its flat
// blank, the formed part (dome or bend), and chessboard views for calibration. Used by
// the tests, bench/gsa_digitise_bench.cpp and `gsa synth-images` (docs/digitise.md).
//
// World frame = the sheet's frame: the flat blank lies in z = 0 with its grid on the X
// and Y axes, the formed part bulges toward +z, toward the cameras.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "gsa/digitise/camera.hpp"
#include "gsa/digitise/digitise.hpp"
#include "gsa/digitise/raycast.hpp"

namespace sf::gsa::digitise::synth {

struct ExampleOptions {
  int width = 1632, height = 1224;  // pixels (2.0 megapixels)
  int n_cameras = 2;                // 2 or 3
  SheetShape shape = SheetShape::kDome;
  PatternKind marks = PatternKind::kDots;  // kDots or kLines
  int half_marks = 15;                     // marks -15..15 per side (31 x 31)
  double pitch = 5.0;                      // mm
  bool reference = true;                   // print the reference mark
  bool occlusion = false;                  // an occluding flap over the part and a trimmed corner
  bool uneven_lighting = true;             // a left-to-right fall-off and vignetting
  int calibration_views = 12;              // chessboard views per camera
  Effects effects{8, 0.7, 1.5 / 255.0, 1, 8, 0};
};

// The true cameras (world = sheet frame).
std::vector<Camera> example_cameras(const ExampleOptions& o);
// The part (flat blank or formed) with its printed grid.
Scene example_part(const ExampleOptions& o, SheetShape shape);
// Chessboard views used for calibration (each board fully inside every camera's image).
std::vector<Scene> example_calibration_boards(const ExampleOptions& o);
// The chessboard's inner-corner counts and square size (mm), as `gsa calibrate` is told.
struct BoardSpec {
  int cols, rows;
  double square;
};
BoardSpec example_board(const ExampleOptions& o);

// True world positions of the grid marks (i, j) of a scene's pattern on its sheet, only
// marks on the part (inside its trimmed outline).
struct TrueMark {
  int i, j;
  Vec3 position;
  double lambda1, lambda2;  // exact principal stretches of the forming there
};
std::vector<TrueMark> true_marks(const Scene& scene);

// One photograph of `scene` per camera, named after the camera; camera c's noise is seeded
// with seed + 31 c (the 2-megapixel studies of the benchmark and the long tests).
std::vector<NamedImage> render_views(const std::vector<Camera>& cameras, const Scene& scene, const Effects& effects,
                                     unsigned seed);

// The material index (I, J) of a label as gsa digitise gives it for this study's camera 0
// (i along the image rows = +X, j down the image = -Y; lines: junction (0, 0) is the
// reference cell's corner at Y = pitch), shifted by `shift` first (sets labelled without a
// reference mark).
std::pair<int, int> material_index(const Label& label, PatternKind marks, const Label& shift = Label(0, 0));

// Digitised marks against the exact ones.
struct Comparison {
  Index n = 0;                          // marks compared
  Index mislabelled = 0;                // marks more than a quarter pitch from their label's exact position
  double rms = 0, max = 0;              // in the marks' frame (mm)
  double rms_rigid = 0, max_rigid = 0;  // after the best rigid motion of the marks onto the truth
};
// `to_frame` maps the exact world positions into the marks' frame (e.g. a rig's camera 0).
Comparison compare_marks(const std::vector<DigitisedMark>& marks, const Scene& scene, PatternKind kind,
                         const Eigen::Isometry3d& to_frame = Eigen::Isometry3d::Identity(),
                         const Label& shift = Label(0, 0));

}  // namespace sf::gsa::digitise::synth

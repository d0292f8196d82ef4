#pragma once
// `gsa digitise`: from one photograph per camera of a rig to labelled 3-D grid marks, and
// from the flat blank's and the formed part's sets to a grid file (CONTRACT.md).
//
//   images (one per camera) --find_marks--> labelled marks per view (detect.hpp)
//     --match_view--> every view's labels in camera 0's (match.hpp)
//     --triangulate--> 3-D marks (triangulate.hpp), dots corrected for perspective bias
//
// Marks that cannot be labelled unambiguously, views whose labels do not fit the epipolar
// geometry, and marks that do not triangulate consistently are reported with the reason,
// never guessed.

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "gsa/digitise/camera.hpp"
#include "gsa/digitise/detect.hpp"
#include "gsa/digitise/image.hpp"
#include "gsa/digitise/match.hpp"
#include "gsa/digitise/triangulate.hpp"
#include "gsa/grid.hpp"

namespace sf::gsa::digitise {

struct DigitiseOptions {
  DetectOptions detect;  // detect.seed applies to camera 0's image only
  MatchOptions match;
  TriangulationOptions triangulation;
  bool bias_correction = true;  // dots: correct the perspective bias of centroids
  double dot_diameter_mm = 0;   // for the bias correction; 0: measured from the images
  int threads = 0;              // views detected in parallel; 0: the hardware's count

  // Throws sf::UsageError naming the option.
  void validate() const;
};

struct DigitisedMark {
  Label ij = Label(0, 0);
  Vec3 X = Vec3::Zero();  // rig frame (mm)
  double rms_px = 0;      // RMS reprojection error over the views used
  int n_views = 0;
};

struct ViewReport {
  std::string name;
  Index n_candidates = 0;  // blobs (dots) or cells (lines) found
  Index n_labelled = 0;    // marks labelled in this view
  Index n_used = 0;        // after the epipolar check
  bool has_reference = false;
  Vec2 reference_pixel = Vec2::Zero();
  LabelTransform transform;                 // this view's labels -> camera 0's
  Index n_consistent = 0, n_runner_up = 0;  // epipolar votes (views other than camera 0)
  std::string dropped;                      // why the whole view was left out (three or more cameras)
  nlohmann::json thresholds;
  std::vector<Rejection> rejected;
  double seconds = 0;
};

struct SetResult {
  std::vector<DigitisedMark> marks;  // ordered by (j, i)
  std::vector<ViewReport> views;
  struct Failure {
    Label ij;
    std::string why;
  };
  std::vector<Failure> failed;  // labelled but not triangulated
  bool has_reference = false;   // camera 0 saw the reference mark (labels relative to it)
  Vec2 reference_lattice = Vec2::Zero();
  MarkKind kind = MarkKind::kDots;
  double rms_px = 0, max_rms_px = 0;  // over the marks
  double dot_diameter_mm = 0;         // used by the bias correction (0: none applied)
  double max_bias_px = 0;             // largest perspective-bias correction applied
  double seconds = 0;

  nlohmann::json to_json() const;  // the report (docs/digitise.md)
};

// Reads one image per camera, in the rig's camera order, checking count and sizes against
// the rig. `option` names the command-line option in messages (e.g. "--deformed").
std::vector<NamedImage> read_image_set(const Rig& rig, const std::vector<std::string>& paths, const std::string& option,
                                       const std::string& rig_name);

// Digitises one set. Throws sf::InputError naming the image when a view holds no usable
// grid or (two cameras) its labels cannot be matched to camera 0's.
SetResult digitise_set(const Rig& rig, const std::vector<NamedImage>& images, const DigitiseOptions& options);

// ---------------------------------------------------------------------------------------
// Grid files

// A rigid frame for a digitised set: origin at mark (0, 0) (the marks' centroid when it was
// not measured), X along the grid's +i direction, Z normal to the marks' best-fit plane on
// the side of `toward` (camera 0's centre), Y = Z x X (so +j, down camera 0's image, is -Y).
Eigen::Isometry3d grid_frame(const SetResult& set, const Vec3& toward);

struct GridRow {
  Label ij = Label(0, 0);
  Vec3 undeformed = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  Vec3 deformed = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  int views_undeformed = 0, views_deformed = 0;  // 0: not measured (nominal or missing)
  double rms_undeformed = std::numeric_limits<double>::quiet_NaN();
  double rms_deformed = std::numeric_limits<double>::quiet_NaN();
};

// Rows of the grid file: every label of either set; undeformed from the flat blank's set
// (in `undeformed_frame`) or, with `pitch` > 0 and no undeformed set, the nominal
// (i pitch, -j pitch, 0); deformed from `deformed` (in `deformed_frame`).
std::vector<GridRow> join_sets(const SetResult* undeformed, const Eigen::Isometry3d& undeformed_frame,
                               const SetResult& deformed, const Eigen::Isometry3d& deformed_frame, double pitch);

// The id of mark (i, j) in the grid files digitise and synth-images write: "i<i>_j<j>".
std::string mark_id(long i, long j);

// The rows as the grid data `gsa analyse` works on (ids "i<i>_j<j>", labels in i, j; a
// state not measured is NaN), for running the analysis straight from the library.
GridData grid_data(const std::vector<GridRow>& rows);

// Writes the grid file through io::GridFileWriter: `#` comment lines (and "# units: U"
// when `units` is not empty), then the columns id, X, Y, Z, x, y, z, i, j and digitise's
// own views_undeformed, reproj_undeformed_px, views_deformed, reproj_deformed_px (empty
// where the state was not measured). Positions are rounded to 1e-5 units, errors to 1e-4 px.
void write_grid(std::ostream& out, const std::vector<GridRow>& rows, const std::vector<std::string>& comments,
                const std::string& units = "");

}  // namespace sf::gsa::digitise

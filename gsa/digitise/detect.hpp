#pragma once
// Grid marks in one photograph: detection, sub-pixel centres, and grid labels (i, j).
//
// Dots (filled circles, dark on a light sheet by default):
//   1. local sheet brightness B: a grey-level closing wider than a dot (removes the dots,
//      keeps the lighting), smoothed; contrast C = (B - I) / B, so uneven lighting cancels;
//   2. blobs: connected regions with C > threshold;
//   3. rejected, with the reason reported: touching the image border, area outside
//      [area_low, area_high] x the median, an outline that is not an ellipse (RMS
//      deviation from the moment ellipse), too elongated, too little contrast;
//   4. centre: the grey-level centroid of (P - I) / P over a window around the blob, P a
//      plane fitted to the window's rim (the local sheet level) -- the centroid of the
//      dot's projected area -- or (--centre ellipse) the centre of an ellipse fitted to
//      sub-pixel edge points at half contrast;
//   5. the reference mark: the one dot with at least `reference_area_ratio` times the area
//      of its neighbours (print it at the grid's origin).
//   The projected centre of a circle is not the projection of its centre (perspective
//   bias); triangulate.hpp corrects it once the surface orientation is known.
//
// Line grids (squares): the light cells between the lines are found as blobs and labelled
// as a lattice; each junction is first placed from the cells around it, then refined by
// fitting the centre lines of its four arms (contrast-weighted centroids of cross-sections
// taken parallel to the other line, so they never cross it; quadratic in the arm
// coordinate, so a curved line on a formed part is not biased) and intersecting the two.
// The reference is a dot printed in the middle of cell (0, 0), whose corner (0, 0) is
// junction (0, 0).
//
// Labels: lattice.hpp grows the lattice from the reference mark (or a given seed pixel, or
// the mark nearest the middle of the marks). i runs along the lattice direction nearest the
// image's +u (right), j down the image. After labelling, a dot whose area differs from its
// labelled neighbours' by more than `partial_area_change` is dropped as partly hidden or
// cut by the part's edge.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/digitise/image.hpp"
#include "gsa/digitise/lattice.hpp"

namespace sf::gsa::digitise {

enum class MarkKind { kDots, kLines };
enum class CentreMethod { kCentroid, kEllipse };

struct DetectOptions {
  MarkKind kind = MarkKind::kDots;
  bool dark_marks = true;      // marks darker than the sheet (false: light marks)
  double threshold = 0.35;     // contrast C above which a pixel belongs to a mark
  double min_contrast = 0.25;  // a dot's median contrast must reach this
  double mark_size_px = 0;     // dot diameter / cell size in pixels (0: measured)
  double min_area_px = 8;      // smaller blobs are noise
  double area_low = 0.3;       // blob area accepted in [area_low, area_high] x median
  double area_high = 3.5;
  double max_outline_residual = 0.1;  // RMS outline deviation from an ellipse / radius
  double min_axis_ratio = 0.25;       // minor / major axis
  double reference_area_ratio = 1.6;  // reference dot: area / neighbours' median area
  double partial_area_change = 0.1;   // dot dropped when |area / neighbours' - 1| exceeds this
  CentreMethod centre = CentreMethod::kCentroid;
  double lattice_tolerance = 0.3;  // see lattice.hpp
  std::optional<Vec2> seed;        // a pixel near the mark to label (0, 0) when there is no reference

  // Throws sf::UsageError naming the option ("--threshold: ...") for values out of range.
  void validate() const;
};

// Why a blob or mark was not used.
struct Rejection {
  Vec2 where;          // pixel
  std::string reason;  // e.g. "area 12 px < 30 px (0.3 x median)"
};

struct ViewMarks {
  std::string name;
  int width = 0, height = 0;
  MarkKind kind = MarkKind::kDots;
  std::vector<Vec2> centres;         // labelled marks, pixels
  std::vector<Label> labels;         // their (i, j)
  std::vector<double> areas;         // dot image areas, pixels^2 (lines: 0)
  std::vector<Vec2> axis_i, axis_j;  // local lattice step vectors, pixels
  bool has_reference = false;        // labels are relative to the reference mark
  Vec2 reference_pixel = Vec2::Zero();
  // Lattice coordinates of the reference: (0, 0) for a reference dot, (0.5, 0.5) for the
  // reference cell of a line grid.
  Vec2 reference_lattice = Vec2::Zero();
  std::vector<Rejection> rejected;  // blobs and marks not used, with reasons
  Index n_candidates = 0;           // blobs (dots) or cells (lines) found
  double mark_size_px = 0;          // measured (or given) mark size
  double median_area_px = 0;
  nlohmann::json thresholds;  // what was applied (for the report)
};

// Finds and labels the marks of one image. Throws sf::InputError naming `name` when the
// image holds no usable grid (e.g. "IMG: too few grid marks (3 found; need 9)").
ViewMarks find_marks(const GreyImage& image, const std::string& name, const DetectOptions& options);

}  // namespace sf::gsa::digitise

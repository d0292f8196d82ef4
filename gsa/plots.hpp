#pragma once
// Pictures of a `gsa analyse` results folder (BRIEF.md §1 "Pictures", CONTRACT.md) and the
// one page that shows them, report.html. Everything is read back from the folder's files
// (strains.csv, summary.json, undeformed.vtp, deformed.vtp), so `gsa plot DIR` can redraw
// any results folder with other options.
//
// Pictures (PNG, surface method; the triangle method has no fitted surfaces and gets only
// the principal strain plot):
//   arrows_undeformed.png  principal strain arrows on the undeformed blank
//   arrows_deformed.png    the same on the formed part
//   thickness.png          thickness change (%) contours on the formed part
//   major_strain.png       major strain contours on the formed part
//   minor_strain.png       minor strain contours on the formed part
//   principal_strains.png  major against minor strain per mark, with reference lines and
//                          the forming limit curve when given
//   shear_angle.png        fibre mode: trellis shear angle contours
//   fibres.png             fibre mode: both fibre families as short lines on the part
//   report.html            summary and all pictures
//
// Arrows: at a regular sampling of the surface (element centres, or 2 x 2 ... points per
// element on small meshes), two perpendicular pairs along the principal directions; each
// arrow is `scale * |strain|` long, with one scale for both arrow pictures stated in the
// legend; heads point out for tension (red) and in for compression (blue).

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/core/types.hpp"
#include "common/io/csv.hpp"
#include "common/io/vtk_xml.hpp"
#include "common/render/scene.hpp"

namespace sf::gsa {

enum class StrainMeasure { kTrue, kEngineering, kLagrangian };

// "true", "engineering" or "lagrangian" (also "green"); throws sf::UsageError naming
// `option` otherwise.
StrainMeasure parse_measure(const std::string& text, const std::string& option = "--measure");
// "true", "engineering", "Lagrangian (Green)".
std::string measure_name(StrainMeasure m);
// Strain in measure `m` of a principal stretch.
double strain_of_stretch(double stretch, StrainMeasure m);

// A forming limit curve: major limit strain against minor strain, in the measure the
// pictures use. Read from CSV with columns `minor` and `major` (any order, '#' comments),
// at least 2 rows; sorted by minor strain on reading.
struct FormingLimitCurve {
  std::string source;
  std::vector<double> minor, major;
  // Linear interpolation at `minor`; NaN outside the curve's minor range.
  double major_at(double minor_strain) const;
};
// Throws sf::InputError naming the file, line and column for bad content.
FormingLimitCurve read_flc(const std::string& path);

struct PlotOptions {
  StrainMeasure measure = StrainMeasure::kTrue;
  render::ImageSize size;  // pixels (--size WxH)
  render::View view;       // for the pictures of the formed part (--view); the undeformed
                           // blank is always seen along its mean normal
  std::string flc_path;    // --flc FILE: forming limit curve (minor, major) in `measure`
  bool quiet = true;
};

// A results folder read back: what the pictures are drawn from.
struct ResultsFolder {
  std::string dir;
  nlohmann::json summary;          // summary.json (empty if absent)
  std::string units = "mm";        // length unit from summary.json
  std::string case_name;           // e.g. "dome/grid.csv": the input's folder and name
  std::vector<double> fibre_angles;  // degrees, fibre mode only
  bool has_surfaces = false;       // undeformed.vtp and deformed.vtp present (surface method)
  io::PolyMesh undeformed, deformed;
  io::CsvTable strains;
};
// Throws sf::InputError when DIR has no strains.csv or its files do not belong together.
ResultsFolder read_results_folder(const std::string& dir);

// The arrow diagram on the undeformed (deformed = false) or deformed surface, as a scene
// (write it with render::write_png). Needs has_surfaces.
render::Scene arrow_diagram(const ResultsFolder& results, bool deformed, const PlotOptions& options);

struct PlotSummary {
  std::vector<std::string> pictures;  // file names written, in report order
  bool flc = false;
  Index n_marks = 0;           // marks in the principal strain plot
  Index n_beyond_flc = 0;      // marks above the forming limit curve
  double min_flc_margin = 0;   // smallest margin (NaN when none could be computed)
};

// Reads the results in `in_dir` and writes the pictures and report.html to the paths
// `out_path(name)` gives (in `gsa analyse`: the atomic output folder). With a forming limit
// curve, strains.csv is rewritten there with a column `flc_margin` (FLC major strain at
// the mark's minor strain minus its major strain, in the plots' measure; negative =
// beyond the limit). Throws sf::InputError for unreadable results, sf::Error when no
// display can be had.
PlotSummary write_pictures(const std::string& in_dir,
                           const std::function<std::string(const std::string&)>& out_path,
                           const PlotOptions& options);

}  // namespace sf::gsa

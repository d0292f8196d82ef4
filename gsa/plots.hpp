#pragma once
// Pictures of the results of `gsa analyse` (BRIEF.md §1 "Pictures", CONTRACT.md) and the
// one page that shows them, report.html. They are drawn from a PlotData: built from the
// results in memory by `gsa analyse`, or from a results folder read back by `gsa plot DIR`
// (strains.csv, summary.json, undeformed.vtp, deformed.vtp), which redraws any results
// folder with other options. Drawing computes nothing new: the forming limit margins come
// with the data (gsa/flc.hpp).
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
//   zones.png              with a forming limit assessment: the zones on the formed part
//   section_N.png          per --section: major, minor and thickness strain along the cut
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
#include "common/io/vtk_xml.hpp"
#include "common/render/scene.hpp"
#include "gsa/analysis.hpp"
#include "gsa/flc.hpp"
#include "gsa/flc_assessment.hpp"
#include "gsa/results_folder.hpp"
#include "gsa/sections.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

struct PlotOptions {
  render::ImageSize size;  // pixels (--size WxH)
  render::View view;       // for the pictures of the formed part (--view); the undeformed
                           // blank is always seen along its mean normal
  // Cut the height of the pictures of the part to its proportions (a long strip drawn
  // 1200 x 900 filled 6 % of the picture): with the default size, not with --size.
  bool fit_height = false;
};

// The results of one analysis as the pictures show them.
struct PlotData {
  std::string source;                            // the results folder, for messages
  std::string case_name;                         // e.g. "dome/grid.csv": the input's folder and name
  std::string units = "mm";                      // length unit
  std::vector<double> fibre_angles;              // degrees, fibre mode only
  nlohmann::json summary;                        // summary.json's content
  bool has_surfaces = false;                     // fitted surfaces (surface method)
  io::PolyMesh undeformed, deformed;             // tessellated surfaces with the strain fields, as in the .vtp files
  StrainMeasure measure = StrainMeasure::kTrue;  // the strain the pictures show
  MarkStrains marks;                             // every mark's principal strains in `measure`
  std::optional<FormingLimitCurve> flc;          // drawn in the principal strain plot (in `measure`)
  std::optional<FlcMargins> margins;             // of the marks against it
  std::vector<StrainPath> strain_paths;          // stage series: paths drawn on the principal strain plot
  // Press-shop results (gsa analyse with a curve, --thickness, --section): the zones on the
  // part (zones.png) and on the principal strain plot, one line plot per section.
  std::optional<FlcAssessment> assessment;  // per-mark zones (with flc)
  std::vector<Section> sections;            // section_N.png
  SectionOptions section_options;           // measure and mid-surface options of the sections and zones
};
// From a results folder read back.
PlotData plot_data(ResultsFolder folder, StrainMeasure measure);
// From the results in memory: the analysis, its summary and its tessellated surfaces
// (empty for the triangle method); `dir` is the results folder.
PlotData plot_data(const AnalysisResult& result, nlohmann::json summary, io::PolyMesh undeformed, io::PolyMesh deformed,
                   const std::string& dir, StrainMeasure measure);

// The arrow diagram on the undeformed (deformed = false) or deformed surface, as a scene
// (write it with render::write_png). Needs has_surfaces.
render::Scene arrow_diagram(const PlotData& data, bool deformed, const PlotOptions& options);

struct PlotSummary {
  std::vector<std::string> pictures;  // file names written, in report order
  Index n_marks = 0;                  // marks in the principal strain plot
};

// Pictures drawn so far of the total, after each one (done = 0 before the first).
using PictureProgress = std::function<void(int done, int total)>;

// Writes the pictures and report.html to the paths `out_path(name)` gives (in `gsa
// analyse`: the atomic output folder). Throws sf::InputError for data that lack a field
// the pictures need, sf::Error when no display can be had.
PlotSummary write_pictures(const PlotData& data, const PlotOptions& options,
                           const std::function<std::string(const std::string&)>& out_path,
                           const PictureProgress& progress = {});

// `gsa plot DIR`: reads the results folder, with a curve (in `measure`) writes its
// strains.csv again with the margins (to out_path("strains.csv")), and draws the pictures.
struct Redrawn {
  PlotSummary pictures;
  std::optional<FlcMargins> margins;  // with a curve
};
// Whether the forming-limit assessment that `gsa analyse` put in `summary` (its zones) was
// made with this curve (the same points) in this measure; a redraw with another curve or
// measure drops those zones (zones.png, the report's counts) instead of showing them beside it.
bool zones_belong_to(const nlohmann::json& summary, const FormingLimitCurve& flc, StrainMeasure measure);

Redrawn redraw_results_folder(const std::string& dir, StrainMeasure measure,
                              const std::optional<FormingLimitCurve>& flc, const PlotOptions& options,
                              const std::function<std::string(const std::string&)>& out_path,
                              const PictureProgress& progress = {});

}  // namespace sf::gsa

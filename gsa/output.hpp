#pragma once
// Writing the results of `gsa analyse` (CONTRACT.md): strains.csv, summary.json,
// undeformed.vtp, deformed.vtp and, with --sample, samples.csv. Everything is
// written into a temporary folder and moved into place only when all succeeded.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/io/atomic_file.hpp"
#include "common/io/vtk_xml.hpp"
#include "gsa/analysis.hpp"
#include "gsa/flc.hpp"
#include "gsa/flc_assessment.hpp"
#include "gsa/grid.hpp"
#include "gsa/midsurface.hpp"
#include "gsa/sections.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::io {
class AtomicOutputDir;
}

namespace sf::gsa {

// A results folder of `gsa analyse` (one state or a stage series) replaces the old one
// whole: these are its outputs (an older run's pictures, surfaces or stages never stay
// beside new strains); the user's own files in the folder are kept.
io::OutputDirOptions analyse_results_folder();

struct OutputOptions {
  std::string units = "mm";  // name of the grid's length unit, written into every file
  int sample = 0;            // > 0: also samples.csv with sample x sample points per element (<= 50)
  // A forming limit curve in the strain `measure`: strains.csv gets a last column
  // flc_margin (gsa/flc.hpp), computed here once.
  std::optional<FormingLimitCurve> flc;
  StrainMeasure measure = StrainMeasure::kTrue;
  bool keep_surfaces = false;  // return the tessellated surfaces (to draw pictures from them)
  // Press-shop outputs (issue 17; docs/usage.md "Mid-surface strains", "Forming-limit
  // assessment", "Sections"). With mid.enabled() (--thickness): mid-surface strains and the
  // thickness per mark (strains.csv mid_major, mid_minor, thickness_mm) and on the surfaces;
  // the forming limit is then assessed on the mid-surface strains.
  MidSurfaceOptions mid;
  std::string flc_description;        // how the curve was made (table, Keeler-Brazier, FLC0)
  ZoneOptions zones;                  // with a curve: the zones (strains.csv flc_radial_margin, zone)
  std::vector<SectionSpec> sections;  // --section, in order: section_N.csv
  bool neck = false;                  // --neck: evaluate a neck on each section
  // Throws OptionError naming the field for a value out of range.
  void validate() const;
};

struct RunInfo {
  std::string command_line;
  std::vector<std::string> inputs;
};

// Column names of strains.csv, in order.
std::vector<std::string> strain_columns(const AnalysisResult& result);

// Per-mark press-shop results written beside the strains (nothing when not asked for).
struct PressColumns {
  std::vector<std::optional<MidSurfaceStrain>> mid;  // per mark, with OutputOptions::mid
  std::optional<FlcAssessment> assessment;           // with a curve
};

// With margins, a comment line and a last column flc_margin; with `press`, the columns
// mid_major, mid_minor, thickness_mm (before flc_margin) and flc_radial_margin, zone (after).
void write_strains_csv(const std::string& path, const GridData& grid, const AnalysisResult& result,
                       const OutputOptions& options, const FlcMargins* margins = nullptr,
                       const PressColumns* press = nullptr);
// Mid-surface strain of every mark (nothing where a mark has no strain or the surfaces
// are missing: triangle method).
std::vector<std::optional<MidSurfaceStrain>> mark_mid_strains(const AnalysisResult& result,
                                                              const MidSurfaceOptions& options);
// The strains the forming limit is assessed on: mid-surface where given, else the face's.
MarkStrains assessed_strains(const AnalysisResult& result, const std::vector<std::optional<MidSurfaceStrain>>& mid,
                             StrainMeasure measure);
nlohmann::json make_summary(const GridData& grid, const AnalysisResult& result, const OutputOptions& options,
                            const RunInfo& info);
// A fitted surface tessellated (subdiv x subdiv quads per element) with the strain fields
// as point data, as undeformed.vtp and deformed.vtp hold it; `deformed` selects the surface.
// With `mid` enabled also mid_lambda1, mid_lambda2 and thickness (current, length unit).
// `measured`: measured_cells(result, subdiv) when already made (gsa/measured_region.hpp; a
// Delaunay triangulation of the marks: both surfaces of one result share it).
io::PolyMesh surface_polymesh(const AnalysisResult& result, bool deformed, int subdiv = 8,
                              const MidSurfaceOptions& mid = {}, const std::vector<bool>* measured = nullptr);
void write_samples_csv(const std::string& path, const AnalysisResult& result, const OutputOptions& options);

// What write_results() computed on the way.
struct WrittenResults {
  nlohmann::json summary;             // summary.json's content
  std::optional<FlcMargins> margins;  // with OutputOptions::flc
  io::PolyMesh undeformed, deformed;  // with OutputOptions::keep_surfaces (surface method)
  PressColumns press;                 // mid-surface strains and the assessment, when asked for
  std::vector<Section> sections;      // one per OutputOptions::sections (section_N.csv written)
};

// Writes everything into `out` (not committed here): strains.csv once (with the forming
// limit margin when options.flc), the surfaces, samples.csv, summary.json. Records the
// write time in result.times.write.
WrittenResults write_results(io::AtomicOutputDir& out, const GridData& grid, AnalysisResult& result,
                             const OutputOptions& options, const RunInfo& info);

}  // namespace sf::gsa

#pragma once
// A results folder of `gsa analyse` read back (for `gsa plot DIR`): strains.csv,
// summary.json and, from the surface method, undeformed.vtp and deformed.vtp.

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/io/csv.hpp"
#include "common/io/vtk_xml.hpp"
#include "gsa/flc.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

struct ResultsFolder {
  std::string dir;
  nlohmann::json summary;     // summary.json (null if absent)
  io::CsvTable strains;       // strains.csv
  bool has_surfaces = false;  // undeformed.vtp and deformed.vtp present (surface method)
  io::PolyMesh undeformed, deformed;
};
// Throws sf::InputError when DIR has no strains.csv or its files do not belong together.
ResultsFolder read_results_folder(const std::string& dir);

// What summary.json says about the run, with defaults for a missing summary.
std::string units_of(const nlohmann::json& summary);                 // length unit ("mm")
std::vector<double> fibre_angles_of(const nlohmann::json& summary);  // degrees; empty unless fibre mode
// "dome/grid.csv": the first input's folder and name; the folder's name without inputs.
std::string case_name_of(const nlohmann::json& summary, const std::string& dir);

// Major and minor strain per row of strains.csv in one measure (NaN unless status ok).
// Throws sf::InputError when the measure's columns are missing or hold bad numbers.
MarkStrains mark_strains(const io::CsvTable& strains, StrainMeasure m);
// The strains the forming limit is assessed on, in measure m: the mid-surface strains
// (mid_major, mid_minor, in the measure summary.json's mid_surface names) when gsa analyse
// wrote them (--thickness), else the marked face's, as gsa analyse does.
MarkStrains assessed_mark_strains(const ResultsFolder& folder, StrainMeasure m);

// Writes the folder's strains.csv to `out` with the column flc_margin (new values),
// keeping its comment lines and adding flc_margin_comment(). With keep_zones (the same
// curve and measure as gsa analyse's assessment) the columns stay as they were, the zones
// included; otherwise flc_radial_margin and zone are left out and flc_margin goes last.
void write_strains_with_margin(const ResultsFolder& folder, const std::string& out, const FlcMargins& margins,
                               bool keep_zones = false);

}  // namespace sf::gsa

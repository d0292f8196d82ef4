#pragma once
// `gsa compare MEASURED SIMULATED --out DIR` (docs/usage.md, "Comparing two analyses"):
// where a simulated part disagrees with a measured one, mark by mark.
//
// Each side is a `gsa analyse` results folder (strains.csv, summary.json and the fitted
// surfaces, surfaces.json) or a grid file, analysed on the spot. Steps:
//
//  1. Registration of the deformed parts, measured onto simulated (fe/registration.hpp):
//     by the marks both sides share (same id, analysed on both), robust rigid fit of their
//     positions on the fitted deformed surfaces; else ICP of the measured marks onto the
//     simulated fitted deformed surface.
//  2. Blank map, measured undeformed -> simulated undeformed (the material coordinates):
//     a robust rigid fit of the shared marks' undeformed positions; without shared marks,
//     of each measured mark's undeformed position against the simulated material point
//     under its registered deformed position (ICP foot point); or the identity
//     (BlankMap::kSame).
//  3. The simulated material point of each measured mark. When the sides share ids: the
//     simulated mark of the same id (its element and xi); a mark missing on either side
//     (not in the file, or without a strain there) is reported and gets no difference.
//     Without shared ids: the measured undeformed position, mapped by the blank map,
//     projected onto the simulated undeformed fitted surface; marks outside the simulated
//     blank are reported and get no difference. (The pictures map every point of the
//     measured surface the second way.)
//  4. Fields of both sides at their own material points, from their fitted surfaces
//     (gsa/mark_strains.hpp), and differences measured - simulated: major and minor
//     strain (in `measure`), thickness change (%), in fibre mode the shear angle (deg) and
//     both fibre stretches; the shape deviation: the registered measured point's signed
//     distance from the simulated deformed surface along its normal (positive on the side
//     the blank's +Z face looks to); the position difference of the same material point
//     (|R x_m + t - x_s|, e.g. draw-in).

#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/core/types.hpp"
#include "common/fe/registration.hpp"
#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"
#include "gsa/strain_measure.hpp"
#include "gsa/surfaces_file.hpp"

namespace sf::gsa {

// One side of a comparison: its fitted surfaces and where each mark sits on them.
struct CompareSide {
  std::string source;  // the folder or grid file as given
  std::string kind;    // "results folder" or "grid file"
  std::string units = "mm";
  std::vector<double> fibre_angles;  // degrees; empty unless fibre mode
  nlohmann::json summary;            // summary.json of the analysis (null for an old folder without one)
  FittedSurfaces surfaces;
  std::vector<std::string> ids;
  std::vector<std::string> status;  // strains.csv status per mark
  std::vector<Index> element;       // -1: no material point
  std::vector<Vec2> xi;
  Index n_marks() const { return static_cast<Index>(ids.size()); }
  // A material point and a strain there: status ok or flagged as an outlier (which keeps the
  // fitted surfaces' strain).
  bool usable(Index m) const;
};

// Reads a results folder of `gsa analyse` (surface method). Throws sf::InputError naming
// the folder for a missing folder, a missing strains.csv or surfaces.json (with what to
// do), or columns that do not belong together.
CompareSide read_compare_side(const std::string& folder);

struct GridSideOptions {
  std::vector<double> fibre_angles;  // as --fibres of gsa analyse
  std::string units = "mm";
};
// Reads a grid file and analyses it (surface method, default settings but these).
CompareSide analyse_compare_side(const std::string& grid_file, const GridSideOptions& options);
// A side from an analysis in memory (surface method; `source` names it in messages).
CompareSide compare_side_from(const GridData& grid, const AnalysisResult& result, const std::string& source,
                              const std::string& units = "mm");

enum class RegistrationMode { kAuto, kIds, kSurface, kNone };
enum class BlankMap { kAuto, kFit, kSame };

struct CompareOptions {
  StrainMeasure measure = StrainMeasure::kTrue;
  RegistrationMode registration = RegistrationMode::kAuto;  // auto: ids when >= min_shared shared marks
  BlankMap blank = BlankMap::kAuto;                         // auto: fit
  Index min_shared = 6;
  fe::RobustOptions robust;
  fe::IcpOptions icp;
  int picture_subdivisions = 6;  // per element side, for the tessellated differences
};

// The difference fields, in column order of differences.csv (values measured - simulated).
enum class Field { kMajor, kMinor, kThickness, kShear, kStretch1, kStretch2 };
inline constexpr int kFieldCount = 6;
const char* field_key(Field f);                     // "major", "minor", "thickness_change_pct", "shear_angle_deg", ...
std::string field_title(Field f, StrainMeasure m);  // "Major true strain"
const char* field_units(Field f);                   // "-", "%", "deg"

struct MarkComparison {
  bool matched = false;
  std::string reason;   // why not matched
  std::string mapping;  // "id" or "material" (projected through the blank map)
  Index sim_mark = -1;  // simulated mark of the same id (-1: none)
  Index sim_element = -1;
  Vec2 sim_xi = Vec2::Zero();
  Vec3 position = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  // measured, fitted deformed (own frame)
  std::array<double, kFieldCount> measured{}, simulated{}, difference{};     // NaN where not defined
  double shape_deviation = std::numeric_limits<double>::quiet_NaN();         // units
  double position_difference = std::numeric_limits<double>::quiet_NaN();     // units
  double registration_distance = std::numeric_limits<double>::quiet_NaN();   // units, after registration
  bool registration_used = false;  // counted in the registration (not an outlier there)
};

struct Statistics {
  Index n = 0;
  double mean = 0, rms = 0, std_dev = 0, min = 0, max = 0, max_abs = 0;
  double p05 = 0, p25 = 0, p50 = 0, p75 = 0, p95 = 0;
};
// Of the finite values (n = 0 when none).
Statistics statistics_of(const std::vector<double>& values);

// The differences on the measured fitted deformed surface, tessellated (for pictures and
// compare.vtp): points in the measured frame.
struct DifferenceSurface {
  Points3 points;
  std::vector<std::vector<Index>> polygons;
  std::array<std::vector<double>, kFieldCount> difference;  // per point (NaN outside the simulated part)
  std::vector<double> shape_deviation, position_difference;
};

struct CompareResult {
  fe::RegistrationReport registration;      // measured onto simulated
  fe::RigidTransform blank;                 // measured undeformed -> simulated undeformed
  std::string blank_method;                 // "shared marks", "ICP foot points", "same (identity)"
  double blank_rms = 0.0;                   // RMS of the blank fit's residuals (units)
  std::vector<MarkComparison> marks;        // one per measured mark, in its order
  std::vector<std::string> simulated_only;  // simulated ids with no measured mark of that id (shared-id runs)
  bool fibre_mode = false;
  StrainMeasure measure = StrainMeasure::kTrue;
  Index n_shared = 0;  // ids usable on both sides
  DifferenceSurface surface;
  double seconds_registration = 0, seconds_mapping = 0;
};

// Checks that the sides can be compared (same units, same fibre mode and angles: an
// sf::InputError naming both otherwise), registers, maps and differences them.
CompareResult compare(const CompareSide& measured, const CompareSide& simulated, const CompareOptions& options);

// summary.json of a comparison.
nlohmann::json compare_summary(const CompareSide& measured, const CompareSide& simulated, const CompareResult& r,
                               const std::string& command_line);
// differences.csv.
void write_differences_csv(const std::string& path, const CompareSide& measured, const CompareResult& r);

}  // namespace sf::gsa

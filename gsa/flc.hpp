#pragma once
// The forming limit curve (docs/usage.md, "--flc"): reading it, evaluating it, and the
// margin of every mark against it.
//
// File: CSV with columns `minor` and `major` (any order, '#' comments), at least 2 rows,
// strains in the measure of the analysis' pictures (--measure). The rows must be monotone in
// minor strain (ascending or descending; a row that turns back or repeats a minor strain is an
// error naming its line); they are stored ascending and interpolated linearly between.
//
// Margin of a mark: the curve's major strain at the mark's minor strain minus the mark's
// major strain; positive = safe, negative = beyond the limit; NaN for marks without a
// strain or with a minor strain outside the curve's range.

#include <limits>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

struct FormingLimitCurve {
  std::string source;                // the file it was read from
  std::vector<double> minor, major;  // ascending minor strain
  // Linear interpolation at `minor`; NaN outside the curve's minor range.
  double major_at(double minor_strain) const;
};
// Throws sf::InputError naming the file (line and column for bad cells).
FormingLimitCurve read_flc(const std::string& path);

struct FlcMargins {
  std::string source;  // the curve's file
  StrainMeasure measure = StrainMeasure::kTrue;
  std::vector<double> margin;                                    // per mark (NaN: no strain, or outside the curve)
  Index n_marks = 0;                                             // marks with a strain
  Index n_beyond = 0;                                            // marks beyond the curve (margin < 0)
  double min_margin = std::numeric_limits<double>::quiet_NaN();  // smallest margin (NaN: none)
};
// `marks` must be in the curve's measure `measure`.
FlcMargins flc_margins(const FormingLimitCurve& curve, const MarkStrains& marks, StrainMeasure measure);

// The comment line that explains the flc_margin column of strains.csv (without the newline).
std::string flc_margin_comment(const FlcMargins& margins);

}  // namespace sf::gsa

#pragma once
// Gross blunders: a mark typed wrong by far (undeformed X = 150 instead of 5, Z = 1000 on
// a flat blank). Left in, such a mark stretches the automatic mesh over empty space and
// the fit fails ("singular", issue 20); the finer outlier checks (gsa/blunders.hpp,
// gsa/outliers.hpp) only run after the fit. So, before any fit: a mark whose nearest
// other mark, in either state, is more than 8 times the median nearest-mark distance
// away is flagged, left out of the analysis (status outlier_undeformed or
// outlier_deformed) and named in a warning. Real grids have no such isolated marks: a
// gap or a missing region leaves the marks at its edge with neighbours one spacing away.
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"

namespace sf::gsa {

struct GrossBlunder {
  Index point = -1;
  bool undeformed = true;  // which state's position is wrong
  double distance = 0.0;   // to its nearest other mark (units)
  double spacing = 0.0;    // the median nearest-mark distance (units)
};

inline constexpr double kGrossBlunderFactor = 8.0;

// Finds the gross blunders of `grid` and sets their wrong position to NaN (the analysis
// then leaves them out).
std::vector<GrossBlunder> screen_gross_blunders(GridData& grid);
// Gives the flagged points their status and adds one warning per blunder to `result`
// ("mark P12: undeformed position lies 95.2 mm from the nearest mark (spacing 5 mm) ...").
void report_gross_blunders(AnalysisResult& result, const GridData& grid, const std::vector<GrossBlunder>& blunders,
                           const std::string& units);

}  // namespace sf::gsa

#pragma once
// Error of computed strains against exact ones (tests and the accuracy benchmark).

#include <vector>

#include "gsa/analysis.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {

struct StrainError {
  double rms_e1 = 0, rms_e2 = 0;  // RMS error of major / minor Green strain
  double max_abs = 0;             // max |error| over both
  double rms_shear_deg = 0;       // trellis shear angle, when computed
  Index n = 0;                    // marks compared
  Index n_missing = 0;            // marks in the set without a strain
  double rms() const { return std::sqrt(0.5 * (rms_e1 * rms_e1 + rms_e2 * rms_e2)); }
};

// Compares at marks at least `border` grid steps inside the grid's outline: every
// grid position (i + di, j + dj), |di|, |dj| <= border, holds a mark (border = 1 on
// a square grid: all but the outermost ring; on a round one, all but the rim).
StrainError strain_error(const GridData& grid, const AnalysisResult& result, const std::vector<ExactStrain>& exact,
                         int border = 1);

}  // namespace sf::gsa

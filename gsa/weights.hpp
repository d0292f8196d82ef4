#pragma once
// Fit weights from the per-point uncertainty a measuring system exports (GridData::sigma_*,
// docs/theory/strain.md "Weights from the measurement uncertainty").
//
// A mark measured with standard deviation sigma_k enters the least-squares data term with
//
//   w_k = (sigma_ref / sigma_k)^2,   sigma_ref = the median sigma of the fit's marks,
//
// so the typical mark keeps weight 1 and the smoothing weights (which are per unit data
// weight, gsa/fit.hpp) mean what they mean without weights. Equal sigmas give w = 1
// exactly (the unweighted fit, bit for bit); a mark with a huge sigma has a weight near 0
// and no influence (below kNegligibleWeight: weight 0, left out); a mark without a sigma
// (NaN, or negative) gets weight 1. Sigmas below
// kSigmaFloor x sigma_ref count as that floor (w <= 1e4), so a sigma of 0 cannot pin the
// surface to one mark.
//
//   const SigmaWeights w = sigma_weights(grid.sigma_deformed, marks.point);
//   // w.weight: m entries, 1 where the input has no sigma or weights are off

#include <limits>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa {

inline constexpr double kSigmaFloor = 0.01;
// A weight below this (sigma over 1000 sigma_ref) is 0: the point is left out of the fit
// like one not measured (it still gets the strain of the surfaces at its material point),
// so it does not count in the noise estimates and the smoothing choice either.
inline constexpr double kNegligibleWeight = 1e-6;

struct SigmaWeights {
  VecX weight;                                                  // m: the base weight of each mark
  bool used = false;                                            // sigma given and weighting on
  double sigma_ref = std::numeric_limits<double>::quiet_NaN();  // median sigma (units)
  Index n_with_sigma = 0;                                       // marks with a finite sigma > 0
  Index n_floored = 0;                                          // marks whose sigma was raised to the floor
  Index n_left_out = 0;                                         // marks of negligible weight (set to 0)
  double min_weight = 1.0, max_weight = 1.0;
};

// `sigma`: n_points entries (NaN: none) or empty (no sigma: all weights 1, used = false);
// `points`: the grid index of each of the m marks. With `enabled` false all weights are 1.
SigmaWeights sigma_weights(const std::vector<double>& sigma, const std::vector<Index>& points, bool enabled = true);

}  // namespace sf::gsa

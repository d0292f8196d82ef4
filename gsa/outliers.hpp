#pragma once
// Outlier detection of `gsa analyse` (docs/theory/strain.md, "Outliers"): marks whose fit
// residual is far beyond the noise are flagged, each with the reason, and left out of the
// fit; flagged marks that a later surface fits well are readmitted. Both fits use it.
//
// Threshold: max(k * robust sigma, floor) with robust sigma = median residual /
// (median of |r| / sigma for Gaussian noise in `dims` components) and floor = 2 % of
// the mark spacing. Each round flags only the worst marks beyond it (at least half the
// largest such residual): one bad mark drags its neighbours' residuals up until it is
// removed.

#include <string>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa {

struct OutlierOptions {
  double sigma = 6.0;  // flag residuals beyond this many robust noise sigmas (> 0)
};

// Why a mark was left out.
enum class OutlierReason {
  kResidual,  // its residual exceeded the threshold
};
const char* to_string(OutlierReason reason);

struct OutlierFlag {
  Index mark = -1;  // index into the fit's marks (FitMarks)
  OutlierReason reason = OutlierReason::kResidual;
  double residual = 0.0;   // its residual when flagged (units)
  double threshold = 0.0;  // the threshold it exceeded (units)
};

// Components of the residuals: the undeformed fit's are distances along the normal
// (projection absorbs the in-plane noise into xi), the deformed fit's 3-D vectors.
enum class ResidualKind { kNormal = 1, kVector = 3 };

// The threshold over the marks with weight > 0 (see above).
double outlier_threshold(const VecX& residual, const VecX& weight, ResidualKind kind, const OutlierOptions& options,
                         double mark_spacing);
// One round: the worst marks with weight > 0 beyond the threshold, in mark order.
std::vector<OutlierFlag> detect_outliers(const VecX& residual, const VecX& weight, ResidualKind kind,
                                         const OutlierOptions& options, double mark_spacing);
// Removes from `flags` the marks whose residual is now below `threshold` and returns them.
std::vector<OutlierFlag> take_readmitted(std::vector<OutlierFlag>& flags, const VecX& residual, double threshold);

}  // namespace sf::gsa

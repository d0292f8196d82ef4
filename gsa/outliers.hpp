#pragma once
// Outliers of `gsa analyse` (docs/theory/strain.md, "Outliers"): isolated blunders,
// never real deformation.
//
// A large fit residual alone does not make a mark wrong: a neck narrower than the
// smoothing, a wrinkle or a dimple leaves large residuals on every mark it covers, and
// flagging them hides the highest strains of the part. A mark is flagged only when its
// neighbours disagree with it (gsa/blunders.hpp): its position is far from the local
// quadratic fit of its nearest neighbours (leaving it out), in noise levels, AND far
// more than its neighbours are from theirs. Undeformed state: the normal component of
// the undeformed position. Deformed state: the deformed position against the
// undeformed in-plane coordinates (this also catches an undeformed position typed
// wrong in the plane: its deformed position does not fit where it claims to be).
//
// A flagged mark takes no part in the fits that its state enters (an undeformed flag:
// both fits; a deformed flag: the deformed fit), still gets the strain of the fitted
// surfaces at its material point, and is readmitted when the final surface passes
// within its threshold. Every flag carries its numbers (deviation, threshold, noise).

#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/blunders.hpp"
#include "gsa/frame_mesh.hpp"

namespace sf::gsa {

struct OutlierOptions {
  double sigma = 4.5;      // deviation from the neighbours' local fit, in noise levels (> 0)
  double isolation = 2.5;  // and over the second largest deviation of the 8 nearest neighbours (>= 1)
  int neighbours = 16;     // of the local fit (>= 8)
  double floor = 0.005;    // the threshold is at least this fraction of the mark spacing (noise-free data)
};

// Why a mark was flagged.
enum class OutlierReason {
  kUndeformedOffNeighbours,  // its undeformed position is off its neighbours' surface
  kDeformedOffNeighbours,    // its deformed position is off its neighbours' deformation
};
const char* to_string(OutlierReason reason);
// One word for tables: "undeformed_off_neighbours", "deformed_off_neighbours".
const char* code(OutlierReason reason);

struct OutlierFlag {
  Index mark = -1;  // index into the fit's marks (FitMarks)
  OutlierReason reason = OutlierReason::kDeformedOffNeighbours;
  double deviation = 0.0;  // from the neighbours' local fit (units)
  double threshold = 0.0;  // the threshold it exceeded (units): sigma x noise, or the floor
  double noise = 0.0;      // the robust noise level along its deviation (units): deviation / score,
                           // the deformed check's noise covariance in that direction
};
// "deformed position 0.123 mm off its neighbours' local fit (threshold 0.061 mm = 4.5 x noise 0.0136 mm)"
std::string describe(const OutlierFlag& flag, double sigma, const std::string& units);

struct MarkOutliers {
  std::vector<OutlierFlag> undeformed, deformed;
  double noise_undeformed = 0.0, noise_deformed = 0.0;  // robust noise levels of the deviations (units)
  // The deformed check's two levels (gsa/blunders.hpp): along its noise's noisiest axis
  // (stereo DIC: the viewing direction) and per component across it (units).
  double noise_deformed_axis = 0.0, noise_deformed_across = 0.0;
  // The undeformed check's neighbour candidates, reused by the deformed check when it
  // uses the same marks (gsa/blunders.hpp).
  std::shared_ptr<const BlunderNeighbours> neighbours;
};
// deformed: m x 3 deformed positions of the marks (NaN where not digitised).
MarkOutliers find_outliers(const FitMarks& marks, const Points3& deformed, double mark_spacing,
                           const OutlierOptions& options);
// The two halves of find_outliers, for a stage series (one undeformed state, many deformed
// ones): the undeformed flags (deformed left empty), then a deformed state's flags against
// them (`out.undeformed` kept; `out.deformed` and `out.noise_deformed` replaced).
// `neighbours`: undeformed_outlier_neighbours(marks, options), searched ahead (e.g. beside
// the frame and mesh); null: searched here.
MarkOutliers find_undeformed_outliers(const FitMarks& marks, double mark_spacing, const OutlierOptions& options,
                                      std::shared_ptr<const BlunderNeighbours> neighbours = nullptr);
std::shared_ptr<const BlunderNeighbours> undeformed_outlier_neighbours(const FitMarks& marks,
                                                                       const OutlierOptions& options);
void find_deformed_outliers(const FitMarks& marks, const Points3& deformed, double mark_spacing,
                            const OutlierOptions& options, MarkOutliers& out);

// Removes from `flags` the marks whose residual (distance from the final surface, which
// they took no part in) is within their threshold, and returns them.
std::vector<OutlierFlag> take_readmitted(std::vector<OutlierFlag>& flags, const VecX& residual);

}  // namespace sf::gsa

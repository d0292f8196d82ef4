#pragma once
// Stage of `gsa analyse`: smoothing relaxed where the fit cannot follow a localised
// feature (docs/theory/strain.md, "Local smoothing").
//
// One smoothing weight for the whole part serves it badly when the strain varies
// sharply in one place: a neck a few spacings wide, a wrinkle. The weight that suits
// the rest of the part smooths the neck's peak away; the weight the neck needs leaves
// the rest noisy. So, after the weight is chosen:
//
//   1. the part is fitted 100 x more heavily; an element where that fit misses the data
//      coherently (the mean residual over the marks of the element and its four
//      neighbours exceeds 4 standard deviations of the mean of the noise model at those
//      marks, correlation included) holds a feature the smoothing would flatten;
//   2. those elements get a penalty multiplier of 0.01 (their edges the smaller one of
//      the two elements), and the weight is chosen again for the rest of the part;
//   3. repeated (at most three rounds) until no further element is found;
//   4. every element relaxed alike is one lighter weight everywhere: the multiplier is
//      folded into the chosen weights and the elements reported as not relaxed.
//
// Each element's multiplier is reported with the local gauge length it gives.

#include <functional>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/frame_mesh.hpp"
#include "gsa/noise_model.hpp"
#include "gsa/smoothing.hpp"
#include "gsa/undeformed_fit.hpp"

namespace sf::gsa {

class DeformedProblem;

struct LocalSmoothing {
  std::vector<double> multiplier;  // per element of the mesh (1: the global weight)
  int rounds = 0;                  // rounds that relaxed some element
  Index relaxed() const;           // elements with a multiplier below 1
};

// `choose` chooses the weight again for the problem as it stands (its multipliers set);
// `choice` holds the current choice and is updated. The problem keeps the final
// multipliers.
LocalSmoothing relax_smoothing(DeformedProblem& problem, SmoothingChoice& choice, const NoiseEstimate& noise,
                               const FrameAndMesh& setup, const UndeformedFit& undeformed, const FitMarks& marks,
                               const std::function<SmoothingChoice()>& choose);

}  // namespace sf::gsa

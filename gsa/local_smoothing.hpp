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
// Steps 1-3 run where the noise is correlated (`residual_test`). Under independent noise
// a strain test takes step 1's place where cross-validation chose about the heaviest
// weight it may (log10(delta / d^6) >= 5.5): an element whose marks' residuals have a
// local gradient (least squares over each mark and its 8 nearest) beyond the noise, by
// a mean squared standardised in-plane component above 6 (strain_misfit_scores), is
// where the fit's strain misses the data's own: a band narrower than the elements that
// the heaviest weight flattens (the ARAMIS crack band, docs/usage.md "Real exports").
// Elsewhere under independent noise steps 1-3 run as a trial: kept only where GCV, the
// weight chosen again, falls by 6 / N or more (N marks in use), and the relaxed elements
// are then never smoothed more than the whole part was before. A coherent feature that
// held the global weight down (a dimple, a neck) is relaxed and the rest smoothed more;
// on a smooth curved part (a dome) GCV refuses it. Not on noise-free marks.
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
                               const std::function<SmoothingChoice()>& choose, bool residual_test);

// Per element of the mesh: how far the fit's strain misses the data's own where the fit
// leaves `residual` (m x 3). At each mark in use the residuals' gradient is fitted by
// least squares over the mark and its 8 nearest; each of its four in-plane components is
// squared over its variance under the noise model (correlation and, where estimated, the
// in-plane level), then scaled so that its median over the marks is a chi-square(1)'s
// (0.455; with 20 marks or more): 1 on average under noise alone, whether the model's
// level is right or not (a feature's own misfit inflates the estimate). The score is the
// largest component's mean over the element's marks (0 with fewer than 2 judged marks).
std::vector<double> strain_misfit_scores(const MatX& residual, const VecX& weight, const NoiseEstimate& noise,
                                         const FrameAndMesh& setup, const UndeformedFit& undeformed,
                                         const FitMarks& marks);

}  // namespace sf::gsa

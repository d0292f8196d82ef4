#pragma once
// Stage of `gsa analyse`: the noise model of the measurement (gsa/noise_model.hpp),
// which the automatic smoothing is chosen with (docs/theory/strain.md, "Noise model").
//
//   NoiseEstimate u = undeformed_noise(setup, marks, undeformed);   // correlation length
//   NoiseEstimate n = deformed_noise(problem, marks, setup, u);      // amplitudes of the deformed data
//
// Undeformed state: the normal residuals of the undeformed fit, refitted with a ladder
// of pilot smoothings (delta = 10^k d^6, k = 8 .. 1). The undeformed sheet is usually
// flat or gently curved, so heavy pilots leave the noise in their residuals and no
// bias; each pilot's variogram is fitted with the shrinkage of its own smoother
// accounted for. Taken: the heaviest pilot whose fit shows no smooth bias and whose
// estimate the next lighter pilot confirms (light pilots take up long-range noise
// themselves and see too little of it).
//
// Deformed state: a formed part is not simple, so heavy pilots are biased; its
// correlation length is taken from the undeformed state (the same measurement, the same
// image subsets) and only the amplitudes (correlated and independent) are fitted, on
// light pilots (k = 4 .. 1), leaving out the points whose neighbourhood fits far worse
// than typical (a neck the pilot cannot follow is misfit, not noise). Taken: the median
// over the pilots.

#include "common/core/types.hpp"
#include "gsa/frame_mesh.hpp"
#include "gsa/noise_model.hpp"
#include "gsa/undeformed_fit.hpp"

namespace sf::gsa {

class DeformedProblem;

NoiseEstimate undeformed_noise(const FrameAndMesh& setup, const FitMarks& marks, const UndeformedFit& undeformed);

NoiseEstimate deformed_noise(DeformedProblem& problem, const FitMarks& marks, const FrameAndMesh& setup,
                             const NoiseEstimate& undeformed);

}  // namespace sf::gsa

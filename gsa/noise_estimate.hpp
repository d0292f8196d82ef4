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

// `displacement`: the estimate from the displacement where the blank is exact
// (displacement_noise, gsa/noise_model.hpp): its length is used instead of the blank's
// and its correlated amplitude is the floor.
NoiseEstimate deformed_noise(DeformedProblem& problem, const FitMarks& marks, const FrameAndMesh& setup,
                             const NoiseEstimate& undeformed, const NoiseEstimate* displacement = nullptr);

// The two levels of the deformed data's noise (NoiseEstimate::sigma_tangent, sigma_normal):
// the residuals of the deformed fit `parameters` (data - fitted, m x 3) at the marks with
// weight > 0, projected on the fitted deformed surface's normal and tangent plane there;
// robust: sigma_normal = median |r_n| / 0.6745, sigma_tangent = median |r_t| / 1.1774 (the
// medians of the norm of one and of two unit normals). If `into` has an amplitude
// (sigma_total > 0) the two are scaled to it, keeping their ratio; else they are set as
// measured. Fewer than 10 marks: left at 0.
void estimate_two_levels(NoiseEstimate& into, const FrameAndMesh& setup, const UndeformedFit& undeformed,
                         const MatX& parameters, const MatX& residual, const VecX& weight);

}  // namespace sf::gsa

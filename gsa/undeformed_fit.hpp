#pragma once
// Stage 2 of `gsa analyse`: the undeformed surface X(xi) and the marks' material
// coordinates (docs/theory/strain.md, "Undeformed fit").
//
// The fit alternates with nearest-point projection of the marks onto the fitted surface
// until their xi settle; with automatic smoothing a first round estimates the
// digitisation noise from a light fit and sets the weights by the noise rule. Marks
// flagged as outliers beforehand (gsa/outliers.hpp) take no part, are projected all the
// same (so they get a material coordinate), and are readmitted when the final surface
// passes within their threshold. The result is what every deformed fit of the
// same marks starts from: fit it once, and fit as many deformed states against it as
// there are.

#include <vector>

#include "common/core/types.hpp"
#include "gsa/fit.hpp"
#include "gsa/frame_mesh.hpp"
#include "gsa/outliers.hpp"
#include "gsa/smoothing.hpp"

namespace sf::gsa {

struct UndeformedFitOptions {
  SmoothingOptions smoothing;
  std::vector<OutlierFlag> outliers;  // undeformed flags (find_outliers): left out unless readmitted
  int max_projection_iterations = 5;  // fit-and-project rounds per outer round (>= 1)
  VecX weight;                        // m: base weight of each mark (gsa/weights.hpp, from its sigma); empty: all 1
};

struct UndeformedFit {
  MatX parameters;                     // n_dofs x 3: the fitted surface X(xi)
  std::vector<MeshLocation> location;  // m: each mark's material coordinate (element, xi)
  VecX residual;                       // m: distance of each mark from X at its location (units)
  VecX weight;                         // m: its base weight where the mark took part (1 without sigma), 0 where flagged
  std::vector<OutlierFlag> flags;      // the marks left out (not readmitted), with reasons
  double rms = 0.0, max = 0.0;         // residuals over the marks that took part
  Penalty penalty;                     // the weights of the final fit
  double noise_estimate = 0.0;         // digitisation noise per coordinate (automatic smoothing), units
  int projection_iterations = 0;       // projections in the last round
  double fit_seconds = 0.0, project_seconds = 0.0;
};

// Throws sf::InputError naming marks.source when the least-squares system is singular
// (too few marks for the mesh).
UndeformedFit fit_undeformed(const FrameAndMesh& setup, const FitMarks& marks, const UndeformedFitOptions& options);

}  // namespace sf::gsa

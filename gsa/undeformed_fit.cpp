#include "gsa/undeformed_fit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "common/core/error.hpp"
#include "common/mesh/projection.hpp"

namespace sf::gsa {

namespace {

// The undeformed fit and projection alternate until no mark moves more than this (in xi).
constexpr double kXiSettled = 1e-4;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Projects the marks onto the surface `parameters`, updating their locations; returns the
// largest change of xi (1 when a mark changed element). The first projection searches the
// whole surface; later ones start from each mark's last location.
double project_marks(const FrameAndMesh& setup, const FitMarks& marks, const MatX& parameters, bool& searched,
                     std::vector<MeshLocation>& loc) {
  const Index m = marks.size();
  const mesh::SurfaceProjector projector(setup.mesh, parameters);
  std::vector<mesh::Projection> proj;
  if (searched) {
    std::vector<Index> elements(static_cast<std::size_t>(m));
    std::vector<Vec2> xi(static_cast<std::size_t>(m));
    for (Index k = 0; k < m; ++k) elements[k] = loc[k].element, xi[k] = loc[k].xi;
    proj = projector.refine_all(marks.undeformed, elements, xi);
  } else {
    proj = projector.project_all(marks.undeformed);
    searched = true;
  }
  double max_dxi = 0.0;
  for (Index k = 0; k < m; ++k) {
    if (!proj[k].ok()) continue;
    if (proj[k].element == loc[k].element)
      max_dxi = std::max(max_dxi, (proj[k].xi - loc[k].xi).norm());
    else
      max_dxi = 1.0;
    loc[k] = {proj[k].element, proj[k].xi};
  }
  return max_dxi;
}

// Noise estimate from a light fit's normal residuals, corrected for the fitted degrees of
// freedom; NaN when the marks do not outnumber the unknowns enough. With weights from
// the marks' sigmas (w = (sigma_ref / sigma)^2) the weighted sum estimates the noise of a
// mark of weight 1; without, the weights are 1 and this is the plain estimate.
double estimate_noise(const FitResult& fit, const VecX& weight, Index n_dofs) {
  double n_used = 0.0;
  const double dofs = static_cast<double>(n_dofs);
  double rss = 0.0;
  for (Index k = 0; k < weight.size(); ++k)
    if (weight[k] > 0) rss += weight[k] * fit.residual[k] * fit.residual[k], n_used += 1.0;
  if (!(n_used > 1.2 * dofs)) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(rss / (n_used - dofs));  // normal residuals: one component
}

}  // namespace

UndeformedFit fit_undeformed(const FrameAndMesh& setup, const FitMarks& marks, const UndeformedFitOptions& options) {
  const mesh::SurfaceMesh& mesh = setup.mesh;
  const double d = setup.mark_spacing;
  const bool automatic = options.smoothing.automatic();
  UndeformedFit out;
  out.location = setup.start;
  const VecX base = options.weight.size() == marks.size() ? options.weight : VecX::Ones(marks.size());
  out.weight = base;
  out.flags = options.outliers;
  for (const OutlierFlag& f : out.flags) out.weight[f.mark] = 0.0;
  out.penalty = penalty_for_noise(options.smoothing, 0.0, d);
  FitResult fit;
  bool searched = false;  // a global projection has been done
  // Round 0 (automatic only): one projection, then the noise estimate sets the weights.
  // Then fit-and-project until the xi settle; once more after readmitting outliers.
  for (int round = automatic ? 0 : 1; round < 3; ++round) {
    const int iterations = round == 0 ? 1 : std::max(1, options.max_projection_iterations);
    for (int it = 0; it < iterations; ++it) {
      const auto tf = Clock::now();
      FitSystem system(mesh, setup.penalties, out.location, out.weight);
      system.set_values(marks.undeformed);
      fit = system.solve(out.penalty, mesh.geometry());
      out.fit_seconds += seconds_since(tf);
      if (!fit.ok) throw InputError(marks.source + ": " + fit.message);
      out.projection_iterations = it + 1;
      const auto tp = Clock::now();
      const double max_dxi = project_marks(setup, marks, fit.parameters, searched, out.location);
      out.project_seconds += seconds_since(tp);
      if (max_dxi < kXiSettled) break;  // xi settled
    }
    if (round == 0) {
      const double noise = estimate_noise(fit, out.weight, mesh.n_dofs());
      if (std::isfinite(noise)) {
        out.noise_estimate = noise;
        out.penalty = noise_rule_penalty(options.smoothing, noise, d);
      }
      continue;
    }
    if (round == 2) break;
    const std::vector<OutlierFlag> back = take_readmitted(out.flags, fit.residual);
    for (const OutlierFlag& f : back) out.weight[f.mark] = base[f.mark];
    if (back.empty()) break;
  }
  out.parameters = fit.parameters;
  out.residual = fit.residual;
  out.rms = fit.rms;
  out.max = fit.max;
  return out;
}

}  // namespace sf::gsa

#include "gsa/analysis.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "gsa/deformed_fit.hpp"
#include "gsa/undeformed_fit.hpp"

namespace sf::gsa {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string found(double v) { return fmt::format(", found {}", v); }

void tell(const ProgressCallback& progress, AnalysisStage stage, const FrameAndMesh* mesh) {
  if (progress) progress(StageStart{stage, mesh});
}

// The deformed fit and its smoothing: the first fit with the noise rule (or the explicit
// weights), outlier rounds, the smoothing choice, readmission.
struct DeformedStages {
  DeformedFit fit;
  SmoothingChoice choice;
};
DeformedStages run_deformed_stages(DeformedProblem& problem, const FrameAndMesh& setup, const UndeformedFit& und,
                                   const AnalyseOptions& options, const ProgressCallback& progress) {
  const double d = setup.mark_spacing;
  DeformedStages out;
  out.fit = fit_deformed(problem, penalty_for_noise(options.smoothing, und.noise_estimate, d), options.outliers, d);
  out.choice = {out.fit.penalty, out.fit.passes};
  if (options.smoothing.chooses_by_gcv()) {
    tell(progress, AnalysisStage::kSmoothingChoice, &setup);
    out.choice = choose_smoothing_gcv(problem, options.smoothing, d);
    refit_deformed(problem, out.fit, out.choice);
  }
  readmit_deformed(problem, out.fit, options.outliers, d);
  return out;
}

// Fills the per-point results in place (`points` was sized before the stages: fresh
// memory for 1e5 points costs 0.1 s here): the status of every point (in order of
// precedence), the fit marks' locations and residuals, and the strains of the ok ones.
void fill_point_results(std::vector<PointResult>& points, const GridData& grid, const FitMarks& marks,
                        const UndeformedFit& und, const DeformedFit& def, const DeformedResiduals& residuals,
                        const SurfacePair& surfaces, const std::vector<double>& fibre_angles) {
  std::vector<char> flagged(static_cast<std::size_t>(marks.size()), 0);
  for (const OutlierFlag& f : def.flags) flagged[static_cast<std::size_t>(f.mark)] = 1;
  std::size_t next = 0;  // marks.point is ascending: the points between marks have no undeformed position
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (next < marks.point.size() && marks.point[next] == static_cast<Index>(p)) ++next;
    else points[p].status = kStatusMissingUndeformed;
  }
  for (Index k = 0; k < marks.size(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    PointResult& pr = points[static_cast<std::size_t>(marks.point[kk])];
    pr.status = !(und.weight[k] > 0)                         ? kStatusOutlierUndeformed
                : !grid.has_deformed(marks.point[kk])         ? kStatusMissingDeformed
                : flagged[kk]                                 ? kStatusOutlierDeformed
                                                              : kStatusOk;
    pr.element = und.location[kk].element;
    pr.xi = und.location[kk].xi;
    pr.residual_undeformed = und.residual[k];
    if (pr.status != kStatusOk) continue;
    pr.residual = residuals.residual[k];
    MarkStrain ms = strain_at(surfaces, und.location[kk], fibre_angles);
    if (!ms.strain) {
      pr.status = kStatusDegenerate;
      continue;
    }
    pr.strain = std::move(ms.strain);
    pr.fibres = std::move(ms.fibres);
    pr.shear_angle_deg = ms.shear_angle_deg;
  }
}

// The parameters used, from the stage results.
void record_parameters(AnalysisResult& r, FrameAndMesh& setup, const UndeformedFit& und, const DeformedProblem& problem,
                       const DeformedStages& def, const DeformedResiduals& residuals, const AnalyseOptions& options) {
  r.mesh = std::move(setup.mesh);
  r.centroid = setup.frame.centroid;
  r.axis1 = setup.frame.a1;
  r.axis2 = setup.frame.a2;
  r.elements1 = setup.elements1;
  r.elements2 = setup.elements2;
  r.mesh_layout = setup.layout;
  r.mark_spacing = setup.mark_spacing;
  r.undeformed_parameters = und.parameters;
  r.deformed_parameters = def.fit.fit.parameters;
  r.rigid = problem.rigid();
  r.penalty_kind = options.smoothing.penalty;
  r.smoothing_automatic = options.smoothing.automatic();
  r.penalty_undeformed = und.penalty;
  r.penalty_deformed = def.fit.penalty;
  r.noise_estimate = und.noise_estimate;
  r.gcv_log10_delta = def.choice.gcv_log10_delta;
  r.gauge_length = gauge_length(def.fit.penalty, setup.mark_spacing);
  r.rms_undeformed = und.rms;
  r.max_undeformed = und.max;
  r.rms_deformed = residuals.rms;
  r.max_deformed = residuals.max;
  r.projection_iterations = und.projection_iterations;
  r.outlier_sigma = options.outliers.sigma;
  r.fibre_angles = options.fibre_angles;
}

AnalysisResult analyse_surface(const GridData& grid, const AnalyseOptions& options, const ProgressCallback& progress) {
  AnalysisResult res;
  res.method = Method::kSurface;
  res.points.resize(static_cast<std::size_t>(grid.n_points()));
  tell(progress, AnalysisStage::kFrameAndMesh, nullptr);
  const FitMarks marks = fit_marks(grid);
  const auto t0 = Clock::now();
  FrameAndMesh setup = build_frame_and_mesh(grid, marks, options.mesh);
  res.times.mesh = seconds_since(t0);

  tell(progress, AnalysisStage::kUndeformedFit, &setup);
  const UndeformedFit und = fit_undeformed(setup, marks, {options.smoothing, options.outliers,
                                                          options.max_projection_iterations});
  const DeformedMarks deformed = deformed_marks(grid, marks, und);

  tell(progress, AnalysisStage::kDeformedFit, &setup);
  const auto tf = Clock::now();
  DeformedProblem problem(setup, marks, und, deformed);
  const DeformedStages def = run_deformed_stages(problem, setup, und, options, progress);
  res.times.fit = und.fit_seconds + seconds_since(tf);
  res.times.project = und.project_seconds;
  const DeformedResiduals residuals = deformed_residuals(problem, def.fit);

  tell(progress, AnalysisStage::kStrains, &setup);
  const auto ts = Clock::now();
  const SurfacePair surfaces(setup.mesh, und.parameters, def.fit.fit.parameters);
  fill_point_results(res.points, grid, marks, und, def.fit, residuals, surfaces, options.fibre_angles);
  res.times.strain = seconds_since(ts);
  record_parameters(res, setup, und, problem, def, residuals, options);
  return res;
}

}  // namespace

void AnalyseOptions::validate() const {
  if (mesh.elements1 < 0) throw OptionError("mesh.elements1", "expected a count >= 0" + found(mesh.elements1));
  if (mesh.elements2 < 0) throw OptionError("mesh.elements2", "expected a count >= 0" + found(mesh.elements2));
  if (!mesh.file.empty() && (mesh.elements1 > 0 || mesh.elements2 > 0))
    throw OptionError("mesh.file", "give either a mesh file or element counts, not both");
  const std::pair<const char*, const std::optional<double>*> weights[] = {
      {"smoothing.alpha", &smoothing.alpha}, {"smoothing.beta", &smoothing.beta},
      {"smoothing.gamma", &smoothing.gamma}, {"smoothing.delta", &smoothing.delta}};
  for (const auto& [field, value] : weights)
    if (*value && !(**value >= 0.0)) throw OptionError(field, "a smoothing weight must be >= 0" + found(**value));
  if (!(smoothing.scale > 0.0)) throw OptionError("smoothing.scale", "must be > 0" + found(smoothing.scale));
  if (!(outliers.sigma > 0.0)) throw OptionError("outliers.sigma", "must be > 0" + found(outliers.sigma));
  if (!fibre_angles.empty() && fibre_angles.size() != 2)
    throw OptionError("fibre_angles", "expected two angles in degrees, e.g. 0,90; found " +
                                          std::to_string(fibre_angles.size()));
  for (double a : fibre_angles)
    if (!std::isfinite(a)) throw OptionError("fibre_angles", "expected finite angles in degrees" + found(a));
}

AnalysisResult analyse(const GridData& grid, const AnalyseOptions& options, const ProgressCallback& progress) {
  options.validate();
  if (options.method == Method::kTriangles) return analyse_triangles(grid, options);
  return analyse_surface(grid, options, progress);
}

}  // namespace sf::gsa

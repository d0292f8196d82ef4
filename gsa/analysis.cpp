#include "gsa/analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <future>
#include <limits>

#include "common/core/parallel.hpp"
#include "gsa/deformed_fit.hpp"
#include "gsa/local_smoothing.hpp"
#include "gsa/noise_estimate.hpp"
#include "gsa/undeformed_fit.hpp"
#include "gsa/weights.hpp"

namespace sf::gsa {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string found(double v) { return fmt::format(", found {}", v); }

void tell(const ProgressCallback& progress, AnalysisStage stage, const FrameAndMesh* mesh) {
  if (progress) progress(StageStart{stage, mesh});
}

// The deformed fit and its smoothing: the first fit with the noise rule (or the explicit
// weights), the smoothing choice (noise model or GCV) with local relaxation, readmission.
struct DeformedStages {
  DeformedFit fit;
  SmoothingChoice choice;
  NoiseEstimate noise;   // of the deformed data (noise-model rule)
  NoiseEstimate noise_displacement;  // exact blank: from the displacement (noise-model rule)
  LocalSmoothing local;  // element multipliers (noise-model rule with local smoothing)
};
// `undeformed_noise_of()` gives the blank's noise estimate, waiting for it when it is still
// being made on another thread (analyse_once): only the smoothing choice needs it.
DeformedStages run_deformed_stages(DeformedProblem& problem, const FrameAndMesh& setup, const FitMarks& marks,
                                   const UndeformedFit& und,
                                   const std::function<const NoiseEstimate&()>& undeformed_noise_of,
                                   std::vector<OutlierFlag> flags, const AnalyseOptions& options,
                                   const ProgressCallback& progress, StageTimes& times) {
  const double d = setup.mark_spacing;
  const SmoothingOptions& so = options.smoothing;
  DeformedStages out;
  if (options.fixed_smoothing && so.chooses_by_gcv()) {  // chosen elsewhere (a stage series): one matrix
    const FixedSmoothing& fixed = *options.fixed_smoothing;
    out.local.multiplier = fixed.multiplier;
    if (out.local.multiplier.empty())
      out.local.multiplier.assign(static_cast<std::size_t>(setup.mesh.n_elements()), 1.0);
    if (!fixed.multiplier.empty()) problem.set_element_multipliers(fixed.multiplier);
    out.fit = fit_deformed(problem, fixed.choice.penalty, std::move(flags));
    out.choice = fixed.choice;
    out.noise = fixed.noise;
    refit_deformed(problem, out.fit, out.choice);
    readmit_deformed(problem, out.fit);
    return out;
  }
  out.fit = fit_deformed(problem, penalty_for_noise(so, und.noise_estimate, d), std::move(flags));
  out.choice = {out.fit.penalty, out.fit.passes};
  out.local.multiplier.assign(static_cast<std::size_t>(setup.mesh.n_elements()), 1.0);
  if (so.chooses_by_gcv()) {
    if (so.rule == SmoothingRule::kNoiseModel) undeformed_noise_of();  // waited for outside the choice's time
    tell(progress, AnalysisStage::kSmoothingChoice, &setup);
    const auto tc = Clock::now();
    if (so.rule == SmoothingRule::kGcv) {
      out.choice = choose_smoothing_gcv(problem, so, d);
    } else {
      const NoiseEstimate& undeformed_noise = undeformed_noise_of();
      const auto tn = Clock::now();
      // Reference positions without noise (nominal subset centres of a 2-D DIC export, a
      // grid placed by --pitch): the blank gives no correlation length; the displacement's
      // own estimate does where its quadratic and quartic local fits agree
      // (gsa/noise_model.hpp, displacement_noise), and the deformed pilots then fit the
      // amplitudes with that length, its correlated amplitude as the floor.
      const bool exact_blank = !(undeformed_noise.sigma_total() > 0.0);
      NoiseEstimate& from_displacement = out.noise_displacement;
      if (exact_blank)
        from_displacement = displacement_noise(marks.undeformed, problem.position(), problem.weight(), d);
      const bool exact_correlated = exact_blank && from_displacement.correlated_over(d);
      out.noise = exact_correlated ? deformed_noise(problem, marks, setup, undeformed_noise, &from_displacement)
                                   : deformed_noise(problem, marks, setup, undeformed_noise);
      // Reported only (summary.json): the relaxation test with each component in its own
      // level did not see the ARAMIS crack band either (docs/usage.md, "Real exports").
      estimate_two_levels(out.noise, setup, und, out.fit.fit.parameters, MatX(problem.data()) - out.fit.fit.fitted,
                          problem.weight());
      // Noise correlated over less than a spacing is independent as far as the smoother
      // can tell: there cross-validation, which needs no noise level, is as good and
      // does not inherit the estimate's error (measured: Cp on the wavy part with
      // 0.03 mm independent noise smoothed 1.6 x worse). Cp where the correlation counts:
      // over a spacing or more, or neighbouring marks correlated by 0.3 or more (a length
      // estimated just under the spacing: GCV there chose a gauge of 0.6 spacings and
      // 3.3 x the 24-neighbour fit's error on the rubber strip, gsa_realdata_bench).
      const bool correlated = exact_blank ? exact_correlated : undeformed_noise.correlated_over(d);
      const MatX probes = correlated ? noise_probes(out.noise, marks.undeformed, kCpNoiseProbes) : MatX();
      const double noise_s = seconds_since(tn);
      times.noise += noise_s;
      times.choice -= noise_s;  // timed from tc on below
      auto choose = [&] {
        return correlated ? choose_smoothing_noise_model(problem, so, probes, d) : choose_smoothing_gcv(problem, so, d);
      };
      out.choice = choose();
      // Local relaxation: its residual test (a 100 x heavier fit missing the data coherently)
      // with correlated noise; under independent noise a strain test where GCV chose its
      // heaviest weight, elsewhere the residual test as a trial GCV must accept (it fires on
      // any curved part: gsa/local_smoothing.hpp).
      if (so.local) out.local = relax_smoothing(problem, out.choice, out.noise, setup, und, marks, choose, correlated);
    }
    times.choice += seconds_since(tc);
    refit_deformed(problem, out.fit, out.choice);
  }
  readmit_deformed(problem, out.fit);
  return out;
}

// Fills the per-point results in place (`points` was sized before the stages: fresh
// memory for 1e5 points costs 0.1 s here): the status of every point (in order of
// precedence), the fit marks' locations and residuals, and the strains of every mark
// with a material point (flagged outliers included: the strain is the fitted
// surfaces' there).
void fill_point_results(std::vector<PointResult>& points, const GridData& grid, const FitMarks& marks,
                        const UndeformedFit& und, const DeformedFit& def, const DeformedResiduals& residuals,
                        const SurfacePair& surfaces, const AnalyseOptions& options) {
  std::vector<const OutlierFlag*> flag_u(static_cast<std::size_t>(marks.size()), nullptr), flag_d = flag_u;
  for (const OutlierFlag& f : und.flags) flag_u[static_cast<std::size_t>(f.mark)] = &f;
  for (const OutlierFlag& f : def.flags) flag_d[static_cast<std::size_t>(f.mark)] = &f;
  std::size_t next = 0;  // marks.point is ascending: the points between marks have no undeformed position
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (next < marks.point.size() && marks.point[next] == static_cast<Index>(p))
      ++next;
    else
      points[p].status =
          grid.not_measured_undeformed(static_cast<Index>(p)) ? kStatusNotMeasured : kStatusMissingUndeformed;
  }
  for (Index k = 0; k < marks.size(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    PointResult& pr = points[static_cast<std::size_t>(marks.point[kk])];
    const bool has_deformed = grid.has_deformed(marks.point[kk]);
    pr.status = flag_u[kk] ? kStatusOutlierUndeformed
                : !has_deformed
                    ? (grid.not_measured_deformed(marks.point[kk]) ? kStatusNotMeasured : kStatusMissingDeformed)
                : flag_d[kk] ? kStatusOutlierDeformed
                             : kStatusOk;
    if (const OutlierFlag* f = flag_u[kk] ? flag_u[kk] : flag_d[kk]) pr.flag = *f;
    pr.element = und.location[kk].element;
    pr.xi = und.location[kk].xi;
    pr.residual_undeformed = und.residual[k];
    if (!has_deformed) continue;
    pr.residual = residuals.residual[k];
    MarkStrain ms = strain_at(surfaces, und.location[kk], options.fibre_angles);
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
void record_parameters(AnalysisResult& r, const FrameAndMesh& setup, const UndeformedFit& und,
                       const DeformedProblem& problem, const DeformedStages& def, const DeformedResiduals& residuals,
                       const AnalyseOptions& options) {
  r.mesh = setup.mesh;
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
  r.log10_delta_optimum = def.choice.log10_delta_optimum;
  r.fit_passes = def.fit.passes;
  r.smoothing_criterion = def.choice.criterion;
  r.smoothing_criterion_value = def.choice.criterion_value;
  r.gauge_length = gauge_length(def.fit.penalty, setup.mark_spacing);
  r.rms_undeformed = und.rms;
  r.max_undeformed = und.max;
  r.rms_deformed = residuals.rms;
  r.max_deformed = residuals.max;
  r.projection_iterations = und.projection_iterations;
  r.outlier_sigma = options.outliers.sigma;
  r.fibre_angles = options.fibre_angles;
}

// Refinement at a localised feature narrower than an element (a neck): the deformed fit
// cannot follow it whatever the smoothing, and its residuals there are far above the
// noise, coherently over whole elements. Cells of the automatic mesh whose RMS deformed
// residual exceeds kRefineFactor x the median cell's make a column (row) misfit when they
// are at least half of it; misfit columns (rows) and their neighbours are split into
// up to kRefinePieces equal parts where they are confined to a band (at most half the
// columns or rows), while the parts keep kRefineMinSpacings mark spacings; the analysis
// runs again on the graded mesh, at most kRefineRounds times. Measured on a 30 x 12 mm
// strip, 0.3 mm spacing, a neck of width parameter 0.4 mm on 1.2 mm elements
// (gsa_realdata_bench, neckn cases; docs/theory/strain.md, "Refinement at a neck"):
// halves (0.6 mm, 1.5 x the width parameter) left the 100 % neck's peak 9-10 % high at
// the strip's edges, where the neck's contraction shears the strip (the shear Y dmu/dX,
// largest at the edges, rang between the marks); thirds (0.4 mm) get it within 3 %.
constexpr double kRefineFactor = 3.0;
constexpr double kRefineMinSpacings = 1.3;
constexpr int kRefinePieces = 3;
constexpr int kRefineRounds = 2;
constexpr int kRefineMinMarks = 4;     // marks a cell needs to be judged
constexpr double kRefineFloor = 1e-6;  // RMS residual (x the mark spacing) below which a cell fits

// The refined breaks (fractions) of the automatic mesh `setup` from the result `r`;
// false when nothing is to be refined.
bool refined_breaks(const FrameAndMesh& setup, const FitMarks& marks, const AnalysisResult& r, std::vector<double>& b1,
                    std::vector<double>& b2) {
  const std::vector<double>& c1 = setup.breaks1;
  const std::vector<double>& c2 = setup.breaks2;
  if (c1.size() < 2 || c2.size() < 2 || setup.plane.rows() != marks.size()) return false;
  const int n1 = static_cast<int>(c1.size()) - 1, n2 = static_cast<int>(c2.size()) - 1;
  std::vector<double> sum(static_cast<std::size_t>(n1) * n2, 0.0);
  std::vector<int> count(sum.size(), 0);
  auto cell = [](const std::vector<double>& b, double f) {
    const int i = static_cast<int>(std::upper_bound(b.begin(), b.end(), f) - b.begin()) - 1;
    return std::clamp(i, 0, static_cast<int>(b.size()) - 2);
  };
  for (Index k = 0; k < marks.size(); ++k) {
    const PointResult& pr = r.points[static_cast<std::size_t>(marks.point[static_cast<std::size_t>(k)])];
    if (pr.status != kStatusOk || !std::isfinite(pr.residual)) continue;
    const int i = cell(c1, (setup.plane(k, 0) - setup.plane_low[0]) / setup.plane_length[0]);
    const int j = cell(c2, (setup.plane(k, 1) - setup.plane_low[1]) / setup.plane_length[1]);
    const std::size_t c = static_cast<std::size_t>(j) * n1 + i;
    sum[c] += pr.residual * pr.residual;
    ++count[c];
  }
  std::vector<double> ms;
  for (std::size_t c = 0; c < sum.size(); ++c)
    if (count[c] >= kRefineMinMarks) ms.push_back(sum[c] / count[c]);
  if (ms.size() < 4) return false;
  const auto mid = ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2);
  std::nth_element(ms.begin(), mid, ms.end());
  // Residuals of round-off size are no feature, whatever their ratio: on noise-free marks
  // (a simulated part's virtual grid) the median cell is at 1e-14 mm and a few cells at
  // 1e-13 are no neck (their refinement made the fit singular).
  const double floor = kRefineFloor * setup.mark_spacing;
  const double limit = std::max(kRefineFactor * kRefineFactor * *mid, floor * floor);
  std::vector<int> col(static_cast<std::size_t>(n1), 0), row(static_cast<std::size_t>(n2), 0);
  for (int j = 0; j < n2; ++j)
    for (int i = 0; i < n1; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * n1 + i;
      if (count[c] >= kRefineMinMarks && sum[c] / count[c] > limit) ++col[i], ++row[j];
    }
  const double d = setup.mark_spacing;
  // A column (row) counts as misfit when at least half its cells are: a neck runs across
  // the part; scattered misfit cells (correlated noise over a few spacings makes some)
  // are no band (measured: splitting at them doubled the error of a neck 3 elements wide).
  for (int& c : col) c = 2 * c >= n2 ? c : 0;
  for (int& c : row) c = 2 * c >= n1 ? c : 0;
  auto split = [&](const std::vector<double>& b, const std::vector<int>& hit, double length, std::vector<double>& out) {
    const int n = static_cast<int>(b.size()) - 1;
    const auto hits = std::count_if(hit.begin(), hit.end(), [](int v) { return v > 0; });
    out = b;
    if (hits == 0 || 2 * hits > n) return false;
    out.assign(1, b[0]);
    bool any = false;
    // A misfit cell and its two neighbours are split: the flanks of a neck, where the
    // strain changes fastest, often lie in the cells next to the misfit ones.
    auto near_hit = [&](int i) {
      for (int q = std::max(0, i - 1); q <= std::min(n - 1, i + 1); ++q)
        if (hit[static_cast<std::size_t>(q)] > 0) return true;
      return false;
    };
    for (int i = 0; i < n; ++i) {
      const double w = (b[i + 1] - b[i]) * length;
      const int pieces = std::min(kRefinePieces, static_cast<int>(w / (kRefineMinSpacings * d)));
      if (near_hit(i) && pieces >= 2) {
        for (int q = 1; q < pieces; ++q) out.push_back(b[i] + (b[i + 1] - b[i]) * q / pieces);
        any = true;
      }
      out.push_back(b[i + 1]);
    }
    return any;
  };
  const bool s1 = split(c1, col, setup.plane_length[0], b1);
  const bool s2 = split(c2, row, setup.plane_length[1], b2);
  return s1 || s2;
}

UndeformedStages undeformed_stages(const GridData& grid, const AnalyseOptions& options, const ProgressCallback& progress);
bool needs_undeformed_noise(const AnalyseOptions& options);
void estimate_undeformed_noise(UndeformedStages& u);
AnalysisResult deformed_stages(const UndeformedStages& u, const GridData& grid, const AnalyseOptions& options,
                               const ProgressCallback& progress, const std::function<void()>& await_noise);

// analyse_undeformed() then analyse_deformed(), with the blank's noise estimate (the
// undeformed pilot fits) on a second thread while the deformed blunder check and the
// first deformed fit run: they do not need it, and only the smoothing choice waits for
// it. Each part computes what it computed in turn (the same bits, whatever the threads:
// gsa_threads tests); the stage times then overlap.
AnalysisResult analyse_once(const GridData& grid, const AnalyseOptions& options, const ProgressCallback& progress,
                            UndeformedStages* kept = nullptr) {
  UndeformedStages u = undeformed_stages(grid, options, progress);
  AnalysisResult res;
  {
    std::future<void> noise;  // destroyed (waited for) before `u`, whose parts it reads and writes
    if (needs_undeformed_noise(options)) {
      if (default_threads() > 1)
        noise = std::async(std::launch::async, [&u] { estimate_undeformed_noise(u); });
      else
        estimate_undeformed_noise(u);
    }
    // get() rethrows the estimate's exception; the deformed stages read u.noise only after it.
    auto await_noise = [&noise] {
      if (noise.valid()) noise.get();
    };
    try {
      res = deformed_stages(u, grid, options, progress, await_noise);
    } catch (...) {
      await_noise();  // an error of the estimate came first (it ran first in turn)
      throw;
    }
    await_noise();
  }
  res.times.mesh = u.mesh_seconds;
  res.times.fit += u.fit.fit_seconds;
  res.times.project = u.fit.project_seconds;
  if (kept) *kept = std::move(u);
  return res;
}

AnalysisResult analyse_surface(const GridData& grid, const AnalyseOptions& options, const ProgressCallback& progress) {
  const bool refinable =
      options.mesh.file.empty() && options.smoothing.automatic() && !options.fixed_smoothing && options.smoothing.local;
  if (!refinable) return analyse_once(grid, options, progress);
  UndeformedStages u;
  AnalysisResult res = analyse_once(grid, options, progress, &u);
  AnalyseOptions refined = options;
  for (int round = 0; round < kRefineRounds; ++round) {
    std::vector<double> b1, b2;
    if (!refined_breaks(u.setup, u.marks, res, b1, b2)) break;
    refined.mesh.breaks1 = std::move(b1);
    refined.mesh.breaks2 = std::move(b2);
    const StageTimes before = res.times;
    // Refinement is an improvement, never a reason to lose the analysis: a refined fit that
    // fails (a singular system: parts with too few marks and no noise to smooth by) leaves
    // the last result, with a warning.
    UndeformedStages next_u;
    AnalysisResult next;
    try {
      next = analyse_once(grid, refined, progress, &next_u);
    } catch (const InputError& e) {
      res.warnings.push_back(std::string("mesh refinement at a localised feature skipped (") + e.what() +
                             "); strains are from the mesh before it");
      break;
    }
    res = std::move(next);
    u = std::move(next_u);
    res.refinement_rounds = round + 1;
    double smallest = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 2; ++axis) {
      const std::vector<double>& b = axis == 0 ? u.setup.breaks1 : u.setup.breaks2;
      for (std::size_t i = 0; i + 1 < b.size(); ++i)
        smallest = std::min(smallest, (b[i + 1] - b[i]) * u.setup.plane_length[axis]);
    }
    res.smallest_element = smallest;
    // The time of every round counts.
    res.times.mesh += before.mesh, res.times.outliers += before.outliers, res.times.project += before.project;
    res.times.fit += before.fit, res.times.noise += before.noise, res.times.choice += before.choice;
    res.times.strain += before.strain;
  }
  return res;
}

}  // namespace

namespace {

bool needs_undeformed_noise(const AnalyseOptions& options) {
  return options.smoothing.chooses_by_gcv() && options.smoothing.rule == SmoothingRule::kNoiseModel;
}

void estimate_undeformed_noise(UndeformedStages& u) {
  const auto tn = Clock::now();
  u.noise = gsa::undeformed_noise(u.setup, u.marks, u.fit);
  u.noise_seconds = seconds_since(tn);
}

// analyse_undeformed() without the noise estimate.
UndeformedStages undeformed_stages(const GridData& grid, const AnalyseOptions& options,
                                   const ProgressCallback& progress) {
  options.validate();
  UndeformedStages u;
  tell(progress, AnalysisStage::kFrameAndMesh, nullptr);
  u.marks = fit_marks(grid);
  // The blunder check's neighbour search needs the marks only: on a second thread beside
  // the frame and mesh (the same search, so the same neighbours; its error, if any, is
  // rethrown by get() after the frame and mesh, as in turn).
  std::future<std::shared_ptr<const BlunderNeighbours>> neighbours;
  if (default_threads() > 1)
    neighbours = std::async(std::launch::async, [&u, &options] {
      return undeformed_outlier_neighbours(u.marks, options.outliers);
    });
  const auto t0 = Clock::now();
  u.setup = build_frame_and_mesh(grid, u.marks, options.mesh);
  u.mesh_seconds = seconds_since(t0);

  tell(progress, AnalysisStage::kOutliers, &u.setup);
  const auto to = Clock::now();
  u.outliers = find_undeformed_outliers(u.marks, u.setup.mark_spacing, options.outliers,
                                        neighbours.valid() ? neighbours.get() : nullptr);
  u.outliers_seconds = seconds_since(to);

  tell(progress, AnalysisStage::kUndeformedFit, &u.setup);
  u.weights = sigma_weights(grid.sigma_undeformed, u.marks.point, options.sigma_weights);
  u.fit =
      fit_undeformed(u.setup, u.marks,
                     {options.smoothing, u.outliers.undeformed, options.max_projection_iterations, u.weights.weight});
  return u;
}

// analyse_deformed(); `await_noise()` returns once u.noise and u.noise_seconds are made
// (analyse_once), and is called before they are read.
AnalysisResult deformed_stages(const UndeformedStages& u, const GridData& grid, const AnalyseOptions& options,
                               const ProgressCallback& progress, const std::function<void()>& await_noise) {
  const FitMarks& marks = u.marks;
  const FrameAndMesh& setup = u.setup;
  const UndeformedFit& und = u.fit;
  AnalysisResult res;
  res.method = Method::kSurface;
  res.points.resize(static_cast<std::size_t>(grid.n_points()));
  Points3 deformed_at_marks(marks.size(), 3);
  for (Index k = 0; k < marks.size(); ++k)
    deformed_at_marks.row(k) = grid.deformed.row(marks.point[static_cast<std::size_t>(k)]);
  MarkOutliers outliers = u.outliers;
  const auto to = Clock::now();
  find_deformed_outliers(marks, deformed_at_marks, setup.mark_spacing, options.outliers, outliers);
  res.times.outliers = u.outliers_seconds + seconds_since(to);
  res.weights_undeformed = u.weights;
  res.weights_deformed = sigma_weights(grid.sigma_deformed, marks.point, options.sigma_weights);
  const DeformedMarks deformed = deformed_marks(grid, marks, und, res.weights_deformed.weight);

  tell(progress, AnalysisStage::kDeformedFit, &setup);
  const auto tf = Clock::now();
  DeformedProblem problem(setup, marks, und, deformed);
  // Deformed flags of marks the undeformed fit readmitted or that lack a deformed position stay as found.
  double waited = 0.0;  // for the blank's noise estimate
  auto undeformed_noise = [&]() -> const NoiseEstimate& {
    const auto tw = Clock::now();
    await_noise();
    waited += seconds_since(tw);
    return u.noise;
  };
  DeformedStages def = run_deformed_stages(problem, setup, marks, und, undeformed_noise, std::move(outliers.deformed),
                                           options, progress, res.times);
  await_noise();
  // The deformed stages less the noise estimate, the smoothing choice timed in them and
  // the wait for the blank's estimate (analyse_surface adds the undeformed fit's time).
  res.times.fit = seconds_since(tf) - res.times.noise - res.times.choice - waited;
  res.times.noise += u.noise_seconds;
  const DeformedResiduals residuals = deformed_residuals(problem, def.fit);

  tell(progress, AnalysisStage::kStrains, &setup);
  const auto ts = Clock::now();
  const SurfacePair surfaces(setup.mesh, und.parameters, def.fit.fit.parameters);
  fill_point_results(res.points, grid, marks, und, def.fit, residuals, surfaces, options);
  res.times.strain = seconds_since(ts);
  res.noise_undeformed = u.noise;
  res.noise = def.noise;
  res.noise_displacement = def.noise_displacement;
  res.element_multiplier = def.local.multiplier;
  res.relaxed_elements = def.local.relaxed();
  if (res.relaxed_elements > 0) {
    const double least = *std::min_element(def.local.multiplier.begin(), def.local.multiplier.end());
    Penalty relaxed = def.fit.penalty;
    for (double* w : {&relaxed.alpha, &relaxed.beta, &relaxed.gamma, &relaxed.delta, &relaxed.boundary}) *w *= least;
    res.local_gauge_length = gauge_length(relaxed, setup.mark_spacing);
  }
  res.noise_outliers_undeformed = outliers.noise_undeformed;
  res.noise_outliers_deformed = outliers.noise_deformed;
  res.noise_outliers_deformed_axis = outliers.noise_deformed_axis;
  res.noise_outliers_deformed_across = outliers.noise_deformed_across;
  record_parameters(res, setup, und, problem, def, residuals, options);
  return res;
}

}  // namespace

UndeformedStages analyse_undeformed(const GridData& grid, const AnalyseOptions& options,
                                    const ProgressCallback& progress) {
  UndeformedStages u = undeformed_stages(grid, options, progress);
  if (needs_undeformed_noise(options)) estimate_undeformed_noise(u);
  return u;
}

AnalysisResult analyse_deformed(const UndeformedStages& u, const GridData& grid, const AnalyseOptions& options,
                                const ProgressCallback& progress) {
  return deformed_stages(u, grid, options, progress, [] {});
}

void AnalyseOptions::validate() const {
  if (mesh.elements1 < 0) throw OptionError("mesh.elements1", "expected a count >= 0" + found(mesh.elements1));
  if (mesh.elements2 < 0) throw OptionError("mesh.elements2", "expected a count >= 0" + found(mesh.elements2));
  if (!mesh.file.empty() && (mesh.elements1 > 0 || mesh.elements2 > 0))
    throw OptionError("mesh.file", "give either a mesh file or element counts, not both");
  const std::pair<const char*, const std::optional<double>*> weights[] = {{"smoothing.alpha", &smoothing.alpha},
                                                                          {"smoothing.beta", &smoothing.beta},
                                                                          {"smoothing.gamma", &smoothing.gamma},
                                                                          {"smoothing.delta", &smoothing.delta}};
  for (const auto& [field, value] : weights)
    if (*value && !(**value >= 0.0 && std::isfinite(**value)))
      throw OptionError(field, "a smoothing weight must be a finite number >= 0" + found(**value));
  if (!(smoothing.scale > 0.0) || !std::isfinite(smoothing.scale))
    throw OptionError("smoothing.scale", "must be a finite number > 0" + found(smoothing.scale));
  if (!(outliers.sigma > 0.0) || !std::isfinite(outliers.sigma))
    throw OptionError("outliers.sigma", "must be a number > 0" + found(outliers.sigma));
  if (!fibre_angles.empty() && fibre_angles.size() != 2)
    throw OptionError("fibre_angles",
                      "expected two angles in degrees, e.g. 0,90; found " + std::to_string(fibre_angles.size()));
  for (double a : fibre_angles)
    if (!std::isfinite(a)) throw OptionError("fibre_angles", "expected finite angles in degrees" + found(a));
}

AnalysisResult analyse(const GridData& grid, const AnalyseOptions& options, const ProgressCallback& progress) {
  options.validate();
  if (options.method == Method::kTriangles) return analyse_triangles(grid, options);
  return analyse_surface(grid, options, progress);
}

}  // namespace sf::gsa

#include "gsa/analysis.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/fe/surface_field.hpp"
#include "common/mesh/projection.hpp"
#include "common/quadrature/gauss.hpp"
#include "gsa/mesh_file.hpp"
#include "gsa/plane.hpp"

namespace sf::gsa {

namespace {

// Calibration constants of the automatic smoothing (docs/theory/strain.md).
// (Calibrated against a noise estimate that was sigma/sqrt(3); rescaled when the
// estimate was corrected to sigma, so the weights did not change.)
constexpr double kAutoGamma = 258.7;   // 500 / 3^0.6
constexpr double kAutoBeta = 115.47;   // 200 / sqrt(3)
constexpr double kAutoDelta = 11547.0;  // 2e4 / sqrt(3)
// A whisper of third-order smoothing holds elements the edge jumps alone cannot
// (a single element, or elements with fewer marks than parameters).
constexpr double kJumpsGammaFloor = 1e-6;
constexpr double kGcvStrainFactor = 2.0;
// The automatic deformed fit is iterated once (two passes, iterated Tikhonov): the
// second pass smooths towards the first one, which squares the smoothing bias.
constexpr int kAutoFitPasses = 2;
// The undeformed fit and projection alternate until no mark moves more than this (in xi).
constexpr double kXiSettled = 1e-4;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Marks per element: ~9 for a few hundred marks, growing slowly up to 1e4 marks
// (22 x 22 elements on a square part); beyond that the element count stays. The
// fit-feasibility study found 6-9 elements a side best for 21 x 21 marks and 20-50
// for 1e5 marks; on a dense grid more elements only add unknowns (the
// factorisation's cost) while the part's shape, not the mark spacing, sets the
// resolution it needs. Measured on the 100 mm dome with 1e5 marks
// (gsa_stages_bench 1e5 N): 16, 20, 22, 24, 28 and 34 elements a side gave RMS
// strain errors 0.95, 1.16, 1.28, 1.42, 1.69 and 1.93e-4 and fit times 0.32,
// 0.45, 0.45, 0.61, 0.76 and 1.46 s. Parts with features smaller than an
// element (about a 22nd of the part) need --elements.
void choose_element_counts(Index n_marks, double len1, double len2, int& n1, int& n2) {
  constexpr double kDense = 1e4;
  const double n = std::clamp(static_cast<double>(n_marks), 1.0, kDense);
  const double total = std::max(1.0, n / (9.0 * std::pow(std::max(1.0, n / 441.0), 0.27)));
  n1 = std::max(1, static_cast<int>(std::lround(std::sqrt(total * len1 / len2))));
  n2 = std::max(1, static_cast<int>(std::lround(total / n1)));
  n1 = std::min(n1, 300);
  n2 = std::min(n2, 300);
}

// Median of |r| over sigma for Gaussian residuals with `dims` components: the
// undeformed residuals are distances along the normal (projection absorbs the
// in-plane noise into xi), the deformed ones 3-D vectors at fixed xi.
double median_over_sigma(int dims) { return dims == 1 ? 0.6745 : 1.5382; }

// Marks whose residual exceeds max(k * robust sigma, floor) and at least half the
// largest such residual (the worst ones of this round). Robust sigma: the median
// residual / median_over_sigma(dims).
double outlier_threshold(const VecX& residual, const VecX& weight, int dims, double k, double floor) {
  std::vector<double> r;
  for (Index i = 0; i < residual.size(); ++i)
    if (weight[i] > 0) r.push_back(residual[i]);
  return std::max(k * median(r) / median_over_sigma(dims), floor);
}

std::vector<Index> worst_outliers(const VecX& residual, const VecX& weight, int dims, double k, double floor) {
  const double threshold = outlier_threshold(residual, weight, dims, k, floor);
  double worst = 0.0;
  for (Index i = 0; i < residual.size(); ++i)
    if (weight[i] > 0 && residual[i] > threshold) worst = std::max(worst, residual[i]);
  std::vector<Index> out;
  for (Index i = 0; i < residual.size(); ++i)
    if (weight[i] > 0 && residual[i] > threshold && residual[i] >= 0.5 * worst) out.push_back(i);
  return out;
}

// Rotation of the polar decomposition F = Q U, by Newton's iteration
// Q <- (Q + Q^-T) / 2 (quadratic convergence; a handful of steps for the
// moderate stretches of a formed sheet). Nothing when F is not invertible with
// a positive determinant.
std::optional<Mat3> polar_rotation(const Mat3& f) {
  if (!f.allFinite() || !(f.determinant() > 0)) return std::nullopt;
  Mat3 q = f;
  for (int it = 0; it < 30; ++it) {
    const Mat3 next = 0.5 * (q + q.inverse().transpose());
    const double change = (next - q).lpNorm<Eigen::Infinity>();
    q = next;
    if (change < 1e-14) break;
  }
  return q;
}


// Area of a mesh's surface (4 x 4 Gauss points per element).
double surface_area(const mesh::SurfaceMesh& mesh) {
  double area = 0.0;
  const auto rule = quadrature::gauss_2d(4, 4);
  const fe::SurfaceField geo(mesh, mesh.geometry());
  for (Index e = 0; e < mesh.n_elements(); ++e)
    for (int g = 0; g < rule.size(); ++g) {
      const Mat32 t = geo.evaluate3(e, rule.points[g], basis::kFirst).dx;
      area += rule.weights[g] * t.col(0).cross(t.col(1)).norm();
    }
  return area;
}

// An automatic mesh with the marks' starting locations on it.
struct AutoMesh {
  mesh::SurfaceMesh mesh;
  std::vector<MeshLocation> loc;
  int n1 = 0, n2 = 0;
  std::string layout;
};

// Keeps the elements of `full` that hold a mark, renumbering the locations.
AutoMesh drop_empty_elements(const mesh::SurfaceMesh& full, std::vector<MeshLocation> loc) {
  std::vector<bool> keep(static_cast<std::size_t>(full.n_elements()), false);
  for (const MeshLocation& l : loc) keep[static_cast<std::size_t>(l.element)] = true;
  std::vector<Index> emap;
  AutoMesh out;
  out.mesh = mesh::extract_elements(full, keep, &emap);
  for (MeshLocation& l : loc) l.element = emap[l.element];
  out.loc = std::move(loc);
  return out;
}

// Structured rectangle over the marks' bounding box in the plane (st: in-plane
// coordinates of the marks), n1 x n2 elements (0: from the number of marks).
AutoMesh rectangle_layout(const Eigen::MatrixX2d& st, const PlaneFrame& frame, int n1, int n2) {
  const Eigen::Vector2d lo = st.colwise().minCoeff(), hi = st.colwise().maxCoeff();
  const double margin = 1e-6 * (hi - lo).maxCoeff();
  const Eigen::Vector2d lo_m = lo.array() - margin, len = (hi - lo).array() + 2 * margin;
  if (n1 == 0 || n2 == 0) choose_element_counts(st.rows(), len[0], len[1], n1, n2);
  const Vec3 origin = frame.centroid + lo_m[0] * frame.a1 + lo_m[1] * frame.a2;
  const mesh::SurfaceMesh full = mesh::make_rectangle_mesh(origin, frame.a1, frame.a2, len[0], len[1], n1, n2);
  std::vector<MeshLocation> loc(static_cast<std::size_t>(st.rows()));
  for (Index k = 0; k < st.rows(); ++k) {
    const double u = (st(k, 0) - lo_m[0]) / len[0] * n1, v = (st(k, 1) - lo_m[1]) / len[1] * n2;
    const int i = std::clamp(static_cast<int>(std::floor(u)), 0, n1 - 1);
    const int j = std::clamp(static_cast<int>(std::floor(v)), 0, n2 - 1);
    loc[k] = {static_cast<Index>(j) * n1 + i, Vec2(std::clamp(u - i, 0.0, 1.0), std::clamp(v - j, 0.0, 1.0))};
  }
  AutoMesh out = drop_empty_elements(full, std::move(loc));
  out.n1 = n1;
  out.n2 = n2;
  out.layout = std::to_string(n1) + "x" + std::to_string(n2);
  return out;
}

}  // namespace

void AnalyseOptions::validate() const {
  if (elements1 < 0 || elements2 < 0) throw UsageError("--elements: expected NxM with positive counts");
  for (const auto* v : {&alpha, &beta, &gamma, &delta})
    if (*v && !(**v >= 0.0)) throw UsageError("--alpha/--beta/--gamma: smoothing weights must be >= 0");
  if (!(smoothing_scale > 0.0)) throw UsageError("--smoothing-scale: must be > 0");
  if (!(outlier_sigma > 0.0)) throw UsageError("--outlier-sigma: must be > 0");
  if (sample < 0 || sample > 50) throw UsageError("--sample: expected 0..50 points per element side");
  if (fibre_angles.size() == 1 || fibre_angles.size() > 2)
    throw UsageError("--fibres: expected two angles in degrees, e.g. --fibres 0,90");
}

AnalysisResult analyse(const GridData& grid, const AnalyseOptions& options) {
  options.validate();
  if (options.method == Method::kTriangles) return analyse_triangles(grid, options);
  AnalysisResult res;
  res.method = Method::kSurface;
  res.penalty_kind = options.penalty;
  const Index n = grid.n_points();
  res.points.resize(n);

  // --- Marks usable for the undeformed fit.
  std::vector<Index> used;
  for (Index p = 0; p < n; ++p) {
    if (grid.has_undeformed(p))
      used.push_back(p);
    else
      res.points[p].status = kStatusMissingUndeformed;
  }
  if (used.size() < 6)
    throw InputError(grid.sources.front() + ": only " + std::to_string(used.size()) +
                     " points have an undeformed position; at least 6 are needed for a surface fit");
  const Index m = static_cast<Index>(used.size());
  Points3 X(m, 3);
  for (Index k = 0; k < m; ++k) X.row(k) = grid.undeformed.row(used[k]);

  // --- Frame and automatic mesh.
  auto t0 = Clock::now();
  const PlaneFrame frame = best_fit_plane(X);
  if (!(frame.spread2 > 1e-6 * frame.spread1))
    throw InputError(grid.sources.front() +
                     ": the undeformed points lie on a line (or coincide); a surface cannot be fitted");
  Eigen::MatrixX2d st(m, 2);
  for (Index k = 0; k < m; ++k) {
    const Vec3 d = X.row(k).transpose() - frame.centroid;
    st(k, 0) = d.dot(frame.a1);
    st(k, 1) = d.dot(frame.a2);
  }
  res.centroid = frame.centroid;
  res.axis1 = frame.a1;
  res.axis2 = frame.a2;
  std::vector<MeshLocation> loc(m);
  if (!options.mesh_file.empty()) {
    // The user's mesh: marks located by projection onto it.
    res.mesh = read_mesh_file(options.mesh_file);
    res.mesh_layout = "from " + options.mesh_file;
    const mesh::SurfaceProjector projector(res.mesh, res.mesh.geometry());
    const std::vector<mesh::Projection> proj = projector.project_all(X);
    for (Index k = 0; k < m; ++k) {
      if (!proj[k].ok())
        throw InputError(grid.where[used[k]] + ": mark '" + grid.ids[used[k]] + "' could not be located on the mesh " +
                         options.mesh_file);
      loc[k] = {proj[k].element, proj[k].xi};
    }
  } else {
    AutoMesh am = rectangle_layout(st, frame, options.elements1, options.elements2);
    res.mesh = std::move(am.mesh);
    loc = std::move(am.loc);
    res.elements1 = am.n1;
    res.elements2 = am.n2;
    res.mesh_layout = am.layout;
  }
  res.mark_spacing = std::sqrt(surface_area(res.mesh) / static_cast<double>(m));
  const mesh::SurfaceMesh& mesh = res.mesh;
  const PenaltyMatrices penalties = assemble_penalties(mesh);
  res.times.mesh = seconds_since(t0);
  cli::status(options.quiet, "gsa: mesh " + res.mesh_layout + " (" + std::to_string(mesh.n_elements()) +
                                 " elements); fitting the undeformed surface");

  // --- Smoothing weights. Automatic: from the estimated noise (see docs/theory/strain.md).
  const double d = res.mark_spacing;
  auto penalty_for_noise = [&](double sigma) {
    Penalty p;
    const double ratio = std::max(sigma / d, 1e-6);
    if (options.penalty == PenaltyKind::kJumps) {
      p.delta = options.smoothing_scale * kAutoDelta * std::pow(d, 6) * std::pow(ratio, 1.0) + 1e-8 * std::pow(d, 6);
      p.gamma = kJumpsGammaFloor * std::pow(d, 4);
    } else if (options.penalty == PenaltyKind::kThirdOrder) {
      p.gamma = options.smoothing_scale * kAutoGamma * std::pow(d, 4) * std::pow(ratio, 1.2) + 1e-8 * std::pow(d, 4);
      p.beta = 0.0;
    } else {
      p.beta = options.smoothing_scale * kAutoBeta * std::pow(d, 2) * ratio + 1e-8 * d * d;
    }
    return p;
  };
  auto explicit_penalty = [&](Penalty p) {
    if (options.alpha) p.alpha = *options.alpha;
    if (options.beta) p.beta = *options.beta;
    if (options.gamma) p.gamma = *options.gamma;
    if (options.delta) p.delta = *options.delta;
    return p;
  };
  const bool automatic = !options.alpha && !options.beta && !options.gamma && !options.delta;
  res.smoothing_automatic = automatic;

  // --- Undeformed fit alternating with projection; outliers flagged.
  VecX w_u = VecX::Ones(m);
  FitResult fit_u;
  Penalty pen_u = automatic ? penalty_for_noise(0.0) : explicit_penalty(Penalty{});
  double fit_time = 0.0, project_time = 0.0;
  bool searched = false;  // a global projection has been done
  for (int outer = 0; outer < 8; ++outer) {
    // The first round only estimates the noise: one projection is enough there.
    const int iterations = (automatic && outer == 0) ? 1 : std::max(1, options.max_projection_iterations);
    for (int it = 0; it < iterations; ++it) {
      auto tf = Clock::now();
      FitSystem system(mesh, penalties, loc, w_u);
      system.set_values(X);
      fit_u = system.solve(pen_u, mesh.geometry());
      fit_time += seconds_since(tf);
      if (!fit_u.ok) throw InputError(grid.sources.front() + ": " + fit_u.message);
      res.projection_iterations = it + 1;
      auto tp = Clock::now();
      // The first projection searches the whole surface; later ones start from
      // each mark's last location (the surface moves little between fits).
      const mesh::SurfaceProjector projector(mesh, fit_u.parameters);
      std::vector<mesh::Projection> proj;
      if (searched) {
        std::vector<Index> elements(static_cast<std::size_t>(m));
        std::vector<Vec2> xi(static_cast<std::size_t>(m));
        for (Index k = 0; k < m; ++k) elements[k] = loc[k].element, xi[k] = loc[k].xi;
        proj = projector.refine_all(X, elements, xi);
      } else {
        proj = projector.project_all(X);
        searched = true;
      }
      double max_dxi = 0.0;
      for (Index k = 0; k < m; ++k) {
        if (!proj[k].ok()) continue;
        if (proj[k].element == loc[k].element) max_dxi = std::max(max_dxi, (proj[k].xi - loc[k].xi).norm());
        else max_dxi = 1.0;
        loc[k] = {proj[k].element, proj[k].xi};
      }
      project_time += seconds_since(tp);
      if (max_dxi < kXiSettled) break;  // xi settled
    }
    // Outliers of the undeformed fit (worst first; see the deformed fit).
    bool changed = false;
    for (Index k : worst_outliers(fit_u.residual, w_u, 1, options.outlier_sigma, 0.02 * d)) {
      w_u[k] = 0.0;
      changed = true;
    }
    if (automatic) {
      // Noise estimate from the light fit, corrected for the fitted degrees of freedom.
      const double n_used = w_u.sum();
      const double dofs = static_cast<double>(mesh.n_dofs());
      double rss = 0.0;
      for (Index k = 0; k < m; ++k)
        if (w_u[k] > 0) rss += fit_u.residual[k] * fit_u.residual[k];
      if (outer == 0 && n_used > 1.2 * dofs) {
        res.noise_estimate = std::sqrt(rss / (n_used - dofs));  // normal residuals: one component
        pen_u = penalty_for_noise(res.noise_estimate);
        changed = true;
      }
    }
    if (!changed) break;
  }
  for (Index k = 0; k < m; ++k)
    if (w_u[k] <= 0) res.points[used[k]].status = kStatusOutlierUndeformed;
  res.undeformed_parameters = fit_u.parameters;
  res.rms_undeformed = fit_u.rms;
  res.max_undeformed = fit_u.max;
  res.penalty_undeformed = pen_u;

  // --- Deformed fit on the same xi, smoothing the displacement.
  Points3 x(m, 3);
  VecX w_d = VecX::Zero(m);
  for (Index k = 0; k < m; ++k) {
    const Index p = used[k];
    x.row(k) = grid.deformed.row(p);
    if (w_u[k] > 0 && grid.has_deformed(p)) w_d[k] = 1.0;
    if (!grid.has_deformed(p) && w_u[k] > 0) res.points[p].status = kStatusMissingDeformed;
  }
  if (w_d.sum() < 6)
    throw InputError(grid.sources.front() + ": only " + std::to_string(static_cast<long>(w_d.sum())) +
                     " points have both positions; at least 6 are needed");
  cli::status(options.quiet, "gsa: fitting the deformed surface");
  Penalty pen_d = automatic ? penalty_for_noise(res.noise_estimate) : explicit_penalty(Penalty{});
  res.penalty_deformed = pen_d;
  auto tf = Clock::now();
  // The smoothing acts on the deviation of the deformed surface from the undeformed
  // one moved rigidly (best fit of the marks): a rigid motion of the deformed scan
  // then moves the fitted surface with it, exactly.
  res.rigid = best_rigid_motion(X, x, w_d);
  MatX reference = res.undeformed_parameters * res.rigid.rotation.transpose();
  for (Index node = 0; node < mesh.n_nodes(); ++node)
    reference.row(mesh::SurfaceMesh::dof(node, mesh::kValue)) += res.rigid.translation.transpose();
  // Each mark's undeformed residual r = X - X^(xi) (the undeformed fit's denoising)
  // is carried to the deformed state with the mark: the deformed data are x - Q r,
  // Q the local rotation of the fitted deformation. A mark off the undeformed
  // surface by r sits off the deformed one by Q r when the part moves rigidly, so
  // rigid motion of a curved part gives zero strain; with independent noise the
  // correction is along the deformed normal, where it does not affect strains.
  const fe::SurfaceField fu(mesh, res.undeformed_parameters);
  std::vector<Vec3> r_u(static_cast<std::size_t>(m), Vec3::Zero());
  std::vector<Mat3> frame_u(static_cast<std::size_t>(m), Mat3::Identity());  // [X,1 X,2 N]
  for (Index k = 0; k < m; ++k) {
    if (!(w_d[k] > 0)) continue;
    const fe::SurfacePoint pu = fu.evaluate3(loc[k].element, loc[k].xi, basis::kValues | basis::kFirst);
    r_u[k] = X.row(k).transpose() - pu.x;
    frame_u[k] << pu.dx, pu.dx.col(0).cross(pu.dx.col(1)).normalized();
  }
  Points3 xt(m, 3);
  // One system per set of weights: rebuilt only when marks are flagged or readmitted.
  std::unique_ptr<FitSystem> system;
  int passes = 1;  // of the deformed fit: kAutoFitPasses once the smoothing is chosen by GCV
  auto transport = [&](const MatX* deformed) {
    std::optional<fe::SurfaceField> fd;
    if (deformed) fd.emplace(mesh, *deformed);
    for (Index k = 0; k < m; ++k) {
      Mat3 q = res.rigid.rotation;
      if (fd && w_d[k] > 0) {
        const fe::SurfacePoint pd = fd->evaluate3(loc[k].element, loc[k].xi, basis::kValues | basis::kFirst);
        Mat3 frame_d;
        frame_d << pd.dx, pd.dx.col(0).cross(pd.dx.col(1)).normalized();
        const std::optional<Mat3> polar = polar_rotation(frame_d * frame_u[k].inverse());
        if (polar) q = *polar;
      }
      xt.row(k) = x.row(k) - (q * r_u[k]).transpose();
    }
    if (system) system->set_values(xt);
  };
  auto refit = [&](bool weights_changed) {
    if (weights_changed) {
      system = std::make_unique<FitSystem>(mesh, penalties, loc, w_d);
      system->set_values(xt);
    }
    FitResult f = system->solve(pen_d, reference, 0, passes);
    if (!f.ok) throw InputError(grid.sources.front() + ": " + f.message);
    return f;
  };
  transport(nullptr);
  FitResult fit_d = refit(true);
  transport(&fit_d.parameters);
  fit_d = refit(false);
  // Outliers: flag the worst marks beyond the threshold and refit, a few rounds
  // (one bad mark drags its neighbours' residuals up until it is removed).
  for (int round = 0; round < 8; ++round) {
    const std::vector<Index> bad = worst_outliers(fit_d.residual, w_d, 3, options.outlier_sigma, 0.02 * d);
    if (bad.empty()) break;
    for (Index k : bad) {
      w_d[k] = 0.0;
      res.points[used[k]].status = kStatusOutlierDeformed;
    }
    fit_d = refit(true);
  }
  if (automatic && options.penalty == PenaltyKind::kJumps) {
    // Smoothing by generalised cross-validation on the deformed positions, then
    // scaled up: GCV balances position errors, and strains (derivatives) want
    // more smoothing (docs/theory/strain.md). Search on log10(delta / d^6) in
    // [-6, 6], two candidates at a time (solved in parallel): the bracket keeps
    // the best point in its middle and halves each round.
    cli::status(options.quiet, "gsa: choosing the smoothing by cross-validation");
    const double n_used = w_d.sum();
    // Hutchinson probes: the trace estimate's relative error falls as 1/sqrt(probes * N),
    // so large grids need fewer probes for the same GCV curve.
    const int probes = n_used > 20000 ? 6 : 12;
    const double tolerance = n_used > 20000 ? 0.3 : 0.2;
    auto penalty_at = [&](double log_delta) {
      Penalty p;
      p.gamma = kJumpsGammaFloor * std::pow(d, 4);
      p.delta = std::pow(10.0, log_delta) * std::pow(d, 6);
      return p;
    };
    auto gcv = [&](const FitResult& f) {
      if (!f.ok || !(f.edf < 0.95 * n_used)) return std::numeric_limits<double>::infinity();
      double rss = 0.0;
      for (Index k = 0; k < m; ++k)
        if (w_d[k] > 0) rss += f.residual[k] * f.residual[k];
      const double a = 1.0 - f.edf / n_used;
      return rss / (3.0 * n_used) / (a * a);
    };
    auto gcv_pair = [&](double a, double b) {
      const std::array<FitResult, 2> f =
          system->solve_pair({penalty_at(a), penalty_at(b)}, reference, probes, kAutoFitPasses);
      return std::array<double, 2>{gcv(f[0]), gcv(f[1])};
    };
    double left = -6.0, right = 6.0, best = -2.0;
    const std::array<double, 2> g0 = gcv_pair(-2.0, 2.0);
    double g_best = g0[0];
    if (g0[0] <= g0[1]) {
      right = 2.0;
    } else {
      left = -2.0, best = 2.0, g_best = g0[1];
    }
    while (right - left > tolerance) {
      const double p1 = 0.5 * (left + best), p2 = 0.5 * (best + right);
      const std::array<double, 2> g = gcv_pair(p1, p2);
      if (g[0] < g_best && g[0] <= g[1]) {
        right = best, best = p1, g_best = g[0];
      } else if (g[1] < g_best) {
        left = best, best = p2, g_best = g[1];
      } else {
        left = p1, right = p2;
      }
    }
    res.gcv_log10_delta = best;
    pen_d = Penalty{};
    pen_d.gamma = kJumpsGammaFloor * std::pow(d, 4);
    pen_d.delta = options.smoothing_scale * kGcvStrainFactor * std::pow(10.0, res.gcv_log10_delta) * std::pow(d, 6);
    res.penalty_deformed = pen_d;
    passes = kAutoFitPasses;
    fit_d = refit(false);
    transport(&fit_d.parameters);
    fit_d = refit(false);
  }
  {
    // Readmit flagged marks that the final surface fits well (good neighbours of a
    // bad mark can exceed the threshold while the bad mark still pulls the fit).
    const double threshold = outlier_threshold(fit_d.residual, w_d, 3, options.outlier_sigma, 0.02 * d);
    bool readmitted = false;
    for (Index k = 0; k < m; ++k)
      if (res.points[used[k]].status == kStatusOutlierDeformed && fit_d.residual[k] < threshold) {
        w_d[k] = 1.0;
        res.points[used[k]].status = kStatusOk;
        readmitted = true;
      }
    if (readmitted) fit_d = refit(true);
  }
  fit_time += seconds_since(tf);
  res.deformed_parameters = fit_d.parameters;
  // Reported residuals: distance of each deformed mark as digitised (not the
  // transported data) from the fitted surface at its material point.
  const VecX residual_d = (fit_d.fitted - MatX(x)).rowwise().norm();
  {
    double sum = 0.0, count = 0.0;
    for (Index k = 0; k < m; ++k)
      if (w_d[k] > 0) {
        sum += residual_d[k] * residual_d[k];
        count += 1.0;
        res.max_deformed = std::max(res.max_deformed, residual_d[k]);
      }
    res.rms_deformed = count > 0 ? std::sqrt(sum / count) : 0.0;
  }
  res.times.fit = fit_time;
  res.times.project = project_time;
  const double rho = 1.0 / (d * d);
  // Effective smoothing length of the strongest term actually used.
  res.gauge_length = std::max({std::pow(std::max(pen_d.gamma, 0.0) / rho, 1.0 / 6.0),
                               std::pow(std::max(pen_d.beta, 0.0) / rho, 0.25),
                               std::pow(std::max(pen_d.delta, 0.0) / rho, 0.125)});

  // --- Strains at the marks.
  auto ts = Clock::now();
  const fe::SurfaceField fd(mesh, res.deformed_parameters);
  for (Index k = 0; k < m; ++k) {
    PointResult& pr = res.points[used[k]];
    pr.element = loc[k].element;
    pr.xi = loc[k].xi;
    pr.residual_undeformed = fit_u.residual[k];
    if (pr.status != kStatusOk) continue;
    pr.residual = residual_d[k];
    const auto b = basis::BicubicHermite::evaluate(loc[k].xi, basis::kValues | basis::kFirst);
    const fe::SurfacePoint pu = fu.evaluate3(loc[k].element, b), pd = fd.evaluate3(loc[k].element, b);
    pr.strain = surface_strain(pu.dx, pd.dx);
    if (!pr.strain) {
      pr.status = kStatusDegenerate;
      continue;
    }
    if (options.fibre_angles.size() == 2) {
      const FibrePair fp = fibre_pair(pu.dx, pd.dx, options.fibre_angles[0], options.fibre_angles[1]);
      for (const auto& fs : fp.state)
        pr.fibres.push_back(fs ? FibreResult{fs->direction_deformed, fs->stretch} : FibreResult{});
      pr.shear_angle_deg = fp.shear_angle_deg;
    }
  }
  res.times.strain = seconds_since(ts);
  return res;
}

}  // namespace sf::gsa

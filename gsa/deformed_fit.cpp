#include "gsa/deformed_fit.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <optional>
#include <string>

#include "common/core/error.hpp"
#include "common/core/parallel.hpp"
#include "common/fe/surface_field.hpp"

namespace sf::gsa {

namespace {

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

}  // namespace

DeformedMarks deformed_marks(const GridData& grid, const FitMarks& marks, const UndeformedFit& undeformed,
                             const VecX& weight) {
  const Index m = marks.size();
  DeformedMarks out;
  out.position.resize(m, 3);
  out.weight = VecX::Zero(m);
  for (Index k = 0; k < m; ++k) {
    const Index p = marks.point[static_cast<std::size_t>(k)];
    out.position.row(k) = grid.deformed.row(p);
    if (undeformed.weight[k] > 0 && grid.has_deformed(p)) out.weight[k] = weight.size() == m ? weight[k] : 1.0;
  }
  const auto both = (out.weight.array() > 0).count();
  if (both < 6)
    throw InputError((grid.sources.empty() ? marks.source : grid.sources.back()) + ": only " + std::to_string(both) +
                     " points have both positions; at least 6 are needed");
  return out;
}

DeformedProblem::DeformedProblem(const FrameAndMesh& setup, const FitMarks& marks, const UndeformedFit& undeformed,
                                 const DeformedMarks& deformed)
    : setup_(setup), marks_(marks), undeformed_(undeformed), deformed_(deformed), weight_(deformed.weight) {
  const mesh::SurfaceMesh& mesh = setup.mesh;
  const Index m = marks.size();
  // The smoothing acts on the deviation from the undeformed surface moved rigidly (best
  // fit of the marks).
  rigid_ = best_rigid_motion(marks.undeformed, deformed.position, weight_);
  reference_ = undeformed.parameters * rigid_.rotation.transpose();
  for (Index node = 0; node < mesh.n_nodes(); ++node)
    reference_.row(mesh::SurfaceMesh::dof(node, mesh::kValue)) += rigid_.translation.transpose();
  // Each mark's undeformed residual and tangent frame, to be carried to the deformed state.
  const fe::SurfaceField fu(mesh, undeformed.parameters);
  residual_u_.assign(static_cast<std::size_t>(m), Vec3::Zero());
  frame_u_.assign(static_cast<std::size_t>(m), Mat3::Identity());
  for (Index k = 0; k < m; ++k) {
    if (!(weight_[k] > 0)) continue;
    const MeshLocation& loc = undeformed.location[static_cast<std::size_t>(k)];
    const fe::SurfacePoint pu = fu.evaluate3(loc.element, loc.xi, basis::kValues | basis::kFirst);
    residual_u_[k] = marks.undeformed.row(k).transpose() - pu.x;
    frame_u_[k] << pu.dx, pu.dx.col(0).cross(pu.dx.col(1)).normalized();
  }
  data_.resize(m, 3);
}

DeformedProblem::~DeformedProblem() = default;

void DeformedProblem::carry_residuals(const MatX* deformed) {
  std::optional<fe::SurfaceField> fd;
  if (deformed) fd.emplace(setup_.mesh, *deformed);
  // The marks on all cores: each row is its own (the same bits whatever the threads).
  parallel_for(
      marks_.size(),
      [&](Index k) {
        Mat3 q = rigid_.rotation;
        if (fd && weight_[k] > 0) {
          const MeshLocation& loc = undeformed_.location[static_cast<std::size_t>(k)];
          const fe::SurfacePoint pd = fd->evaluate3(loc.element, loc.xi, basis::kValues | basis::kFirst);
          Mat3 frame_d;
          frame_d << pd.dx, pd.dx.col(0).cross(pd.dx.col(1)).normalized();
          const std::optional<Mat3> polar = polar_rotation(frame_d * frame_u_[k].inverse());
          if (polar) q = *polar;
        }
        data_.row(k) = deformed_.position.row(k) - (q * residual_u_[k]).transpose();
      },
      2048);
  if (system_) system_->set_values(data_);
}

void DeformedProblem::set_weight(Index k, double weight) {
  weight_[k] = weight;
  rebuild_ = true;
}

FitSystem& DeformedProblem::system() {
  // One system per set of weights: rebuilt only when marks are flagged or readmitted.
  if (rebuild_ || !system_) {
    system_ = std::make_unique<FitSystem>(setup_.mesh, relaxed_ ? *relaxed_ : setup_.penalties, undeformed_.location,
                                          weight_);
    system_->set_values(data_);
    if (probes_.size() > 0) system_->set_probes(probes_);
    rebuild_ = false;
  }
  return *system_;
}

MatX DeformedProblem::smooth(const MatX& values, const Penalty& penalty, int passes) {
  FitSystem& s = system();
  s.set_values(values);
  const FitResult f = s.solve(penalty, MatX::Zero(setup_.mesh.n_dofs(), values.cols()), 0, passes);
  s.set_values(data_);
  if (!f.ok) throw InputError(marks_.source + ": " + f.message);
  return f.fitted;
}

MatX DeformedProblem::smoothing_residual(const MatX& values, const Penalty& penalty, int passes) {
  std::optional<MatX> out = system().smoothing_residual(values, penalty, passes);
  if (!out) throw InputError(marks_.source + ": surface fit: the smoothed least-squares system is singular");
  return std::move(*out);
}

MatX DeformedProblem::weighted_values(const MatX& values) { return system().weighted_values(values); }

MatX DeformedProblem::smoothing_residual(const MatX& values, const MatX& weighted, const Penalty& penalty, int passes,
                                         int slot) {
  std::optional<MatX> out = system().smoothing_residual(values, weighted, penalty, passes, slot);
  if (!out) throw InputError(marks_.source + ": surface fit: the smoothed least-squares system is singular");
  return std::move(*out);
}

void DeformedProblem::set_probes(MatX probes) {
  probes_ = std::move(probes);
  if (system_) system_->set_probes(probes_);
}

void DeformedProblem::set_element_multipliers(std::vector<double> multipliers) {
  multipliers_ = std::move(multipliers);
  const bool uniform = std::all_of(multipliers_.begin(), multipliers_.end(), [](double v) { return v == 1.0; });
  if (uniform)
    relaxed_.reset();
  else
    relaxed_ = std::make_unique<PenaltyMatrices>(assemble_penalties(setup_.mesh, multipliers_));
  rebuild_ = true;
}

FitResult DeformedProblem::fit(const Penalty& penalty, int passes, int slot) {
  FitResult f = system().solve(penalty, reference_, 0, passes, slot);
  if (!f.ok) throw InputError(marks_.source + ": " + f.message);
  return f;
}

std::array<FitResult, 2> DeformedProblem::fit_pair(const std::array<Penalty, 2>& penalties, int trace_probes,
                                                   int passes) {
  return system().solve_pair(penalties, reference_, trace_probes, passes);
}

DeformedFit fit_deformed(DeformedProblem& problem, const Penalty& penalty, std::vector<OutlierFlag> flags) {
  DeformedFit out;
  out.penalty = penalty;
  out.passes = 1;
  out.flags = std::move(flags);
  for (const OutlierFlag& f : out.flags) problem.set_weight(f.mark, 0.0);
  problem.carry_residuals(nullptr);
  out.fit = problem.fit(penalty, out.passes);
  problem.carry_residuals(&out.fit.parameters);
  out.fit = problem.fit(penalty, out.passes);
  return out;
}

void refit_deformed(DeformedProblem& problem, DeformedFit& fit, const SmoothingChoice& choice) {
  fit.penalty = choice.penalty;
  fit.passes = choice.passes;
  fit.fit = problem.fit(fit.penalty, fit.passes);
  problem.carry_residuals(&fit.fit.parameters);
  fit.fit = problem.fit(fit.penalty, fit.passes);
}

void readmit_deformed(DeformedProblem& problem, DeformedFit& fit) {
  // Distance of each flagged mark as digitised from the surface at its material point.
  const VecX residual = (fit.fit.fitted - MatX(problem.position())).rowwise().norm();
  const std::vector<OutlierFlag> back = take_readmitted(fit.flags, residual);
  for (const OutlierFlag& f : back) problem.set_weight(f.mark, problem.base_weight(f.mark));
  if (!back.empty()) fit.fit = problem.fit(fit.penalty, fit.passes);
}

DeformedResiduals deformed_residuals(const DeformedProblem& problem, const DeformedFit& fit) {
  DeformedResiduals out;
  // Distance of each deformed mark as digitised (not the carried data) from the fitted
  // surface at its material point.
  out.residual = (fit.fit.fitted - MatX(problem.position())).rowwise().norm();
  double sum = 0.0, count = 0.0;
  const VecX& w = problem.weight();
  for (Index k = 0; k < w.size(); ++k)
    if (w[k] > 0) {
      sum += out.residual[k] * out.residual[k];
      count += 1.0;
      out.max = std::max(out.max, out.residual[k]);
    }
  out.rms = count > 0 ? std::sqrt(sum / count) : 0.0;
  return out;
}

}  // namespace sf::gsa

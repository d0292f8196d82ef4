#include "forming/solve/static_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"
#include "forming/solve/line_search.hpp"
#include "forming/solve/messages.hpp"

namespace sf::forming {
namespace {

[[noreturn]] void bad_option(const std::string& name, const std::string& expected, double found) {
  detail::bad_solver_option("static solver", name, expected, found);
}

// Relative size of the last Newton correction below which the state is converged even
// when the residual test is not met (round-off floor of the residual).
constexpr double kIncrementTolRel = 1e-14;

}  // namespace

// ---------------------------------------------------------------------------------
// Model

Model::Model(ElementRule rule) : rule_(rule), brick_rule_(rule.brick()) {}

int Model::add_ply(PlyMesh ply, std::shared_ptr<const Material> material, const ConstraintTerms& constraints) {
  if (!material) throw InputError("model: ply added without a material");
  constraints.validate();
  if (constraints.inextensible && material->fibre_direction().isZero(0.0))
    throw InputError("model: fibre inextensibility asked for a material without fibres (" + material->name() + ")");
  const Index n = ply.n_dofs();
  const Index ne = ply.n_elements();
  Body b{std::move(ply), std::move(material), n_dofs_, constraints, {}, {}};
  if (constraints.active()) {
    b.p.assign(static_cast<std::size_t>(ne), constraints.p);
    b.T.assign(static_cast<std::size_t>(ne), constraints.T);
  }
  bodies_.push_back(std::move(b));
  n_dofs_ += n;
  return n_bodies() - 1;
}

void Model::set_multipliers(int body, std::vector<double> p, std::vector<double> T) {
  Body& b = bodies_.at(static_cast<std::size_t>(body));
  SF_ASSERT(static_cast<Index>(p.size()) == b.ply.n_elements() && static_cast<Index>(T.size()) == b.ply.n_elements(),
            "one multiplier per element");
  b.p = std::move(p);
  b.T = std::move(T);
}

ConstraintTerms Model::element_constraints(const Body& b, Index e) const {
  ConstraintTerms c = b.constraints;
  if (c.active()) {
    c.p = b.p[static_cast<std::size_t>(e)];
    c.T = b.T[static_cast<std::size_t>(e)];
  }
  return c;
}

std::vector<Model::ConstraintState> Model::constraint_state(int body, const Eigen::Ref<const VecX>& x) const {
  const Body& b = bodies_.at(static_cast<std::size_t>(body));
  std::vector<ConstraintState> out;
  if (!b.constraints.active()) return out;
  const MatX xb = PlyMesh::unflatten(x.segment(b.offset, b.ply.n_dofs()));
  for (Index e = 0; e < b.ply.n_elements(); ++e) {
    const ElementResult r = brick_element(b.ply.element_parameters(e, b.ply.reference()), b.ply.element_parameters(e, xb),
                                          *b.material, brick_rule_, false, element_constraints(b, e));
    out.push_back({r.g_J, r.g_T, r.p_eff, r.T_eff, r.volume});
  }
  return out;
}

VecX Model::reference_positions() const {
  VecX x(n_dofs_);
  for (const Body& b : bodies_) x.segment(b.offset, b.ply.n_dofs()) = b.ply.reference_dofs();
  return x;
}

std::vector<bool> Model::used_dofs() const {
  std::vector<bool> used(n_dofs_, false);
  for (const Body& b : bodies_)
    for (Index e = 0; e < b.ply.n_elements(); ++e) {
      const BrickMap map = b.ply.element_map(e);
      for (int k = 0; k < kBrickFunctions; ++k)
        for (int t = 0; t < map.n_terms[k]; ++t)
          if (map.terms[k][t].coef != 0.0)
            for (int i = 0; i < 3; ++i) used[b.offset + 3 * map.terms[k][t].dof + i] = true;
    }
  return used;
}

Model::ElementDofs Model::element_dofs(int body, Index e) const {
  const Body& b = bodies_[body];
  const BrickMap map = b.ply.element_map(e);
  ElementDofs out;
  for (int k = 0; k < kBrickFunctions; ++k)
    for (int t = 0; t < map.n_terms[k]; ++t)
      for (int i = 0; i < 3; ++i) {
        out.dofs.push_back(b.offset + 3 * map.terms[k][t].dof + i);
        out.coefs.push_back(map.terms[k][t].coef);
        out.local.push_back(3 * k + i);
      }
  return out;
}

Assembly Model::assemble(const Eigen::Ref<const VecX>& x, bool want_tangent) const {
  SF_ASSERT(x.size() == n_dofs_, "positions must have n_dofs entries");
  Assembly out;
  out.force = VecX::Zero(n_dofs_);
  linalg::TripletAssembler triplets(n_dofs_, n_dofs_);
  if (want_tangent) {
    Index n_el = 0;
    for (const Body& b : bodies_) n_el += b.ply.n_elements();
    triplets.reserve(n_el * kBrickDofs * kBrickDofs);
  }
  MatX block;
  for (int body = 0; body < n_bodies(); ++body) {
    const Body& b = bodies_[body];
    const MatX xb = PlyMesh::unflatten(x.segment(b.offset, b.ply.n_dofs()));
    for (Index e = 0; e < b.ply.n_elements(); ++e) {
      const BrickParams X_e = b.ply.element_parameters(e, b.ply.reference());
      const BrickParams x_e = b.ply.element_parameters(e, xb);
      const ElementResult r = brick_element(X_e, x_e, *b.material, brick_rule_, want_tangent, element_constraints(b, e));
      if (!r.ok()) {
        out.ok = false;
        out.message = "body " + std::to_string(body) + " element " + std::to_string(e) + ": " +
                      to_string(r.status) + " (min det F " + detail::short_number(r.min_det_f) + ")";
        out.energy = std::numeric_limits<double>::infinity();
        return out;
      }
      out.energy += r.energy;
      // Expanded local -> global list: one entry per (function, map term, coordinate);
      // duplicates (collapsed elements) are summed by the assembler.
      const ElementDofs ed = element_dofs(body, e);
      const std::vector<Index>& dofs = ed.dofs;
      const std::vector<double>& coefs = ed.coefs;
      const std::vector<int>& local = ed.local;
      const int m = static_cast<int>(dofs.size());
      for (int a = 0; a < m; ++a) out.force(dofs[a]) += coefs[a] * r.force(local[a]);
      if (!want_tangent) continue;
      block.resize(m, m);
      for (int c = 0; c < m; ++c)
        for (int a = 0; a < m; ++a) block(a, c) = coefs[a] * coefs[c] * r.tangent(local[a], local[c]);
      triplets.add_block(dofs, dofs, block);
    }
  }
  if (want_tangent) out.tangent = triplets.compress();
  return out;
}

std::vector<Mat3> Model::deformation_gradients(int body, const Eigen::Ref<const VecX>& x) const {
  const Body& b = bodies_[body];
  const MatX xb = PlyMesh::unflatten(x.segment(b.offset, b.ply.n_dofs()));
  std::vector<Mat3> out;
  for (Index e = 0; e < b.ply.n_elements(); ++e) {
    const std::vector<Mat3> f = brick_deformation_gradients(b.ply.element_parameters(e, b.ply.reference()),
                                                            b.ply.element_parameters(e, xb), brick_rule_);
    out.insert(out.end(), f.begin(), f.end());
  }
  return out;
}

// ---------------------------------------------------------------------------------
// Options and report

void StaticOptions::validate() const {
  if (!(initial_increment > 0.0 && initial_increment <= 1.0))
    bad_option("initial_increment", "a load-factor increment in (0, 1]", initial_increment);
  if (!(max_increment > 0.0 && max_increment <= 1.0))
    bad_option("max_increment", "a load-factor increment in (0, 1]", max_increment);
  if (!(min_increment > 0.0 && min_increment <= initial_increment))
    bad_option("min_increment", "a value in (0, initial_increment]", min_increment);
  if (!(growth >= 1.0) || !std::isfinite(growth)) bad_option("growth", "a finite factor >= 1", growth);
  if (easy_iterations < 1) bad_option("easy_iterations", "at least 1", easy_iterations);
  if (max_iterations < 1) bad_option("max_iterations", "at least 1", max_iterations);
  if (max_steps < 1) bad_option("max_steps", "at least 1", max_steps);
  if (!(residual_tol_rel >= 0.0)) bad_option("residual_tol_rel", "a value >= 0", residual_tol_rel);
  if (!(residual_tol_abs >= 0.0)) bad_option("residual_tol_abs", "a value >= 0 (N)", residual_tol_abs);
  if (!(divergence_factor > 1.0)) bad_option("divergence_factor", "a factor > 1", divergence_factor);
  if (max_line_search < 0) bad_option("max_line_search", "at least 0", max_line_search);
  if (!linalg::solver_available(linear_solver))
    throw InputError("static solver linear_solver: '" + linalg::to_string(linear_solver) +
                     "' is not compiled in");
}

std::string to_string(StaticReport::Status status) {
  switch (status) {
    case StaticReport::Status::kConverged:
      return "converged";
    case StaticReport::Status::kStepFailed:
      return "step-failed";
    case StaticReport::Status::kInvalidStart:
      return "invalid-start";
  }
  return "unknown";
}

std::string StaticReport::brief() const {
  std::ostringstream os;
  os << to_string(status) << ": lambda " << load_factor << " in " << n_converged_steps << " steps ("
     << n_cutbacks << " cut-backs), " << total_iterations << " Newton iterations";
  for (auto it = steps.rbegin(); it != steps.rend(); ++it)
    if (it->converged && !it->residual_norms.empty()) {
      os << ", |r| " << detail::short_number(it->residual_norms.back());
      break;
    }
  if (!message.empty()) os << "; " << message;
  return os.str();
}

TangentSolver::TangentSolver(linalg::SolverKind kind, bool unsymmetric) {
  const bool try_cholesky = kind == linalg::SolverKind::kAuto && !unsymmetric &&
                            linalg::solver_available(linalg::SolverKind::kCholmod);
  if (try_cholesky)
    spd_ = std::make_unique<linalg::LinearSolver>(linalg::SolverKind::kCholmod,
                                                  linalg::MatrixProperty::kSymmetricPositiveDefinite);
  general_ = std::make_unique<linalg::LinearSolver>(
      kind, unsymmetric ? linalg::MatrixProperty::kUnsymmetric : linalg::MatrixProperty::kSymmetricIndefinite);
}

const linalg::SolveReport& TangentSolver::factorize(const linalg::SparseMatrix& k) {
  if (spd_ && skip_cholesky_ > 0) {
    --skip_cholesky_;
  } else if (spd_) {
    const linalg::SolveReport& r = spd_->factorize(k);
    if (r.ok()) {
      active_ = spd_.get();
      return r;
    }
    skip_cholesky_ = 4;
  }
  const linalg::SolveReport& r = general_->factorize(k);
  active_ = r.ok() ? general_.get() : nullptr;
  return r;
}

Eigen::MatrixXd TangentSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& b) const {
  SF_ASSERT(active_ != nullptr, "TangentSolver::solve() needs a successful factorize()");
  return active_->solve(b);
}

FreeDofs::FreeDofs(const std::vector<bool>& is_free) {
  const Index n = static_cast<Index>(is_free.size());
  for (Index d = 0; d < n; ++d)
    if (is_free[static_cast<std::size_t>(d)]) index.push_back(d);
  select.resize(n, size());
  std::vector<Eigen::Triplet<double, int>> t;
  t.reserve(index.size());
  for (Index j = 0; j < size(); ++j) t.emplace_back(static_cast<int>(index[j]), static_cast<int>(j), 1.0);
  select.setFromTriplets(t.begin(), t.end());
}

VecX FreeDofs::restrict(const VecX& v) const {
  VecX out(size());
  for (Index j = 0; j < size(); ++j) out(j) = v(index[j]);
  return out;
}

// ---------------------------------------------------------------------------------
// Newton solver

StaticResult solve_static(const Model& model, const Eigen::Ref<const VecX>& x_start,
                          const std::vector<PrescribedDof>& prescribed, const VecX& f_ext,
                          const StaticOptions& options) {
  if (f_ext.size() != 0 && f_ext.size() != model.n_dofs()) {
    StaticResult result;
    result.positions = x_start;
    result.reactions = VecX::Zero(model.n_dofs());
    result.report.status = StaticReport::Status::kInvalidStart;
    result.report.message = "external force has " + std::to_string(f_ext.size()) + " entries, expected " +
                            std::to_string(model.n_dofs());
    return result;
  }
  const VecX dead = f_ext.size() == 0 ? VecX::Zero(model.n_dofs()) : f_ext;
  const LoadFunction load = [&dead](double lambda, const VecX&, bool) { return ExternalLoad{lambda * dead, {}}; };
  return solve_static(model, x_start, prescribed, load, false, options);
}

StaticResult solve_static(const Model& model, const Eigen::Ref<const VecX>& x_start,
                          const std::vector<PrescribedDof>& prescribed, const LoadFunction& load_at,
                          bool unsymmetric, const StaticOptions& options) {
  options.validate();
  const Index n = model.n_dofs();
  StaticResult result;
  StaticReport& report = result.report;
  result.positions = x_start;
  result.reactions = VecX::Zero(n);
  auto invalid = [&](const std::string& msg) {
    report.status = StaticReport::Status::kInvalidStart;
    report.message = msg;
    return result;
  };
  if (x_start.size() != n)
    return invalid("start positions have " + std::to_string(x_start.size()) + " entries, expected " +
                   std::to_string(n));
  // Residual and (optionally) tangent at lambda, x: internal minus external.
  struct State {
    Assembly a;
    VecX residual;
    double scale = 0.0;  // max(|f_int|, |f_ext|)
  };
  auto evaluate = [&](double lam, const VecX& xs, bool want_tangent) {
    State st;
    st.a = model.assemble(xs, want_tangent);
    if (!st.a.ok) return st;
    ExternalLoad ext = load_at(lam, xs, want_tangent);
    SF_ASSERT(ext.force.size() == n, "external load must have n_dofs entries");
    st.residual = st.a.force - ext.force;
    st.scale = std::max(st.a.force.norm(), ext.force.norm());
    if (want_tangent && ext.tangent.size() > 0) st.a.tangent -= ext.tangent;
    return st;
  };

  // Dof classes: free, prescribed, held (used by no element).
  enum : char { kFree, kPrescribed, kHeld };
  std::vector<char> kind(n, kFree);
  VecX target = x_start;
  for (const PrescribedDof& p : prescribed) {
    if (p.dof < 0 || p.dof >= n)
      return invalid("prescribed dof " + std::to_string(p.dof) + " is outside 0.." + std::to_string(n - 1));
    if (!std::isfinite(p.value)) return invalid("prescribed dof " + std::to_string(p.dof) + " has a non-finite value");
    kind[p.dof] = kPrescribed;
    target(p.dof) = p.value;
  }
  const std::vector<bool> used = model.used_dofs();
  std::vector<bool> is_free(static_cast<std::size_t>(n), false);
  for (Index d = 0; d < n; ++d) {
    if (!used[d] && kind[d] == kFree) kind[d] = kHeld;
    is_free[static_cast<std::size_t>(d)] = kind[d] == kFree;
  }
  const FreeDofs free_dofs(is_free);
  const Index nf = free_dofs.size();
  const linalg::SparseMatrix& select = free_dofs.select;
  double length_scale = 0.0;
  for (Index d = 0; d < n; ++d) length_scale = std::max(length_scale, std::abs(x_start(d)));
  length_scale = std::max(length_scale, 1e-300);

  {
    const Assembly a0 = model.assemble(x_start, false);
    if (!a0.ok) return invalid("start state: " + a0.message);
  }

  TangentSolver solver(options.linear_solver, unsymmetric);
  VecX x = x_start;
  double lambda = 0.0;
  double increment = std::min(options.initial_increment, options.max_increment);
  auto prescribed_at = [&](double lam) {
    VecX v = x;
    for (Index d = 0; d < n; ++d)
      if (kind[d] == kPrescribed) v(d) = x_start(d) + lam * (target(d) - x_start(d));
    return v;
  };
  auto free_part = [&](const VecX& v) { return free_dofs.restrict(v); };

  int attempts = 0;
  while (lambda < 1.0) {
    if (attempts >= options.max_steps) {
      report.status = StaticReport::Status::kStepFailed;
      report.message = "max_steps (" + std::to_string(options.max_steps) + ") attempted load steps reached at lambda " +
                       detail::short_number(lambda);
      break;
    }
    ++attempts;
    const double lam_new = (1.0 - lambda <= increment * (1.0 + 1e-12)) ? 1.0 : lambda + increment;
    StepRecord rec;
    rec.load_factor = lam_new;
    rec.increment = lam_new - lambda;

    // Predictor: tangent at the converged state, prescribed dofs moved.
    VecX xt = x;
    bool failed = false;
    {
      const State st = evaluate(lam_new, x, true);
      const Assembly& a = st.a;
      if (!a.ok) return invalid("converged state became inadmissible: " + a.message);
      const VecX x_new = prescribed_at(lam_new);
      const VecX dxp = x_new - x;  // nonzero on prescribed dofs only
      const VecX rhs = -free_part(st.residual + a.tangent * dxp);
      const linalg::SparseMatrix kff = select.transpose() * a.tangent * select;
      if (nf > 0) {
        const linalg::SolveReport& sr = solver.factorize(kff);
        if (!sr.ok()) {
          rec.failure = "predictor: linear solve " + sr.brief();
          failed = true;
        } else {
          const VecX dxf = solver.solve(rhs);
          xt = x_new + select * dxf;
        }
      } else {
        xt = x_new;
      }
      rec.iterations = 1;
    }
    // Corrector.
    double first_norm = -1.0;
    while (!failed) {
      const State st = evaluate(lam_new, xt, true);
      const Assembly& a = st.a;
      if (!a.ok) {
        rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + a.message;
        failed = true;
        break;
      }
      const VecX rf = free_part(st.residual);
      const double rnorm = rf.norm();
      rec.residual_norms.push_back(rnorm);
      const double scale = st.scale;
      if (first_norm < 0.0) first_norm = rnorm;
      if (rnorm <= std::max(options.residual_tol_abs, options.residual_tol_rel * scale)) {
        rec.converged = true;
        report.force_scale = scale;
        break;
      }
      if (!std::isfinite(rnorm) || rnorm > options.divergence_factor * std::max(first_norm, 1e-300)) {
        rec.failure = "diverged: |r| " + detail::short_number(rnorm) + " after " + std::to_string(rec.iterations) + " iterations";
        failed = true;
        break;
      }
      if (rec.iterations >= options.max_iterations) {
        rec.failure = "no convergence in " + std::to_string(options.max_iterations) + " iterations (|r| " +
                      detail::short_number(rnorm) + ", tolerance " +
                      detail::short_number(std::max(options.residual_tol_abs, options.residual_tol_rel * scale)) + ")";
        failed = true;
        break;
      }
      const linalg::SolveReport& sr = solver.factorize(select.transpose() * a.tangent * select);
      if (!sr.ok()) {
        rec.failure = "linear solve " + sr.brief();
        failed = true;
        break;
      }
      const VecX dxf = solver.solve(-rf);
      ++rec.iterations;
      if (!dxf.allFinite()) {
        rec.failure = "linear solve returned non-finite values";
        failed = true;
        break;
      }
      const VecX dx = select * dxf;
      // Round-off floor: a correction this small cannot reduce |r| further.
      if (dxf.size() == 0 || dxf.lpNorm<Eigen::Infinity>() <= kIncrementTolRel * length_scale) {
        xt += dx;
        rec.step_lengths.push_back(1.0);
        rec.converged = true;
        report.force_scale = scale;
        break;
      }
      double alpha = 1.0;
      if (options.line_search) {
        alpha = detail::backtrack(rnorm, options.max_line_search, [&](double trial_step, bool&) -> std::optional<double> {
                  const State trial = evaluate(lam_new, xt + trial_step * dx, false);
                  if (!trial.a.ok) return std::nullopt;
                  return free_part(trial.residual).norm();
                }).step;
        if (alpha < 0.0) {
          rec.failure = "iteration " + std::to_string(rec.iterations) + ": every line-search trial inverted an element";
          failed = true;
          break;
        }
      }
      xt += alpha * dx;
      rec.step_lengths.push_back(alpha);
    }
    report.total_iterations += rec.iterations;
    if (rec.converged) {
      x = xt;
      lambda = lam_new;
      ++report.n_converged_steps;
      if (rec.iterations <= options.easy_iterations)
        increment = std::min(options.max_increment, increment * options.growth);
      report.steps.push_back(std::move(rec));
      continue;
    }
    ++report.n_cutbacks;
    const std::string why = rec.failure;
    report.steps.push_back(std::move(rec));
    increment *= 0.5;
    if (increment < options.min_increment) {
      report.status = StaticReport::Status::kStepFailed;
      report.message = "load step from lambda " + detail::short_number(lambda) + " failed (" + why +
                       "); increment cut back below min_increment " + detail::short_number(options.min_increment);
      break;
    }
  }
  if (lambda >= 1.0) {
    report.status = StaticReport::Status::kConverged;
    report.message.clear();
  }
  report.load_factor = lambda;
  result.positions = x;
  result.reactions = evaluate(lambda, x, false).residual;
  return result;
}

StaticResult solve_static_constrained(Model& model, const Eigen::Ref<const VecX>& x_start,
                                      const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                                      bool unsymmetric, const StaticOptions& options, const UzawaOptions& uzawa,
                                      UzawaReport* report) {
  UzawaReport rep;
  StaticResult r = solve_static(model, x_start, prescribed, load, unsymmetric, options);
  bool any = false;
  for (int b = 0; b < model.n_bodies(); ++b) any = any || model.constrained(b);
  auto measure = [&](const VecX& x) {
    rep.max_g_J = rep.max_g_T = 0.0;
    for (int b = 0; b < model.n_bodies(); ++b)
      for (const Model::ConstraintState& c : model.constraint_state(b, x)) {
        if (model.constraints(b).incompressible) rep.max_g_J = std::max(rep.max_g_J, std::abs(c.g_J));
        if (model.constraints(b).inextensible) rep.max_g_T = std::max(rep.max_g_T, std::abs(c.g_T));
      }
    return std::max(rep.max_g_J, rep.max_g_T);
  };
  if (any && r.report.ok()) {
    // Every repeat starts where the last one ended, with the targets already reached:
    // its prescribed dofs do not move.
    while (measure(r.positions) > uzawa.tolerance) {
      if (rep.updates >= uzawa.max_updates) {
        rep.converged = false;
        r.report.status = StaticReport::Status::kStepFailed;
        r.report.message = "constraints not met after " + std::to_string(uzawa.max_updates) +
                           " multiplier updates (max |mean J - 1| " + detail::short_number(rep.max_g_J) + ", max |mean (I4 - 1)/2| " +
                           detail::short_number(rep.max_g_T) + ", tolerance " + detail::short_number(uzawa.tolerance) + ")";
        break;
      }
      for (int b = 0; b < model.n_bodies(); ++b) {
        if (!model.constrained(b)) continue;
        std::vector<double> p, t;
        for (const Model::ConstraintState& c : model.constraint_state(b, r.positions)) {
          p.push_back(c.p_eff);
          t.push_back(c.T_eff);
        }
        model.set_multipliers(b, std::move(p), std::move(t));
      }
      ++rep.updates;
      const LoadFunction full = [&load](double, const VecX& x, bool want_tangent) { return load(1.0, x, want_tangent); };
      const StaticResult again = solve_static(model, r.positions, prescribed, full, unsymmetric, options);
      const int iterations = r.report.total_iterations + again.report.total_iterations;
      r = again;
      r.report.total_iterations = iterations;
      if (!r.report.ok()) {
        rep.converged = false;
        break;
      }
    }
  }
  if (any && !r.report.ok()) rep.converged = false;
  if (report) *report = rep;
  return r;
}

}  // namespace sf::forming

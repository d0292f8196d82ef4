#include "forming/solve/branch_switch.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/core/error.hpp"
#include "forming/model/model.hpp"
#include "forming/solve/tangent_solver.hpp"

namespace sf::forming {
namespace {

constexpr Index kNodeDofs = 12;  // a node's position and its three derivatives (Model::dof)

// The body of dof d and its local index there.
int body_of(const Model& model, Index d, Index& local) {
  for (int b = model.n_bodies() - 1; b >= 0; --b)
    if (d >= model.offset(b)) {
      local = d - model.offset(b);
      return b;
    }
  local = d;
  return 0;
}

}  // namespace

void BranchSwitchOptions::validate() const {
  if (!(amplitude >= 0.0) || !std::isfinite(amplitude))
    throw InputError("solver branch_switch amplitude: expected a displacement >= 0 (mm), found " +
                     std::to_string(amplitude));
  if (give_up_after < 0)
    throw InputError("solver branch_switch give_up_after: expected at least 0 (0: off), found " +
                     std::to_string(give_up_after));
  if (retries < 0)
    throw InputError("solver branch_switch retries: expected at least 0, found " + std::to_string(retries));
  if (inverse_steps < 1)
    throw InputError("solver branch_switch inverse_steps: expected at least 1, found " +
                     std::to_string(inverse_steps));
}

double nearest_eigenvalue(TangentSolver& solver, const linalg::SparseMatrix& k, double& spread, VecX& mode,
                          int steps) {
  const Index n = k.rows();
  spread = 1.0;
  if (n == 0) return 0.0;
  VecX x(n);
  for (Index i = 0; i < n; ++i) x(i) = 1.0 + 0.5 * std::sin(0.7 * double(i) + 0.3);  // fixed start, not an eigenvector
  x.normalize();
  double mu = 0.0;  // 1 / lambda
  for (int it = 0; it < steps; ++it) {
    const VecX w = solver.solve(x);
    if (!w.allFinite() || w.norm() == 0.0) return std::numeric_limits<double>::quiet_NaN();
    mu = x.dot(w);
    spread = (w - mu * x).norm() / w.norm();
    x = w.normalized();
  }
  mode = x;
  const double diag = k.diagonal().cwiseAbs().maxCoeff();
  return (mu == 0.0 ? std::numeric_limits<double>::infinity() : 1.0 / mu) / std::max(diag, 1e-300);
}

ModePlace mode_place(const Model& model, const VecX& v, const VecX& x) {
  ModePlace p;
  Index at = 0;
  v.cwiseAbs().maxCoeff(&at);
  Index local = 0;
  const int b = body_of(model, at, local);
  p.ply = b + 1;
  p.node = local / kNodeDofs;
  const Index d = model.dof(b, p.node, 0, 0);
  p.x = x(d);
  p.z = x(d + 2);
  p.coordinate = "xyz"[local % 3];
  p.derivative = local % kNodeDofs >= 3;
  const double total = std::max(v.squaredNorm(), 1e-300);
  for (int c = 0; c < model.n_bodies(); ++c) {
    const Index end = c + 1 < model.n_bodies() ? model.offset(c + 1) : model.n_dofs();
    p.shares.push_back(100.0 * v.segment(model.offset(c), end - model.offset(c)).squaredNorm() / total);
  }
  return p;
}

std::string describe(const ModePlace& p) {
  std::ostringstream os;
  os.precision(3);
  os << "largest at ply " << p.ply << " node " << p.node << " (x " << p.x << ", z " << p.z << ") " << p.coordinate
     << (p.derivative ? " (a derivative)" : "") << "; ply shares %";
  for (const double s : p.shares) os << " " << std::lround(s);
  return os.str();
}

TangentMode tangent_mode(const Model& model, const VecX& x, const std::vector<PrescribedDof>& prescribed,
                         const InteractionContext& context, const linalg::SparseMatrix* load_tangent,
                         TangentWorkspace& workspace, int inverse_steps) {
  TangentMode out;
  const Index n = model.n_dofs();
  std::vector<bool> is_free = model.used_dofs();
  for (const PrescribedDof& p : prescribed)
    if (p.dof >= 0 && p.dof < n) is_free[static_cast<std::size_t>(p.dof)] = false;
  const FreeDofs free(is_free);
  if (free.size() == 0) {
    out.message = "no free unknowns";
    return out;
  }
  const bool unsymmetric = !model.symmetric_tangent() || (load_tangent && load_tangent->nonZeros() > 0);
  workspace.prepare(model, is_free, linalg::SolverKind::kAuto, unsymmetric);
  linalg::PatternAssembler& pattern = workspace.pattern();
  const Assembly a = model.assemble_into(x, context, &pattern);
  if (!a.ok) {
    out.message = "the state is inadmissible: " + a.message;
    return out;
  }
  if (load_tangent && load_tangent->nonZeros() > 0) {
    pattern.add(*load_tangent, -1.0);
    pattern.flush();
  }
  TangentSolver& solver = workspace.solver();
  const linalg::SolveReport& sr = solver.factorize(pattern.matrix());
  if (!sr.ok()) {
    out.message = "factorisation failed: " + sr.brief();
    return out;
  }
  out.determinant_sign = sr.determinant_sign;
  out.negative_pivots = sr.negative_pivots;
  VecX mode_f;
  out.eigenvalue = nearest_eigenvalue(solver, pattern.matrix(), out.spread, mode_f, inverse_steps);
  if (!std::isfinite(out.eigenvalue) || mode_f.size() != free.size()) {
    out.message = "inverse iteration failed";
    return out;
  }
  out.mode = free.expand(mode_f);
  // Scale: the largest position entry (not a derivative) 1.
  double largest = 0.0;
  for (Index d = 0; d < n; ++d) {
    Index local = 0;
    body_of(model, d, local);
    if (local % kNodeDofs < 3) largest = std::max(largest, std::abs(out.mode(d)));
  }
  if (!(largest > 0.0)) {
    out.message = "the mode moves no node";
    return out;
  }
  out.mode /= largest;
  out.place = mode_place(model, out.mode, x);
  out.ok = true;
  return out;
}

VecX perturbed(const Model& model, const VecX& x, const VecX& mode, double amplitude,
               const InteractionContext& context, int& sign) {
  const VecX plus = x + amplitude * mode, minus = x - amplitude * mode;
  const Assembly ap = model.assemble(plus, context, false), am = model.assemble(minus, context, false);
  if (ap.ok && am.ok) {
    sign = am.energy < ap.energy ? -1 : 1;
  } else if (ap.ok || am.ok) {
    sign = ap.ok ? 1 : -1;
  } else {
    sign = 0;
    return VecX();
  }
  return sign > 0 ? plus : minus;
}

}  // namespace sf::forming

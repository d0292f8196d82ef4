// Implicit dynamics (forming/solve/dynamic_solver.hpp): consistent mass matrix, generalised-alpha /
// HHT / Newmark time integration (notes/forming-verification.md sections 2.7, 3.3).
//
// Plies: flat rectangles (bottom face z = 0), compressible neo-Hookean E = 1000 MPa,
// nu = 0.3, density 1.5e-9 t/mm^3 (a dense ply), units mm, N, s, t.
//   free ply      2 x 1 bricks, 2 x 1 x 0.2 mm, no support, no load;
//   cantilever    the same ply with every parameter of its x = 0 edge clamped (both layers).
// Checks
//   mass          total mass rho V (two bodies, graded mesh), second moments int X^2 dV,
//                 symmetry, block diagonality, positive definiteness;
//   energy        free ply started with stretching and bending velocity fields:
//                 rho_inf = 1 keeps kinetic + internal energy constant, rho_inf = 0.5
//                 dissipates it; linear momentum conserved to round-off by both;
//   period        cantilever's first mode at small amplitude: discrete period against
//                 the generalised eigenvalue; trapezoidal (rho_inf = 1) error
//                 (omega dt/2)/atan(omega dt/2) - 1 ~ (omega dt)^2/12, second order;
//   quasi-static  slowly ramped dead tip load -> the solve_static solution;
//   prescribed    a rigid translation at constant velocity driven by a clamped edge is
//                 reproduced exactly;
//   external tangent, inverting motion (step-failed report), bad options/input.
// Measured figures are printed (std::printf) and quoted next to each tolerance.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "common/core/error.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/solve/dynamic_solver.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/solve/static_solver.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using ::testing::HasSubstr;

constexpr double kE = 1000.0;  // MPa
constexpr double kNu = 0.3;
constexpr double kRho = 1.5e-9;                   // t/mm^3
constexpr double kL1 = 2.0, kL2 = 1.0, kH = 0.2;  // mm

// ---- Named tolerances (measured values in the comments) -------------------------
// Total mass and second moments against closed form (measured ~1e-16).
constexpr double kMassExact = 1e-12;
// Energy drift max |E - E0| / E0 over 400 steps with rho_inf = 1. Measured 1.5e-3, and
// 2.9e-4 / 7.8e-5 with dt / 2 and dt / 4 (second order): for a nonlinear law the
// midpoint evaluation f_int(x_{n+1/2}) conserves energy only to O(dt^2); a linear system
// conserves it to the Newton tolerance (see the period test's modal energy).
constexpr double kEnergyDrift = 3e-3;
// rho_inf = 0.5 must lose at least this fraction of the energy in 160 steps (measured
// 0.056; 0.108 in 400 steps).
constexpr double kMinDissipation = 0.03;
// Linear momentum change relative to the momentum scale sqrt(2 E0 m) (measured ~1e-15).
constexpr double kMomentum = 1e-10;
// Period error vs the trapezoidal closed form, relative to that error (measured 1e-5;
// the amplitude 1e-3 mm keeps the geometric nonlinearity below 1e-6 of the period).
constexpr double kPeriodModel = 1e-3;
// Modal energy after 4 periods with rho_inf = 1 (measured 1 - 1.5e-6).
constexpr double kModalEnergy = 1e-4;
// Convergence order from halving dt: ratio of the period errors (measured 3.970, the
// closed form's ratio at omega dt = 0.39 -> 0.20).
constexpr double kOrderRatioLow = 3.8, kOrderRatioHigh = 4.2;
// Quasi-static: |x_dyn - x_static|_inf / |x_static - X|_inf (measured 2.4e-5); also the
// reactions' sum against the load, relative (measured 4e-5).
constexpr double kQuasiStatic = 2e-3;
// Rigid translation: positions to round-off (measured 2e-14 relative to the ply size);
// velocities carry the acceleration round-off ~ eps L / (beta dt^2) times dt (measured
// 6e-10 relative to |v|).
constexpr double kRigidExact = 1e-12;
constexpr double kRigidVelocity = 1e-8;

// Tolerances handed to the solvers.
constexpr double kNewtonTolRel = 1e-10;

struct PlyCase {
  std::unique_ptr<Model> model;
  linalg::SparseMatrix mass;
  VecX X;  // reference positions
};

PlyCase make_setup(int n1 = 2, int n2 = 1) {
  PlyCase s;
  s.model = std::make_unique<Model>();
  s.model->add_ply(fixtures::rectangle_ply(kL1, kL2, kH, n1, n2),
                   std::make_shared<NeoHookean>(NeoHookeanParams::from_young_poisson(kE, kNu)));
  s.mass = mass_matrix(*s.model, {kRho});
  s.X = s.model->reference_positions();
  return s;
}

// Every parameter (both layers, 3 coordinates) of the surface nodes at x = 0 of body 0.
std::vector<Index> clamped_dofs(const Model& model) {
  return fixtures::node_dofs(model, 0, fixtures::surface_nodes_at_x(model.ply(0), 0.0));
}

std::vector<TimedDof> fixed(const std::vector<Index>& dofs, const VecX& X) {
  std::vector<TimedDof> out;
  for (Index d : dofs) {
    const double value = X(d);
    out.push_back({d, [value](double) { return value; }});
  }
  return out;
}

std::vector<Index> free_dofs(Index n, const std::vector<Index>& fixed_dofs) {
  std::vector<bool> is_fixed(n, false);
  for (Index d : fixed_dofs) is_fixed[d] = true;
  std::vector<Index> out;
  for (Index d = 0; d < n; ++d)
    if (!is_fixed[d]) out.push_back(d);
  return out;
}

MatX dense_sub(const linalg::SparseMatrix& a, const std::vector<Index>& idx) {
  const MatX full = MatX(a);
  MatX out(idx.size(), idx.size());
  for (std::size_t c = 0; c < idx.size(); ++c)
    for (std::size_t r = 0; r < idx.size(); ++r) out(r, c) = full(idx[r], idx[c]);
  return out;
}

// Unit rigid translation along coordinate i (value parameters 1, derivatives 0).
VecX translation(const Model& model, int i) {
  VecX u = VecX::Zero(model.n_dofs());
  for (Index p = 0; p < model.n_dofs() / 3; ++p)
    if (p % 4 == 0) u(3 * p + i) = 1.0;
  return u;
}

// Lowest generalised eigenpair of the cantilever (K, M on the free dofs at X).
struct Mode {
  double omega = 0.0;  // rad/s
  VecX shape;          // free dofs, max |entry| = 1
};
Mode first_mode(const PlyCase& s, const std::vector<Index>& free) {
  const Assembly a = s.model->assemble(s.X, true);
  const MatX k = dense_sub(a.tangent, free);
  const MatX m = dense_sub(s.mass, free);
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> ges(k, m);
  Mode mode;
  mode.omega = std::sqrt(ges.eigenvalues()(0));
  mode.shape = ges.eigenvectors().col(0);
  mode.shape /= mode.shape.cwiseAbs().maxCoeff();
  return mode;
}

// ---------------------------------------------------------------------------------
// (a) Mass matrix

TEST(DynamicsMass, TotalMassSecondMomentsSymmetryDefiniteness) {
  // Body 0: graded 2 x 1 mesh (unequal scale factors), body 1: 1 x 2 mesh.
  Model model;
  auto mat = std::make_shared<NeoHookean>(NeoHookeanParams::from_young_poisson(kE, kNu));
  model.add_ply(fixtures::rectangle_ply(kL1, kL2, kH, 2, 1, 0.0, PlyPlacement::kBottom, {0.0, 0.7, 2.0}), mat);
  model.add_ply(fixtures::rectangle_ply(1.0, 3.0, 0.3, 1, 2), mat);
  const double rho0 = 1.5e-9, rho1 = 7.85e-9;
  const linalg::SparseMatrix m = mass_matrix(model, {rho0, rho1});
  const double v0 = kL1 * kL2 * kH, v1 = 1.0 * 3.0 * 0.3;
  const double total = rho0 * v0 + rho1 * v1;
  for (int i = 0; i < 3; ++i) {
    const VecX u = translation(model, i);
    const double mu = u.dot(m * u);
    std::printf("[mass] coordinate %d: u^T M u = %.17g, rho V = %.17g, rel err %.2e\n", i, mu, total,
                std::abs(mu - total) / total);
    EXPECT_NEAR(mu, total, kMassExact * total) << "coordinate " << i;
  }
  // Second moments on body 0: u = X_x (coordinate x) and u = X_z (coordinate z).
  {
    const MatX X = model.ply(0).reference();
    VecX ux = VecX::Zero(model.n_dofs()), uz = VecX::Zero(model.n_dofs());
    for (Index p = 0; p < X.rows(); ++p) {
      ux(model.offset(0) + 3 * p + 0) = X(p, 0);  // value X_x; derivative rows give dX_x/ds
      uz(model.offset(0) + 3 * p + 2) = X(p, 2);
    }
    const double ix = ux.dot(m * ux), iz = uz.dot(m * uz);
    const double ix_exact = rho0 * kH * kL2 * kL1 * kL1 * kL1 / 3.0;
    const double iz_exact = rho0 * kL1 * kL2 * kH * kH * kH / 3.0;
    std::printf("[mass] int rho X^2 dV = %.6e (rel err %.2e), int rho Z^2 dV = %.6e (rel err %.2e)\n", ix,
                std::abs(ix - ix_exact) / ix_exact, iz, std::abs(iz - iz_exact) / iz_exact);
    EXPECT_NEAR(ix, ix_exact, kMassExact * ix_exact);
    EXPECT_NEAR(iz, iz_exact, kMassExact * iz_exact);
  }
  // Block diagonal per coordinate (no stored coupling) and symmetric.
  int coupled = 0;
  for (int k = 0; k < m.outerSize(); ++k)
    for (linalg::SparseMatrix::InnerIterator it(m, k); it; ++it)
      if (it.row() % 3 != it.col() % 3) ++coupled;
  EXPECT_EQ(coupled, 0);
  const MatX dense = MatX(m);
  const double asym = (dense - dense.transpose()).cwiseAbs().maxCoeff() / dense.cwiseAbs().maxCoeff();
  EXPECT_LE(asym, 1e-15);
  const Eigen::SelfAdjointEigenSolver<MatX> es(dense);
  const double lmin = es.eigenvalues().minCoeff(), lmax = es.eigenvalues().maxCoeff();
  std::printf("[mass] asymmetry %.1e, eigenvalues %.3e .. %.3e (condition %.2e)\n", asym, lmin, lmax, lmax / lmin);
  EXPECT_GT(lmin, 0.0) << "every dof is used: M positive definite";
}

// ---------------------------------------------------------------------------------
// (b) Energy conservation / dissipation on the free ply

struct EnergyRun {
  std::vector<double> energy;  // T + U per step (initial state first)
  double max_momentum_change = 0.0;
  double momentum_scale = 0.0;
  DynamicReport report;
};

// Free ply, kinetic energy + internal energy at the start = that of a 3 % stretch along x.
//   prestretched: released from the 3 % stretch (affine, all parameters) with a bending
//                 velocity field v_z ~ (X_x - xc)^2 carrying the same energy again;
//   otherwise:    from the reference state with a stretching velocity v_x ~ (X_x - xc)
//                 and the bending field, each carrying half of that energy.
EnergyRun run_free_ply(const DynamicOptions& options, bool prestretched) {
  const PlyCase s = make_setup();
  const Model& model = *s.model;
  const MatX Xp = model.ply(0).reference();
  const Mat3 F0 = Eigen::Vector3d(1.03, 1.0, 1.0).asDiagonal();
  const Vec3 centre(0.5 * kL1, 0.5 * kL2, 0.5 * kH);
  MatX stretched = Xp, v_stretch = MatX::Zero(Xp.rows(), 3), v_bend = MatX::Zero(Xp.rows(), 3);
  for (Index p = 0; p < Xp.rows(); ++p) {
    const int d = static_cast<int>(p % 4);
    const Vec3 row = Xp.row(p).transpose();
    stretched.row(p) = (d == 0 ? Vec3(F0 * (row - centre) + centre) : Vec3(F0 * row)).transpose();
    v_stretch(p, 0) = d == 0 ? row(0) - centre(0) : row(0);  // v_x = X_x - xc
  }
  // v_z = (X_x - xc)^2: value, d/ds1, d/ds2, d2/ds1ds2 from the reference parameters.
  for (Index node = 0; node < Xp.rows() / 4; ++node) {
    const double xr = Xp(4 * node, 0) - centre(0);
    const Vec3 t1 = Xp.row(4 * node + 1).transpose(), t2 = Xp.row(4 * node + 2).transpose();
    const Vec3 c12 = Xp.row(4 * node + 3).transpose();
    v_bend(4 * node + 0, 2) = xr * xr;
    v_bend(4 * node + 1, 2) = 2.0 * xr * t1(0);
    v_bend(4 * node + 2, 2) = 2.0 * xr * t2(0);
    v_bend(4 * node + 3, 2) = 2.0 * t1(0) * t2(0) + 2.0 * xr * c12(0);
  }
  const double u_stretch = model.assemble(PlyMesh::flatten(stretched), false).energy;
  VecX vb = PlyMesh::flatten(v_bend), vs = PlyMesh::flatten(v_stretch);
  VecX x0, v0;
  if (prestretched) {
    x0 = PlyMesh::flatten(stretched);
    v0 = vb * std::sqrt(u_stretch / kinetic_energy(s.mass, vb));
  } else {
    x0 = s.X;
    v0 = vb * std::sqrt(0.5 * u_stretch / kinetic_energy(s.mass, vb)) +
         vs * std::sqrt(0.5 * u_stretch / kinetic_energy(s.mass, vs));
  }
  const double u0 = kinetic_energy(s.mass, v0) + model.assemble(x0, false).energy;

  EnergyRun run;
  std::vector<VecX> u(3);
  Vec3 p0;
  for (int i = 0; i < 3; ++i) {
    u[i] = translation(model, i);
    p0(i) = u[i].dot(s.mass * v0);
  }
  run.momentum_scale = std::sqrt(2.0 * u0 * u[0].dot(s.mass * u[0]));
  const StepCallback cb = [&](double, const VecX& x, const VecX& v) {
    run.energy.push_back(kinetic_energy(s.mass, v) + model.assemble(x, false).energy);
    for (int i = 0; i < 3; ++i)
      run.max_momentum_change = std::max(run.max_momentum_change, std::abs(u[i].dot(s.mass * v) - p0(i)));
  };
  run.report = solve_dynamic(model, s.mass, x0, v0, {}, {}, options, cb).report;
  return run;
}

TEST(DynamicsEnergy, TrapezoidalConservesAndRhoHalfDissipates) {
  // Free ply spectrum (6 rigid modes first): omega_7 = 2.70e5 rad/s (T = 2.32e-5 s),
  // omega_max = 1.92e7 rad/s (through the thickness). dt = 2.5e-7 s: omega_7 dt = 0.068,
  // omega_max dt = 4.8; 400 steps = 4.3 periods of the lowest elastic mode and ~20 of the
  // in-plane stretch mode.
  DynamicOptions opt;
  opt.initial_dt = 2.5e-7;
  opt.end_time = 1e-4;
  opt.rho_inf = 1.0;
  const EnergyRun cons = run_free_ply(opt, false);
  ASSERT_TRUE(cons.report.ok()) << cons.report.brief();
  const double e0 = cons.energy.front();
  double drift = 0.0;
  for (double e : cons.energy) drift = std::max(drift, std::abs(e - e0) / e0);
  std::printf("[energy] rho_inf 1: %s\n", cons.report.brief().c_str());
  std::printf("[energy] rho_inf 1: E0 = %.6e N mm, max |E - E0|/E0 = %.2e, end %.2e, momentum change %.1e\n", e0, drift,
              (cons.energy.back() - e0) / e0, cons.max_momentum_change / cons.momentum_scale);
  EXPECT_LE(drift, kEnergyDrift);
  EXPECT_LE(cons.max_momentum_change, kMomentum * cons.momentum_scale);

  opt.rho_inf = 0.5;
  opt.end_time = 4e-5;  // 160 steps
  const EnergyRun diss = run_free_ply(opt, false);
  ASSERT_TRUE(diss.report.ok()) << diss.report.brief();
  const double loss = 1.0 - diss.energy.back() / diss.energy.front();
  std::printf("[energy] rho_inf 0.5, 160 steps: energy lost %.3f, momentum change %.1e\n", loss,
              diss.max_momentum_change / diss.momentum_scale);
  EXPECT_GE(loss, kMinDissipation);
  EXPECT_LE(diss.max_momentum_change, kMomentum * diss.momentum_scale);
}

// ---------------------------------------------------------------------------------
// (c) Single mode: period error and order

struct PeriodRun {
  double omega_discrete = 0.0;
  double modal_energy_ratio = 0.0;  // end / start of 1/2 (qdot^2 + omega^2 q^2)
  DynamicReport report;
};

PeriodRun run_mode(const PlyCase& s, const std::vector<Index>& clamp, const Mode& mode, double dt, int n_steps,
                   DynamicOptions opt) {
  const std::vector<Index> free = free_dofs(s.model->n_dofs(), clamp);
  const double amplitude = 1e-3;  // mm: geometric nonlinearity ~ (1e-3/2)^2 in the period
  VecX x0 = s.X;
  for (std::size_t j = 0; j < free.size(); ++j) x0(free[j]) += amplitude * mode.shape(j);
  const MatX mff = dense_sub(s.mass, free);
  const VecX mphi = mff * mode.shape;
  const double norm = mode.shape.dot(mphi);
  std::vector<double> q, qd;
  const StepCallback cb = [&](double, const VecX& x, const VecX& v) {
    double qq = 0.0, qv = 0.0;
    for (std::size_t j = 0; j < free.size(); ++j) {
      qq += mphi(j) * (x(free[j]) - s.X(free[j]));
      qv += mphi(j) * v(free[j]);
    }
    q.push_back(qq / norm);
    qd.push_back(qv / norm);
  };
  opt.initial_dt = dt;
  opt.end_time = n_steps * dt;
  opt.residual_tol_rel = kNewtonTolRel;
  PeriodRun run;
  run.report = solve_dynamic(*s.model, s.mass, x0, VecX::Zero(x0.size()), fixed(clamp, s.X), {}, opt, cb).report;
  // A sampled sinusoid satisfies q_{n+1} + q_{n-1} = 2 cos(omega dt) q_n: least squares.
  double num = 0.0, den = 0.0;
  for (std::size_t k = 1; k + 1 < q.size(); ++k) {
    num += q[k] * (q[k + 1] + q[k - 1]);
    den += 2.0 * q[k] * q[k];
  }
  run.omega_discrete = std::acos(num / den) / dt;
  auto modal_energy = [&](std::size_t k) { return 0.5 * (qd[k] * qd[k] + mode.omega * mode.omega * q[k] * q[k]); };
  run.modal_energy_ratio = modal_energy(q.size() - 1) / modal_energy(0);
  return run;
}

TEST(DynamicsPeriod, TrapezoidalSecondOrderPeriodError) {
  const PlyCase s = make_setup();
  const std::vector<Index> clamp = clamped_dofs(*s.model);
  const std::vector<Index> free = free_dofs(s.model->n_dofs(), clamp);
  const Mode mode = first_mode(s, free);
  const double period = 2.0 * kPi / mode.omega;
  std::printf("[period] cantilever mode 1: omega = %.6e rad/s, T = %.6e s\n", mode.omega, period);

  DynamicOptions opt;
  opt.rho_inf = 1.0;
  double errors[2];
  double w_ref = 0.0;  // discrete omega at dt = T/16
  for (int r = 0; r < 2; ++r) {
    const int per_period = 16 << r;
    const double dt = period / per_period;
    const PeriodRun run = run_mode(s, clamp, mode, dt, 4 * per_period, opt);
    ASSERT_TRUE(run.report.ok()) << run.report.brief();
    ASSERT_EQ(run.report.n_cutbacks, 0) << "the frequency estimate needs a uniform dt";
    const double wdt = mode.omega * dt;
    const double err = mode.omega / run.omega_discrete - 1.0;
    const double model_err = 0.5 * wdt / std::atan(0.5 * wdt) - 1.0;
    errors[r] = err;
    if (r == 0) w_ref = run.omega_discrete;
    std::printf(
        "[period] rho_inf 1, dt = T/%d: omega dt %.4f, period error %.5e, closed form %.5e, "
        "(omega dt)^2/12 %.5e, modal energy ratio %.8f, %d Newton iterations\n",
        per_period, wdt, err, model_err, wdt * wdt / 12.0, run.modal_energy_ratio, run.report.total_iterations);
    EXPECT_NEAR(err, model_err, kPeriodModel * model_err);
    EXPECT_NEAR(run.modal_energy_ratio, 1.0, kModalEnergy) << "no amplitude decay";
  }
  const double ratio = errors[0] / errors[1];
  std::printf("[period] error ratio dt -> dt/2: %.4f (order %.3f)\n", ratio, std::log2(ratio));
  EXPECT_GE(ratio, kOrderRatioLow);
  EXPECT_LE(ratio, kOrderRatioHigh);

  // Newmark trapezoidal (beta 1/4, gamma 1/2) gives the same discrete frequency; HHT and
  // rho_inf < 1 lengthen the period and decay the amplitude (reported, loosely checked).
  const double dt = period / 16;
  DynamicOptions nm;
  nm.integrator = Integrator::kNewmark;
  const PeriodRun newmark = run_mode(s, clamp, mode, dt, 64, nm);
  ASSERT_TRUE(newmark.report.ok()) << newmark.report.brief();
  std::printf("[period] Newmark(1/4, 1/2) vs generalised-alpha rho 1: omega rel diff %.2e\n",
              std::abs(newmark.omega_discrete - w_ref) / w_ref);
  EXPECT_NEAR(newmark.omega_discrete, w_ref, 1e-6 * w_ref);
  DynamicOptions hht;
  hht.integrator = Integrator::kHHTAlpha;
  hht.hht_alpha = -0.1;
  DynamicOptions ga;
  ga.rho_inf = 0.5;
  for (const DynamicOptions* o : {&hht, &ga}) {
    const PeriodRun run = run_mode(s, clamp, mode, dt, 64, *o);
    ASSERT_TRUE(run.report.ok()) << run.report.brief();
    std::printf("[period] %s (%s): period error %.4e, modal energy after 4 periods %.4f\n",
                to_string(o->integrator).c_str(), o->integrator == Integrator::kHHTAlpha ? "alpha -0.1" : "rho_inf 0.5",
                mode.omega / run.omega_discrete - 1.0, run.modal_energy_ratio);
    EXPECT_LT(run.modal_energy_ratio, 1.0);
    EXPECT_GT(mode.omega / run.omega_discrete - 1.0, 0.0);
  }
}

// ---------------------------------------------------------------------------------
// (d) Quasi-static limit

TEST(DynamicsQuasiStatic, SlowDeadLoadReachesStaticSolution) {
  const PlyCase s = make_setup();
  const Model& model = *s.model;
  const std::vector<Index> clamp = clamped_dofs(model);
  const Mode mode = first_mode(s, free_dofs(model.n_dofs(), clamp));
  const double period = 2.0 * kPi / mode.omega;
  // Tip load 0.1 N along z on the value parameters of the x = L1 nodes (tip deflection ~0.2 L1).
  VecX f = VecX::Zero(model.n_dofs());
  const PlyMesh& ply = model.ply(0);
  std::vector<Index> tip_nodes;
  for (Index sn = 0; sn < ply.n_surface_nodes(); ++sn)
    if (std::abs(ply.surface().geometry()(mesh::SurfaceMesh::dof(sn, 0), 0) - kL1) < 1e-12)
      for (int layer = 0; layer < 2; ++layer) tip_nodes.push_back(ply.node(sn, layer));
  for (Index node : tip_nodes) f(model.dof(0, node, 0, 2)) = 0.1 / static_cast<double>(tip_nodes.size());

  std::vector<PrescribedDof> bcs;
  for (Index d : clamp) bcs.push_back({d, s.X(d)});
  StaticOptions sopt;
  sopt.initial_increment = 0.25;
  sopt.max_increment = 0.25;
  const StaticResult st = solve_static(model, s.X, bcs, f, sopt);
  ASSERT_TRUE(st.report.ok()) << st.report.brief();

  // Cycloidal ramp over 10 periods (zero rate and acceleration at both ends), then hold 1 period.
  const double ramp = 10.0 * period;
  const ExternalForceFn load = [&](double t, const VecX&, bool) {
    const double tau = std::min(t / ramp, 1.0);
    return ExternalForce{(tau - std::sin(2.0 * kPi * tau) / (2.0 * kPi)) * f, {}};
  };
  DynamicOptions opt;
  opt.rho_inf = 0.5;
  opt.initial_dt = period / 20.0;
  opt.end_time = ramp + period;
  opt.residual_tol_rel = kNewtonTolRel;
  opt.line_search = true;
  const DynamicResult dyn = solve_dynamic(model, s.mass, s.X, VecX::Zero(s.X.size()), fixed(clamp, s.X), load, opt);
  ASSERT_TRUE(dyn.report.ok()) << dyn.report.brief();
  const double deflection = (st.positions - s.X).lpNorm<Eigen::Infinity>();
  const double err = (dyn.positions - st.positions).lpNorm<Eigen::Infinity>() / deflection;
  std::printf("[quasi-static] T1 = %.3e s, static max |x - X| = %.4f mm, dynamic vs static %.2e (%s)\n", period,
              deflection, err, dyn.report.brief().c_str());
  EXPECT_LE(err, kQuasiStatic);
  EXPECT_GT(deflection, 0.2) << "the load should bend the cantilever noticeably";
  // The dynamic reactions balance the load (inertia small at the end).
  const double reaction_z = translation(model, 2).dot(dyn.reactions);
  std::printf("[quasi-static] sum of z reactions %.6f N (load 0.1 N)\n", reaction_z);
  EXPECT_NEAR(reaction_z, -0.1, 0.1 * kQuasiStatic) << "the support pulls against the +z load";
}

// ---------------------------------------------------------------------------------
// Prescribed motion, external tangent, failures

TEST(DynamicsPrescribed, ConstantVelocityRigidTranslationIsExact) {
  const PlyCase s = make_setup();
  const std::vector<Index> clamp = clamped_dofs(*s.model);
  const Vec3 vel(30.0, -20.0, 50.0);  // mm/s
  std::vector<TimedDof> bcs;
  for (Index d : clamp) {
    const double x0 = s.X(d);
    const double rate = (d / 3) % 4 == 0 ? vel(d % 3) : 0.0;
    bcs.push_back({d, [x0, rate](double t) { return x0 + rate * t; }});
  }
  VecX v0 = VecX::Zero(s.X.size());
  for (int i = 0; i < 3; ++i) v0 += vel(i) * translation(*s.model, i);
  DynamicOptions opt;
  opt.rho_inf = 0.5;
  opt.initial_dt = 1e-5;
  opt.end_time = 1e-3;
  const DynamicResult r = solve_dynamic(*s.model, s.mass, s.X, v0, bcs, {}, opt);
  ASSERT_TRUE(r.report.ok()) << r.report.brief();
  const VecX expected = s.X + opt.end_time * v0;
  const double err = (r.positions - expected).lpNorm<Eigen::Infinity>() / s.X.lpNorm<Eigen::Infinity>();
  const double verr = (r.velocities - v0).lpNorm<Eigen::Infinity>() / vel.norm();
  std::printf(
      "[prescribed] rigid translation: position err %.1e, velocity err %.1e, |a| %.1e, |reactions| %.1e N; %s\n", err,
      verr, r.accelerations.lpNorm<Eigen::Infinity>(), r.reactions.lpNorm<Eigen::Infinity>(), r.report.brief().c_str());
  EXPECT_LE(err, kRigidExact);
  EXPECT_LE(verr, kRigidVelocity);
  EXPECT_EQ(r.report.n_converged_steps, 100);
}

TEST(DynamicsStepping, HitTimesRegrowthAndCallback) {
  // Cantilever at rest under a constant tip load: dt starts at 1e-6 s and grows by 1.5
  // after easy steps up to max_dt = 5e-6 s; the steps land exactly on the hit times and
  // on end_time; the callback sees the initial state and every step.
  const PlyCase s = make_setup();
  const std::vector<Index> clamp = clamped_dofs(*s.model);
  VecX f = VecX::Zero(s.X.size());
  f(s.model->dof(0, s.model->ply(0).node(2, 1), 0, 2)) = 1e-3;  // surface node 2 is at x = L1
  DynamicOptions opt;
  opt.initial_dt = 1e-6;
  opt.max_dt = 5e-6;
  opt.end_time = 4e-5;
  opt.hit_times = {2.5e-5, 1.0e-5, 7.77e-6, 5e-5 /* after end_time: ignored */};
  std::vector<double> times;
  const DynamicResult r = solve_dynamic(
      *s.model, s.mass, s.X, VecX::Zero(s.X.size()), fixed(clamp, s.X),
      [&](double, const VecX&, bool) {
        return ExternalForce{f, {}};
      },
      opt, [&](double t, const VecX&, const VecX&) { times.push_back(t); });
  ASSERT_TRUE(r.report.ok()) << r.report.brief();
  std::printf("[stepping] %s\n", r.report.brief().c_str());
  ASSERT_EQ(times.size(), static_cast<std::size_t>(r.report.n_converged_steps + 1));
  EXPECT_EQ(times.front(), 0.0);
  EXPECT_EQ(times.back(), opt.end_time);
  for (double h : {7.77e-6, 1.0e-5, 2.5e-5})
    EXPECT_NE(std::find(times.begin(), times.end(), h), times.end()) << "hit time " << h;
  EXPECT_TRUE(std::is_sorted(times.begin(), times.end()));
  EXPECT_DOUBLE_EQ(r.report.max_dt_used, opt.max_dt);
  EXPECT_DOUBLE_EQ(r.report.steps.front().increment, opt.initial_dt);
  EXPECT_EQ(r.report.n_cutbacks, 0);
}

TEST(DynamicsExternalTangent, GroundSpringTangentSpeedsNewtonSameAnswer) {
  // Ground springs k (x - X) on every free z value dof as an external load -k (x - X)
  // with tangent -k I: the run with the tangent (unsymmetric path) and the one without
  // must agree; the consistent tangent converges in fewer iterations.
  const PlyCase s = make_setup();
  const Model& model = *s.model;
  const std::vector<Index> clamp = clamped_dofs(model);
  const Mode mode = first_mode(s, free_dofs(model.n_dofs(), clamp));
  const double k = 4.0 * mode.omega * mode.omega * s.mass.diagonal().maxCoeff();  // N/mm
  std::vector<Index> springs;
  for (Index p = 0; p < model.n_dofs() / 3; ++p)
    if (p % 4 == 0 && std::abs(s.X(3 * p)) > 1e-12) springs.push_back(3 * p + 2);
  auto make_load = [&](bool with_tangent) {
    return ExternalForceFn([&, with_tangent](double t, const VecX& x, bool want) {
      ExternalForce out;
      out.force = VecX::Zero(x.size());
      for (Index d : springs) out.force(d) = -k * (x(d) - s.X(d));
      out.force(springs.back()) += 0.05 * std::sin(0.5 * mode.omega * t);  // drive
      if (with_tangent && want) {
        linalg::TripletAssembler ta(x.size(), x.size());
        for (Index d : springs) ta.add(d, d, -k);
        out.tangent = ta.compress();
      }
      return out;
    });
  };
  DynamicOptions opt;
  opt.rho_inf = 0.8;
  opt.initial_dt = 2.0 * kPi / mode.omega / 20.0;
  opt.end_time = 30 * opt.initial_dt;
  opt.residual_tol_rel = kNewtonTolRel;
  opt.max_iterations = 60;
  const DynamicResult with =
      solve_dynamic(model, s.mass, s.X, VecX::Zero(s.X.size()), fixed(clamp, s.X), make_load(true), opt);
  const DynamicResult without =
      solve_dynamic(model, s.mass, s.X, VecX::Zero(s.X.size()), fixed(clamp, s.X), make_load(false), opt);
  ASSERT_TRUE(with.report.ok()) << with.report.brief();
  ASSERT_TRUE(without.report.ok()) << without.report.brief();
  const double amp = (with.positions - s.X).lpNorm<Eigen::Infinity>();
  const double diff = (with.positions - without.positions).lpNorm<Eigen::Infinity>() / amp;
  std::printf("[external tangent] iterations with %d, without %d; relative difference %.1e (amplitude %.2e mm)\n",
              with.report.total_iterations, without.report.total_iterations, diff, amp);
  EXPECT_LE(diff, 1e-6);
  EXPECT_LT(with.report.total_iterations, without.report.total_iterations);
}

TEST(DynamicsRobustness, InvertingMotionEndsWithLastConvergedState) {
  // Every parameter prescribed: bottom layer fixed, the top face pushed through it
  // (z = h (1 - 2t), flat): det F = 0 at t = 0.5.
  const PlyCase s = make_setup();
  const Model& model = *s.model;
  const PlyMesh& ply = model.ply(0);
  std::vector<TimedDof> bcs;
  for (Index sn = 0; sn < ply.n_surface_nodes(); ++sn) {
    for (int d = 0; d < 4; ++d)
      for (int i = 0; i < 3; ++i) {
        const Index dof = model.dof(0, ply.node(sn, 0), d, i);
        const double x0 = s.X(dof);
        bcs.push_back({dof, [x0](double) { return x0; }});
      }
    for (int d = 0; d < 4; ++d)
      for (int i = 0; i < 3; ++i) {
        const Index dof = model.dof(0, ply.node(sn, 1), d, i);
        const double x0 = s.X(dof);
        if (d == 0 && i == 2)
          bcs.push_back({dof, [](double t) { return kH * (1.0 - 2.0 * t); }});
        else
          bcs.push_back({dof, [x0](double) { return x0; }});
      }
  }
  DynamicOptions opt;
  opt.initial_dt = 0.1;
  opt.min_dt = 1e-3;
  opt.end_time = 1.0;
  int calls = 0;
  const DynamicResult r = solve_dynamic(model, s.mass, s.X, VecX::Zero(s.X.size()), bcs, {}, opt,
                                        [&](double, const VecX&, const VecX&) { ++calls; });
  std::printf("[robustness] %s\n", r.report.brief().c_str());
  EXPECT_EQ(r.report.status, DynamicReport::Status::kStepFailed);
  EXPECT_THAT(r.report.message, HasSubstr("min_dt"));
  EXPECT_GE(r.report.time, 0.4);
  EXPECT_LT(r.report.time, 0.5);
  EXPECT_TRUE(r.positions.allFinite());
  EXPECT_EQ(calls, r.report.n_converged_steps + 1);
  EXPECT_TRUE(model.assemble(r.positions, false).ok);
  EXPECT_LE(r.report.n_converged_steps + r.report.n_cutbacks, 40);
}

TEST(DynamicsRobustness, InvalidStartIsReported) {
  const PlyCase s = make_setup();
  const VecX z = VecX::Zero(s.X.size());
  EXPECT_EQ(solve_dynamic(*s.model, s.mass, s.X, VecX::Zero(3), {}, {}).report.status,
            DynamicReport::Status::kInvalidStart);
  EXPECT_EQ(solve_dynamic(*s.model, linalg::SparseMatrix(3, 3), s.X, z, {}, {}).report.status,
            DynamicReport::Status::kInvalidStart);
  EXPECT_EQ(solve_dynamic(*s.model, s.mass, s.X, z, {{-1, [](double) { return 0.0; }}}, {}).report.status,
            DynamicReport::Status::kInvalidStart);
  EXPECT_EQ(solve_dynamic(*s.model, s.mass, s.X, z, {{0, nullptr}}, {}).report.status,
            DynamicReport::Status::kInvalidStart);
  // A massless body: M_ff singular.
  const linalg::SparseMatrix m0 = mass_matrix(*s.model, {0.0});
  const DynamicResult r = solve_dynamic(*s.model, m0, s.X, z, {}, {});
  EXPECT_EQ(r.report.status, DynamicReport::Status::kInvalidStart);
  EXPECT_THAT(r.report.message, HasSubstr("mass matrix"));
  // Wrong external force size.
  const ExternalForceFn bad = [](double, const VecX&, bool) { return ExternalForce{VecX::Zero(5), {}}; };
  EXPECT_EQ(solve_dynamic(*s.model, s.mass, s.X, z, {}, bad).report.status, DynamicReport::Status::kInvalidStart);
}

// ---------------------------------------------------------------------------------
// (e) Options

TEST(DynamicsOptions, ParametersMatchTable) {
  // notes 3.3: rho_inf -> (am, af, gamma, beta); HHT alpha -> (gamma, beta).
  struct Row {
    double rho, am, af, gamma, beta;
  };
  for (const Row& r :
       {Row{1.0, 0.5, 0.5, 0.5, 0.25}, Row{0.8, 1.0 / 3.0, 4.0 / 9.0, 0.6111111111111111, 0.30864197530864196},
        Row{0.5, 0.0, 1.0 / 3.0, 5.0 / 6.0, 4.0 / 9.0}, Row{0.0, -1.0, 0.0, 1.5, 1.0}}) {
    DynamicOptions o;
    o.rho_inf = r.rho;
    const IntegratorParameters p = o.parameters();
    EXPECT_NEAR(p.alpha_m, r.am, 1e-15) << r.rho;
    EXPECT_NEAR(p.alpha_f, r.af, 1e-15) << r.rho;
    EXPECT_NEAR(p.gamma, r.gamma, 1e-15) << r.rho;
    EXPECT_NEAR(p.beta, r.beta, 1e-15) << r.rho;
  }
  for (const Row& r : {Row{-0.05, 0, 0.05, 0.55, 0.275625}, Row{-0.1, 0, 0.1, 0.6, 0.3025},
                       Row{-1.0 / 3.0, 0, 1.0 / 3.0, 5.0 / 6.0, 4.0 / 9.0}}) {
    DynamicOptions o;
    o.integrator = Integrator::kHHTAlpha;
    o.hht_alpha = r.rho;
    const IntegratorParameters p = o.parameters();
    EXPECT_EQ(p.alpha_m, 0.0);
    EXPECT_NEAR(p.alpha_f, r.af, 1e-15);
    EXPECT_NEAR(p.gamma, r.gamma, 1e-15);
    EXPECT_NEAR(p.beta, r.beta, 1e-15);
  }
  EXPECT_EQ(parse_integrator("hht-alpha"), Integrator::kHHTAlpha);
  EXPECT_EQ(parse_integrator(to_string(Integrator::kGeneralizedAlpha)), Integrator::kGeneralizedAlpha);
  EXPECT_EQ(parse_integrator("newmark"), Integrator::kNewmark);
}

TEST(DynamicsOptions, BadOptionsThrowNamingTheOption) {
  auto expect_bad = [](const std::string& name, auto&& change) {
    DynamicOptions o;
    change(o);
    try {
      o.validate();
      ADD_FAILURE() << name << ": no exception";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("dynamic solver " + name)) << e.what();
    }
  };
  expect_bad("end_time", [](DynamicOptions& o) { o.end_time = o.start_time; });
  expect_bad("start_time", [](DynamicOptions& o) { o.start_time = std::nan(""); });
  expect_bad("initial_dt", [](DynamicOptions& o) { o.initial_dt = 0.0; });
  expect_bad("min_dt", [](DynamicOptions& o) { o.min_dt = 2.0 * o.initial_dt; });
  expect_bad("max_dt", [](DynamicOptions& o) { o.max_dt = 0.5 * o.initial_dt; });
  expect_bad("growth", [](DynamicOptions& o) { o.growth = 0.9; });
  expect_bad("cutback_factor", [](DynamicOptions& o) { o.cutback_factor = 1.0; });
  expect_bad("easy_iterations", [](DynamicOptions& o) { o.easy_iterations = 0; });
  expect_bad("max_iterations", [](DynamicOptions& o) { o.max_iterations = 0; });
  expect_bad("max_steps", [](DynamicOptions& o) { o.max_steps = 0; });
  expect_bad("hit_times", [](DynamicOptions& o) { o.hit_times = {0.1, INFINITY}; });
  expect_bad("rho_inf", [](DynamicOptions& o) { o.rho_inf = 1.1; });
  expect_bad("rho_inf", [](DynamicOptions& o) { o.rho_inf = -0.1; });
  expect_bad("hht_alpha", [](DynamicOptions& o) {
    o.integrator = Integrator::kHHTAlpha;
    o.hht_alpha = -0.5;
  });
  expect_bad("hht_alpha", [](DynamicOptions& o) {
    o.integrator = Integrator::kHHTAlpha;
    o.hht_alpha = 0.1;
  });
  expect_bad("newmark_beta", [](DynamicOptions& o) {
    o.integrator = Integrator::kNewmark;
    o.newmark_beta = 0.0;
  });
  expect_bad("newmark_gamma", [](DynamicOptions& o) {
    o.integrator = Integrator::kNewmark;
    o.newmark_gamma = 0.4;
  });
  expect_bad("residual_tol_rel", [](DynamicOptions& o) { o.residual_tol_rel = -1.0; });
  expect_bad("residual_tol_rel", [](DynamicOptions& o) { o.residual_tol_rel = 0.0; });
  expect_bad("residual_tol_abs", [](DynamicOptions& o) { o.residual_tol_abs = -1.0; });
  expect_bad("divergence_factor", [](DynamicOptions& o) { o.divergence_factor = 1.0; });
  expect_bad("max_line_search", [](DynamicOptions& o) { o.max_line_search = -1; });
  // An inactive integrator's parameters are not checked.
  DynamicOptions o;
  o.hht_alpha = 5.0;
  EXPECT_NO_THROW(o.validate());
  // solve_dynamic validates too.
  const PlyCase s = make_setup();
  o.rho_inf = 2.0;
  EXPECT_THROW(solve_dynamic(*s.model, s.mass, s.X, VecX::Zero(s.X.size()), {}, {}, o), InputError);

  EXPECT_THROW(parse_integrator("central-difference", "case.yaml:3:5"), InputError);
  try {
    parse_integrator("x", "case.yaml:3:5");
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("case.yaml:3:5"));
  }
  EXPECT_THROW(mass_matrix(*s.model, {}), InputError);
  EXPECT_THROW(mass_matrix(*s.model, {-1.0}), InputError);
  try {
    mass_matrix(*s.model, {std::nan("")});
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("mass matrix density"));
  }
}

}  // namespace
}  // namespace sf::forming

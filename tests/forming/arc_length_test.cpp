// Arc-length continuation through a limit point: a long thin tube (plane strain,
// compressible neo-Hookean) inflated by a follower pressure on its inner face. The
// pressure rises to a maximum and falls while the tube keeps growing; load control
// cannot pass the maximum, the arc length must. Reference: the exact plane-strain
// solution of the radial equilibrium ODE (shooting with RK4, converged to 1e-10),
// so the comparison measures the discretisation (cubic Hermite around, linear through
// the wall) and the solver, not a thin-wall approximation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <memory>
#include <random>
#include <vector>

#include "common/core/error.hpp"
#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/solve/arc_length.hpp"
#include "forming/model/loads.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/case/reader.hpp"
#include "forming/run/run.hpp"
#include "forming/solve/stabilisation.hpp"
#include "forming/solve/static_solver.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {
namespace {

constexpr double kMu = 1.0, kLambda = 10.0;  // MPa
constexpr double kA = 1.0, kB = 1.02;        // inner and outer reference radius, mm

// Nominal radial and hoop stress of W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2
// with stretches (lr, lt, 1).
double p_r(double lr, double lt) { return kMu * (lr - 1 / lr) + kLambda * std::log(lr * lt) / lr; }
double p_t(double lr, double lt) { return kMu * (lt - 1 / lt) + kLambda * std::log(lr * lt) / lt; }

// r'' from radial equilibrium d P_r/dR + (P_r - P_t)/R = 0.
double accel(double R, double r, double s) {
  const double lr = s, lt = r / R;
  const double dpr_dlr = kMu * (1 + 1 / (lr * lr)) + kLambda * (1 - std::log(lr * lt)) / (lr * lr);
  const double dpr_dlt = kLambda / (lr * lt);
  return ((p_t(lr, lt) - p_r(lr, lt)) / R - dpr_dlt * (s - r / R) / R) / dpr_dlr;
}

// Integrates from A with r = lambda_a A, r' = s; returns P_r at B.
double shoot(double lambda_a, double s) {
  const int n = 400;
  const double h = (kB - kA) / n;
  double R = kA, r = lambda_a * kA, v = s;
  for (int i = 0; i < n; ++i) {
    const double k1r = v, k1v = accel(R, r, v);
    const double k2r = v + 0.5 * h * k1v, k2v = accel(R + 0.5 * h, r + 0.5 * h * k1r, v + 0.5 * h * k1v);
    const double k3r = v + 0.5 * h * k2v, k3v = accel(R + 0.5 * h, r + 0.5 * h * k2r, v + 0.5 * h * k2v);
    const double k4r = v + h * k3v, k4v = accel(R + h, r + h * k3r, v + h * k3v);
    r += h / 6 * (k1r + 2 * k2r + 2 * k3r + k4r);
    v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    R += h;
  }
  return p_r(v, r / kB);
}

// Exact inner pressure for inner hoop stretch lambda_a (secant on r'(A)).
double exact_pressure(double lambda_a) {
  double s0 = 1.0 / lambda_a, s1 = 1.01 / lambda_a;
  double f0 = shoot(lambda_a, s0), f1 = shoot(lambda_a, s1);
  for (int it = 0; it < 60 && std::abs(f1) > 1e-13; ++it) {
    const double s2 = s1 - f1 * (s1 - s0) / (f1 - f0);
    s0 = s1, f0 = f1, s1 = s2, f1 = shoot(lambda_a, s1);
  }
  // Cauchy sigma_rr(a) = -p and P_r = lambda_t sigma_rr (lambda_z = 1).
  return -p_r(s1, lambda_a) / lambda_a;
}

struct Tube {
  Model model;
  std::vector<PrescribedDof> fixed;
  LoadSet loads;
};

Tube make_tube(int n1, double a, double b, double span, bool arch);

// A quarter of the tube (symmetry planes x = 0 and y = 0), n1 elements around, one
// along z (plane strain: every z parameter held, and x, y independent of z).
Tube make_tube(int n1) { return make_tube(n1, kA, kB, 0.5 * kPi, false); }

// Builder for the quarter tube and for a clamped shallow arch (span in radians).
Tube make_tube(int n1, double a, double b, double span, bool arch) {
  const double rm = 0.5 * (a + b), length = span * rm, depth = 0.1;
  mesh::SurfaceMesh s = mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), length, depth, n1, 1);
  const MatX flat = s.geometry();
  MatX bottom = MatX::Zero(flat.rows(), 3), top = bottom;
  for (Index node = 0; node < s.n_nodes(); ++node) {
    const double th = flat(4 * node, 0) / rm, z = flat(4 * node, 1);
    for (auto [layer, r] : {std::pair<MatX*, double>{&bottom, a}, {&top, b}}) {
      layer->row(4 * node) = Vec3(r * std::cos(th), r * std::sin(th), z).transpose();
      layer->row(4 * node + 1) = Vec3(-r / rm * std::sin(th), r / rm * std::cos(th), 0.0).transpose();
      layer->row(4 * node + 2) = Vec3(0.0, 0.0, 1.0).transpose();
    }
  }
  Tube t;
  PlyMesh ply(std::move(s), bottom, top, b - a, 0.0);
  const Index ns = ply.n_surface_nodes();
  t.model.add_ply(std::move(ply), std::make_shared<NeoHookean>(NeoHookeanParams{kMu, kLambda}));
  const VecX X = t.model.reference_positions();
  auto fix = [&](Index node, int d, int c) {
    t.fixed.push_back({t.model.dof(0, node, d, c), X(t.model.dof(0, node, d, c))});
  };
  for (Index node = 0; node < 2 * ns; ++node) {
    for (int d = 0; d < 4; ++d) fix(node, d, 2);
    for (int c = 0; c < 2; ++c) {
      fix(node, 2, c);
      fix(node, 3, c);
    }
    const Index i = (node % ns) % (n1 + 1);
    if (arch) {  // both ends clamped
      if (i == 0 || i == n1)
        for (int c = 0; c < 2; ++c) {
          fix(node, 0, c);
          fix(node, 1, c);
        }
      continue;
    }
    if (i == 0) {  // plane y = 0
      fix(node, 0, 1);
      fix(node, 1, 0);
    }
    if (i == n1) {  // plane x = 0
      fix(node, 0, 0);
      fix(node, 1, 1);
    }
  }
  PressureLoad p;
  for (Index e = 0; e < t.model.ply(0).n_elements(); ++e)
    p.faces.push_back({0, e, arch ? BrickFace::kTop : BrickFace::kBottom});
  p.pressure = 1.0;  // the load factor is the pressure in MPa
  p.follower = true;
  t.loads.pressures.push_back(p);
  return t;
}

TEST(ArcLength, ExactTubeReferenceRisesTowardsItsAsymptote) {
  // Plane strain: the pressure rises monotonically towards mu ln(B/A)-like values (no
  // limit point, unlike a sphere or a free-ended tube).
  double last = 0.0;
  for (double l = 1.05; l < 2.6; l += 0.05) {
    const double p = exact_pressure(l);
    EXPECT_GT(p, last);
    last = p;
  }
  EXPECT_LT(last, 1.05 * kMu * std::log(kB / kA));
}

TEST(ArcLength, FollowerPressureInflationOfATubeMatchesTheExactSolution) {
  Tube t = make_tube(8);
  const LoadFunction load = [&](double lambda, const VecX& x, bool want_tangent) {
    return t.loads.assemble(t.model, x, lambda, want_tangent);
  };
  ArcLengthOptions o;
  o.arc_length = 0.02;
  o.max_arc = 0.2;
  o.max_steps = 300;
  const Index probe = t.model.dof(0, 0, 0, 0);  // inner radius at theta = 0
  const ArcLengthResult r = solve_arc_length(t.model, t.model.reference_positions(), t.fixed, load, true, o,
                                             [&](const ArcLengthPoint& pt) { return pt.x(probe) / kA > 2.6; });
  ASSERT_TRUE(r.ok()) << r.message;
  double max_rel = 0.0;
  int compared = 0;
  for (const ArcLengthPoint& pt : r.path) {
    const double la = pt.x(probe) / kA;
    if (la < 1.02) continue;
    const double exact = exact_pressure(la);
    max_rel = std::max(max_rel, std::abs(pt.lambda - exact) / exact);
    ++compared;
  }
  EXPECT_GT(compared, 10);
  EXPECT_LT(max_rel, 1e-3);
  std::printf("tube inflation to lambda_a 2.6: %zu points, %d cut-backs; max |p - exact|/exact %.2e\n", r.path.size(),
              r.n_cutbacks, max_rel);
}

// A clamped shallow arch under a follower pressure snaps through: the pressure passes
// a maximum (limit point) and falls while the crown keeps moving down, then rises
// again on the inverted branch. Load control stops at the maximum; arc length follows
// the path. Checked: a maximum is passed, every point is in equilibrium to the
// tolerance, and a load-controlled solve past the maximum fails.
TEST(ArcLength, ShallowArchSnapsThroughItsLimitPoint) {
  const double radius = 10.0, h = 0.05, span = 0.4;  // rise R (1 - cos 0.2) = 0.2 mm = 4 h
  Tube t = make_tube(8, radius, radius + h, span, true);
  const LoadFunction load = [&](double lambda, const VecX& x, bool want_tangent) {
    return t.loads.assemble(t.model, x, lambda, want_tangent);
  };
  ArcLengthOptions o;
  o.arc_length = 0.01;
  o.max_arc = 0.05;
  o.max_steps = 400;
  // Crown: bottom node in the middle of the arch (n1 = 8: surface node 4), y component.
  const Index crown = t.model.dof(0, 4, 0, 0);
  const VecX X = t.model.reference_positions();
  const ArcLengthResult r = solve_arc_length(t.model, X, t.fixed, load, true, o, [&](const ArcLengthPoint& pt) {
    return X(crown) - pt.x(crown) > 0.5;  // well past the inverted position
  });
  ASSERT_TRUE(r.ok()) << r.message;
  // The limit point: the last point before the pressure first falls.
  double p_max = 0.0, p_min_after = 1e30, crown_at_max = 0.0;
  bool passed = false;
  for (const ArcLengthPoint& pt : r.path) {
    if (std::getenv("SF_ARCH_PATH")) std::printf("%g %g\n", X(crown) - pt.x(crown), pt.lambda);
    if (!passed && pt.lambda >= p_max) {
      p_max = pt.lambda;
      crown_at_max = X(crown) - pt.x(crown);
    } else {
      passed = true;
      p_min_after = std::min(p_min_after, pt.lambda);
    }
    EXPECT_LT(pt.residual, 1e-8) << "equilibrium at every point";
  }
  EXPECT_GT(p_max, 0.0);
  EXPECT_TRUE(passed);
  EXPECT_LT(p_min_after, 0.8 * p_max) << "the pressure should fall after the limit point";
  EXPECT_GT(r.path.back().lambda, p_max) << "and rise again on the inverted branch";
  // Load control to 1.05 times the limit pressure cannot converge (no equilibrium near).
  StaticOptions so;
  so.initial_increment = 0.1;
  so.min_increment = 1e-3;
  so.max_steps = 200;
  const LoadFunction beyond = [&](double lambda, const VecX& x, bool want_tangent) {
    return t.loads.assemble(t.model, x, 1.05 * p_max * lambda, want_tangent);
  };
  const StaticResult s = solve_static(t.model, X, t.fixed, beyond, true, so);
  EXPECT_FALSE(s.report.ok());
  EXPECT_NEAR(s.report.load_factor * 1.05 * p_max, p_max, 0.02 * p_max) << "load control stalls at the limit point";
  std::printf(
      "shallow arch: limit pressure %.6g MPa at crown deflection %.4f mm, falls to %.3g of it; %zu points, "
      "%d cut-backs; load control to 1.05 p_limit stalls at %.4f p_limit\n",
      p_max, crown_at_max, p_min_after / p_max, r.path.size(), r.n_cutbacks, s.report.load_factor * 1.05);
}

// The diaphragm-inflation sample (control: arc_length in the case file): the load
// factor rises to a maximum and falls while the bulge grows; the run ends at the
// requested displacement, converged.
TEST(ArcLength, DiaphragmSamplePassesThePressureMaximum) {
  const FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/diaphragm_inflation.yaml");
  RunOptions o;
  o.quiet = true;
  o.out_dir = (std::filesystem::temp_directory_path() / "sf_arc_diaphragm").string();
  const RunReport r = run_case(spec, o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_GE(r.max_displacement.norm(), 150.0);
  std::ifstream h(o.out_dir + "/history.csv");
  std::string line;
  std::getline(h, line);  // header
  double peak = 0.0, last = 0.0;
  while (std::getline(h, line)) {
    const double lam = std::stod(line.substr(line.find(',') + 1));
    peak = std::max(peak, lam);
    last = lam;
  }
  EXPECT_GT(peak, 0.5);
  EXPECT_LT(last, 0.8 * peak);
  std::printf("diaphragm: peak load factor %.4f (%.4f MPa), %.4f at 150 mm\n", peak, 0.02 * peak, last);
  std::filesystem::remove_all(o.out_dir);
}

// ---- Viscous stabilisation (forming/solve/stabilisation.hpp) on the same arch ----------
//
// Load control with F_v = c M* (x - x_prev) / dt added: below the limit point the result
// is the static one up to the dissipated fraction; past it the arch snaps onto its
// inverted branch, which the arc-length path locates independently.

// The clamped shallow arch of ShallowArchSnapsThroughItsLimitPoint.
Tube make_arch() { return make_tube(8, 10.0, 10.05, 0.4, true); }
Index arch_crown(const Model& model) { return model.dof(0, 4, 0, 0); }

// Its arc-length path (crown deflection, pressure in MPa) through the limit point to a
// crown deflection of 0.5 mm, computed once.
const std::vector<std::pair<double, double>>& arch_path() {
  static const std::vector<std::pair<double, double>> path = [] {
    Tube t = make_arch();
    const LoadFunction load = [&](double lambda, const VecX& x, bool want_tangent) {
      return t.loads.assemble(t.model, x, lambda, want_tangent);
    };
    ArcLengthOptions o;
    o.arc_length = 0.01;
    o.max_arc = 0.05;
    o.max_steps = 400;
    const Index crown = arch_crown(t.model);
    const VecX X = t.model.reference_positions();
    const ArcLengthResult r = solve_arc_length(t.model, X, t.fixed, load, true, o,
                                               [&](const ArcLengthPoint& pt) { return X(crown) - pt.x(crown) > 0.5; });
    std::vector<std::pair<double, double>> out;
    if (r.ok())
      for (const ArcLengthPoint& pt : r.path) out.emplace_back(X(crown) - pt.x(crown), pt.lambda);
    return out;
  }();
  return path;
}

double arch_limit_pressure() {
  double p_max = 0.0;
  for (const auto& [w, p] : arch_path()) {
    if (p < p_max) break;
    p_max = p;
  }
  return p_max;
}

// Crown deflection on the inverted branch (after the pressure's minimum) at pressure p,
// interpolated along the arc-length path; < 0 when the path does not reach p there.
double inverted_branch_deflection(double p) {
  const auto& path = arch_path();
  std::size_t k = 1;
  while (k < path.size() && path[k].second <= path[k - 1].second) ++k;  // rising to the limit
  while (k < path.size() && path[k].second >= path[k - 1].second) ++k;
  while (k < path.size() && path[k].second < path[k - 1].second) ++k;  // falling to the minimum
  for (; k < path.size(); ++k)
    if (path[k - 1].second <= p && p <= path[k].second) {
      const double t = (p - path[k - 1].second) / (path[k].second - path[k - 1].second);
      return path[k - 1].first + t * (path[k].first - path[k - 1].first);
    }
  return -1.0;
}

// The arch as a Problem for the load stepper: ends held, the follower pressure following
// `table` (MPa against the load factor).
Problem arch_problem(const LoadTable& table) {
  Tube t = make_arch();
  Problem p;
  p.model = std::move(t.model);
  for (const PrescribedDof& f : t.fixed) p.prescriptions.add(Prescription{f.dof, f.value, 0.0, Ramp::kLinear});
  p.loads.add(table, std::move(t.loads));
  p.density.assign(1, 0.0);
  return p;
}

// Keeps every converged step.
struct Steps final : StepObserver {
  std::vector<StepInfo> info;
  std::vector<VecX> x;
  StepAction on_step(const StepInfo& step, const SteppingState& state, const VecX&) override {
    info.push_back(step);
    x.push_back(state.x);
    return StepAction::kContinue;
  }
};

struct StepperRun {
  SteppingReport report;
  Steps steps;
  double crown = 0.0;         // deflection at the last converged step, mm
  double static_residual = 0.0;  // |f_int - f_ext| on the free dofs there, relative to |f_ext|
};

StepperRun run_arch(const LoadTable& table, int steps, const StabiliseOptions& stabilise) {
  Problem p = arch_problem(table);
  StepperSettings s;
  s.steps = steps;
  s.statics.max_iterations = 30;
  s.statics.max_steps = 4000;
  s.stabilise = stabilise;
  StepperRun out;
  SteppingState state{p.model.reference_positions(), VecX::Zero(p.model.n_dofs()), 0.0};
  out.report = make_stepper(p, s)->run(state, out.steps);
  const VecX X = p.model.reference_positions();
  out.crown = X(arch_crown(p.model)) - state.x(arch_crown(p.model));
  // The static residual without the stabilisation: interactions other than it (none here).
  const Assembly a = p.model.assemble(state.x, false);
  const ExternalLoad f = p.loads.at(p.model, state.load_factor, state.x, false);
  std::vector<bool> held(static_cast<std::size_t>(p.model.n_dofs()), false);
  for (const PrescribedDof& d : p.prescriptions.at(state.load_factor)) held[static_cast<std::size_t>(d.dof)] = true;
  VecX r = a.force - f.force;
  for (Index d = 0; d < r.size(); ++d)
    if (held[static_cast<std::size_t>(d)]) r(d) = 0.0;
  out.static_residual = r.norm() / std::max(f.force.norm(), 1e-300);
  return out;
}

// Below the limit point (half the limit pressure in 5 steps): with Abaqus' default
// fraction the stabilised result is the static one to 1e-4 and it dissipates about
// that fraction of the strain energy.
TEST(Stabilisation, BelowTheLimitPointTheStabilisedArchIsTheStaticOne) {
  const double p_max = arch_limit_pressure();
  ASSERT_GT(p_max, 0.0);
  const LoadTable table{{0.0, 1.0}, {0.0, 0.5 * p_max}};
  const StepperRun plain = run_arch(table, 5, {});
  StabiliseOptions st;
  st.fraction = 2e-4;
  const StepperRun stab = run_arch(table, 5, st);
  ASSERT_EQ(plain.report.status, SteppingReport::Status::kFinished) << plain.report.message;
  ASSERT_EQ(stab.report.status, SteppingReport::Status::kFinished) << stab.report.message;
  ASSERT_EQ(stab.steps.info.size(), 5u);
  const StepInfo& last = stab.steps.info.back();
  EXPECT_TRUE(last.stabilised);
  EXPECT_GT(last.damping, 0.0) << "c calibrated from step 1";
  // The strain energy of the last state: 1/2 p.. measured through the model.
  Problem p = arch_problem(table);
  const double strain = p.model.assemble(stab.steps.x.back(), false).strain_energy;
  const double ratio = last.stabilisation_energy / strain;
  EXPECT_GT(ratio, 0.0);
  EXPECT_LT(ratio, 2e-3) << "a few times the fraction over five steps";
  EXPECT_NEAR(stab.crown, plain.crown, 1e-4 * plain.crown);
  // The viscous force at the end of each step is what separates the two.
  EXPECT_LT(stab.static_residual, 1e-3);
  std::printf(
      "stabilised arch below the limit: crown %.9f mm (static %.9f), c %.3g N s/mm^4, dissipated %.3g N mm = %.3g "
      "of the strain energy, static residual %.2g\n",
      stab.crown, plain.crown, last.damping, last.stabilisation_energy, ratio, stab.static_residual);
}

// Past the limit point: the pressure rises to 1.02 p_max in 10 steps and is then held
// for 10. Load control alone fails at the limit; stabilised, the arch snaps onto its
// inverted branch, and once the pressure is held the viscous force dies away: the crown
// agrees with the arc-length path's inverted branch at that pressure.
TEST(Stabilisation, StabilisedLoadControlSnapsTheArchOntoItsInvertedBranch) {
  const double p_max = arch_limit_pressure();
  ASSERT_GT(p_max, 0.0);
  const double p = 1.02 * p_max;
  const double w_ref = inverted_branch_deflection(p);
  ASSERT_GT(w_ref, 0.0) << "the arc-length path reaches " << p << " MPa on the inverted branch";
  const LoadTable table{{0.0, 0.5, 1.0}, {0.0, p, p}};
  const StepperRun plain = run_arch(table, 20, {});
  EXPECT_EQ(plain.report.status, SteppingReport::Status::kFailed) << "load control stops at the limit point";
  StabiliseOptions st;
  st.fraction = 2e-4;
  const StepperRun stab = run_arch(table, 20, st);
  ASSERT_EQ(stab.report.status, SteppingReport::Status::kFinished) << stab.report.message;
  EXPECT_NEAR(stab.crown, w_ref, 0.01 * w_ref);
  EXPECT_LT(stab.static_residual, 1e-4) << "held: the viscous force has died away";
  // The snap released energy the stabilisation took: its ratio says so.
  Problem pr = arch_problem(table);
  const double strain = pr.model.assemble(stab.steps.x.back(), false).strain_energy;
  const double ratio = stab.steps.info.back().stabilisation_energy / strain;
  EXPECT_GT(ratio, 0.05) << "a snap is not quasi-static: the run should warn";
  int cutbacks = 0;
  for (const StepInfo& i : stab.steps.info) cutbacks += i.cutbacks;
  std::printf(
      "stabilised arch past the limit (%.5g MPa = 1.02 p_max): crown %.5f mm, arc-length inverted branch %.5f mm; "
      "unstabilised: %s; %d Newton iterations, %d cut-backs; dissipated %.3g of the strain energy; static "
      "residual %.2g\n",
      p, stab.crown, w_ref, plain.report.step_failure.c_str(), stab.report.total_iterations, cutbacks, ratio,
      stab.static_residual);
}

// The added tangent (c / dt) M* against central differences of the added force, its
// symmetry, the dissipation F_v . dx, and M* as the volume for a rigid translation.
TEST(Stabilisation, TangentForceAndDissipationAreConsistent) {
  Tube t = make_arch();
  const double c = 0.37, t0 = 0.1, t1 = 0.35;
  ViscousStabilisation s(t.model, c);
  const Index n = t.model.n_dofs();
  const VecX X = t.model.reference_positions();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  VecX prev = X, x = X;
  for (Index d = 0; d < n; ++d) {
    prev(d) += u(rng);
    x(d) += 10 * u(rng);
  }
  const InteractionContext ctx{t1, nullptr, &prev, t0};
  auto force = [&](const VecX& at, linalg::TripletAssembler* k) {
    InteractionSums sums;
    sums.force = VecX::Zero(n);
    sums.stiffness = k;
    s.add_to(at, ctx, sums);
    EXPECT_TRUE(sums.ok);
    EXPECT_EQ(sums.energy, 0.0);
    return sums.force;
  };
  linalg::TripletAssembler k(n, n);
  const VecX f = force(x, &k);
  const MatX K = MatX(k.compress());
  // The force is c M* v with v = (x - prev) / dt.
  EXPECT_LT((f - c * (s.mass() * (x - prev)) / (t1 - t0)).norm(), 1e-12 * f.norm());
  MatX fd(n, n);
  const double h = 1e-6;
  for (Index j = 0; j < n; ++j) {
    VecX xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    fd.col(j) = (force(xp, nullptr) - force(xm, nullptr)) / (2 * h);
  }
  EXPECT_LT((K - fd).cwiseAbs().maxCoeff(), 1e-7 * K.cwiseAbs().maxCoeff());
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-14 * K.cwiseAbs().maxCoeff());
  EXPECT_NEAR(f.dot(x - prev), s.dissipation(prev, x, t1 - t0), 1e-12 * f.dot(x - prev));
  // Rigid translation along x: u^T M* u is the arch's volume (unit density).
  VecX e = VecX::Zero(n);
  for (Index node = 0; node < t.model.ply(0).n_nodes(); ++node) e(t.model.dof(0, node, 0, 0)) = 1.0;
  const double volume = 0.4 * 10.025 * 0.05 * 0.1;  // span x mean radius x wall x depth, mm^3
  EXPECT_NEAR(s.mass_norm(e), volume, 1e-6 * volume);
  // Nothing without rates (the arc-length and dynamic solvers' contexts) or with c = 0.
  InteractionSums none;
  none.force = VecX::Zero(n);
  s.add_to(x, InteractionContext{}, none);
  EXPECT_EQ(none.force.norm(), 0.0);
  ViscousStabilisation off(t.model);
  off.add_to(x, ctx, none);
  EXPECT_EQ(none.force.norm(), 0.0);
  EXPECT_THROW(s.set_damping(-1.0), InputError);
  StabiliseOptions both;
  both.fraction = 2e-4;
  both.damping = 1.0;
  EXPECT_THROW(both.validate(), InputError);
}

TEST(ArcLength, BadOptionsAreInputErrors) {
  ArcLengthOptions o;
  o.arc_length = -1.0;
  EXPECT_THROW(o.validate(), InputError);
  o = ArcLengthOptions{};
  o.max_arc = 0.01;
  EXPECT_THROW(o.validate(), InputError);
}

}  // namespace
}  // namespace sf::forming

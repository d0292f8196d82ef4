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
#include "forming/solve/static_solver.hpp"

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

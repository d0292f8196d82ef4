// External loads (forming/model/loads.hpp): follower pressure and its load-correction
// tangent against finite differences, totals of dead loads, and the closed form of a
// block under pressure (follower pressure is a CAUCHY traction: sigma_33 = -p on the
// current face; a dead pressure is a nominal one).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include "common/core/error.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/model/loads.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/case/reader.hpp"
#include "forming/run/run.hpp"
#include "forming/solve/static_solver.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

Model block_model(double lx, double ly, double h, int n1, int n2, double mu = 1.0, double lambda = 2.0) {
  return fixtures::one_ply_model(fixtures::rectangle_ply(lx, ly, h, n1, n2), fixtures::neo_hookean(mu, lambda));
}

std::vector<FaceRef> all_faces(const Model& model, BrickFace face) {
  std::vector<FaceRef> out;
  for (Index e = 0; e < model.ply(0).n_elements(); ++e) out.push_back({0, e, face});
  return out;
}

// A smooth non-uniform deformation of the reference positions (all parameters perturbed).
VecX perturbed(const Model& model, double amount) {
  VecX x = model.reference_positions();
  for (Index i = 0; i < x.size(); ++i) x(i) += amount * std::sin(1.7 * static_cast<double>(i) + 0.3);
  return x;
}

TEST(Loads, FollowerPressureTangentMatchesFiniteDifferences) {
  const Model model = block_model(2.0, 1.5, 0.4, 2, 1);
  LoadSet loads;
  std::vector<FaceRef> faces = all_faces(model, BrickFace::kTop);
  for (BrickFace f : {BrickFace::kBottom, BrickFace::kXi1Max, BrickFace::kXi2Min}) faces.push_back({0, 1, f});
  loads.pressures.push_back({faces, 0.7, true});
  ASSERT_TRUE(loads.has_follower());
  const VecX x = perturbed(model, 0.05);
  const ExternalLoad l = loads.assemble(model, x, 1.0, true);
  const MatX k = MatX(l.tangent);
  const double h = 1e-6;
  double max_err = 0.0, max_k = 0.0;
  for (Index j = 0; j < x.size(); ++j) {
    VecX xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    const VecX fd =
        (loads.assemble(model, xp, 1.0, false).force - loads.assemble(model, xm, 1.0, false).force) / (2 * h);
    max_err = std::max(max_err, (fd - k.col(j)).lpNorm<Eigen::Infinity>());
    max_k = std::max(max_k, k.col(j).lpNorm<Eigen::Infinity>());
  }
  EXPECT_GT(max_k, 0.01);
  EXPECT_LT(max_err, 1e-8 * std::max(1.0, max_k)) << "max |K - FD| " << max_err << " of max |K| " << max_k;
}

TEST(Loads, PressureOnAFlatPlyGivesPressureTimesAreaAgainstTheNormal) {
  const Model model = block_model(3.0, 2.0, 0.5, 3, 2);
  const VecX X = model.reference_positions();
  for (bool follower : {true, false}) {
    LoadSet loads;
    loads.pressures.push_back({all_faces(model, BrickFace::kTop), 0.25, follower});
    const VecX f = loads.assemble(model, X, 2.0, false).force;
    Vec3 total = Vec3::Zero();
    const PlyMesh& ply = model.ply(0);
    for (Index n = 0; n < ply.n_nodes(); ++n)
      for (int c = 0; c < 3; ++c) total[c] += f(model.dof(0, n, 0, c));  // value parameters carry the resultant
    EXPECT_NEAR(total.z(), -2.0 * 0.25 * 6.0, 1e-12);
    EXPECT_NEAR(total.x(), 0.0, 1e-12);
    EXPECT_NEAR(total.y(), 0.0, 1e-12);
  }
  EXPECT_NEAR(face_area(model, all_faces(model, BrickFace::kTop), X), 6.0, 1e-12);
  EXPECT_NEAR(face_area(model, {{0, 0, BrickFace::kXi1Min}}, X), 1.0 * 0.5, 1e-12);
}

TEST(Loads, BodyForceAndTractionTotals) {
  const Model model = block_model(3.0, 2.0, 0.5, 3, 2);
  const VecX X = model.reference_positions();
  LoadSet loads;
  loads.body_forces.push_back({0, Vec3(0.0, 0.0, -9.81e-6)});
  std::vector<FaceRef> side;
  for (Index e : {2, 5}) side.push_back({0, e, BrickFace::kXi1Max});  // the x = 3 side
  loads.tractions.push_back({side, Vec3(0.1, 0.0, -0.2)});
  loads.nodal.push_back({model.dof(0, 0, 0, 1), 0.5});
  const VecX f = loads.assemble(model, X, 1.0, false).force;
  Vec3 total = Vec3::Zero();
  for (Index n = 0; n < model.ply(0).n_nodes(); ++n)
    for (int c = 0; c < 3; ++c) total[c] += f(model.dof(0, n, 0, c));
  const double volume = 3.0 * 2.0 * 0.5, side_area = 2.0 * 0.5;
  EXPECT_NEAR(total.x(), 0.1 * side_area, 1e-12);
  EXPECT_NEAR(total.y(), 0.5, 1e-12);
  EXPECT_NEAR(total.z(), -9.81e-6 * volume - 0.2 * side_area, 1e-12);
  EXPECT_FALSE(loads.has_follower());
  EXPECT_EQ(loads.assemble(model, X, 1.0, true).tangent.size(), 0);
}

TEST(Loads, BadReferencesAreInputErrors) {
  const Model model = block_model(1.0, 1.0, 0.5, 1, 1);
  LoadSet loads;
  loads.pressures.push_back({{{0, 7, BrickFace::kTop}}, 1.0, true});
  EXPECT_THROW(loads.assemble(model, model.reference_positions(), 1.0, false), InputError);
  LoadSet nodal;
  nodal.nodal.push_back({model.n_dofs(), 1.0});
  EXPECT_THROW(nodal.assemble(model, model.reference_positions(), 1.0, false), InputError);
}

// Uniaxial compression of a free block by a pressure on its top face; bottom on the
// plane z = 0 (may slide), rigid motions removed. The solution is homogeneous; the
// Cauchy stress must be sigma_33 = -p (follower) or sigma_33 J / (F11 F22) = -p (dead
// pressure = nominal traction), with the lateral stresses zero.
struct BlockSolution {
  Mat3 F;
  Mat3 sigma;
  int iterations;
};

BlockSolution compress_block(double p, bool follower) {
  const Model model = block_model(2.0, 2.0, 1.0, 2, 2, 1.0, 2.0);
  const PlyMesh& ply = model.ply(0);
  const VecX X = model.reference_positions();
  std::vector<PrescribedDof> fixed;
  for (Index s = 0; s < ply.n_surface_nodes(); ++s)
    for (int d = 0; d < 4; ++d)
      fixed.push_back({model.dof(0, ply.node(s, 0), d, 2), X(model.dof(0, ply.node(s, 0), d, 2))});
  // Node 0 (origin) fixed in x, y on both layers; node 2 (x = 2, y = 0) in y.
  for (int layer = 0; layer < 2; ++layer) {
    fixed.push_back({model.dof(0, ply.node(0, layer), 0, 0), 0.0});
    fixed.push_back({model.dof(0, ply.node(0, layer), 0, 1), 0.0});
    fixed.push_back({model.dof(0, ply.node(2, layer), 0, 1), 0.0});
  }
  LoadSet loads;
  loads.pressures.push_back({all_faces(model, BrickFace::kTop), p, follower});
  const LoadFunction fn = [&](double lambda, const VecX& x, bool want_tangent) {
    return loads.assemble(model, x, lambda, want_tangent);
  };
  StaticOptions so;
  so.initial_increment = 0.25;
  const StaticResult r = solve_static(model, X, fixed, fn, loads.has_follower(), so);
  EXPECT_TRUE(r.report.ok()) << r.report.brief();
  const std::vector<Mat3> fs = model.deformation_gradients(0, r.positions);
  BlockSolution out;
  out.F = fs.front();
  for (const Mat3& f : fs) EXPECT_LT((f - out.F).norm(), 1e-9) << "not homogeneous";
  const MaterialResponse m = model.material(0).evaluate(out.F.transpose() * out.F, false);
  out.sigma = out.F * m.stress * out.F.transpose() / out.F.determinant();
  out.iterations = r.report.total_iterations;
  return out;
}

TEST(Loads, FollowerPressureIsACauchyTractionOnTheCurrentFace) {
  const double p = 0.6;  // MPa with mu = 1: about 25 % compression
  const BlockSolution s = compress_block(p, true);
  EXPECT_LT(s.F(2, 2), 0.8);
  EXPECT_NEAR(s.sigma(2, 2), -p, 1e-9);
  EXPECT_NEAR(s.sigma(0, 0), 0.0, 1e-9);
  EXPECT_NEAR(s.sigma(1, 1), 0.0, 1e-9);
  const BlockSolution d = compress_block(p, false);
  // Dead pressure: force p * reference area on the current area F11 F22.
  EXPECT_NEAR(d.sigma(2, 2) * d.F(0, 0) * d.F(1, 1), -p, 1e-9);
  EXPECT_GT(std::abs(d.F(2, 2) - s.F(2, 2)), 1e-3) << "follower and dead pressure should differ at finite strain";
  std::printf("block under p = %.2f: follower F33 = %.6f sigma33 = %.12f (%d Newton); dead F33 = %.6f\n", p, s.F(2, 2),
              s.sigma(2, 2), s.iterations, d.F(2, 2));
}

// The free-bending sample (data/forming/free_bending.yaml): a clamped strip under its
// own weight. The clamp carries the weight exactly; the tip deflection is within a few
// per cent of Timoshenko beam theory, q L^4 / (8 E_f I) + q L^2 / (2 G_L b h) (the 3-D
// continuum has no shear-correction factor to choose and a compressible cross-section).
TEST(Loads, GravityCantileverSampleCarriesItsWeightAndSagsLikeABeam) {
  const FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/free_bending.yaml");
  RunOptions o;
  o.out_dir = (std::filesystem::temp_directory_path() / "sf_loads_free_bending").string();
  o.quiet = true;
  const RunReport r = run_case(spec, o);
  ASSERT_TRUE(r.ok()) << r.message;
  const double b = 20.0, h = 1.0, L = 200.0, rho = 1.5e-9, g = 9810.0;
  const double q = rho * g * b * h, weight = q * L;
  EXPECT_NEAR(r.tool_force.z(), weight, 1e-6 * weight);  // the clamp's reaction, to the Newton tolerance
  const double EI = 25000.0 * b * h * h * h / 12.0, GA = 0.5 * b * h;
  const double beam = q * std::pow(L, 4) / (8.0 * EI) + q * L * L / (2.0 * GA);
  const double tip = -r.max_displacement.z();
  EXPECT_NEAR(tip, beam, 0.03 * beam);
  std::printf("free bending: tip %.4f mm, beam theory %.4f mm (%.2f %%), reaction %.6g N (weight %.6g N)\n", tip, beam,
              100.0 * (tip - beam) / beam, r.tool_force.z(), weight);
  std::filesystem::remove_all(o.out_dir);
}

}  // namespace
}  // namespace sf::forming

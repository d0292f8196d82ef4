// Tied faces (forming/model/tied_faces.hpp), the vacuum's grip as a tie
// (`diaphragms: {vacuum: {hold: tie}}`):
//  * a rigid motion of both plies costs nothing; sliding the upper ply by delta over the
//    lower one costs k/2 |delta|^2 A and pulls it back with k A delta (A the tied area),
//    on matching and on non-matching meshes (2 x 2 bricks on 3 x 3), and the force is the
//    gradient of the energy;
//  * the case key ties the laminate's outer faces to the diaphragms (and only those
//    pairs), a bad value is reported with its line and column; the coarse 2-D bend runs
//    with the tie and the laminate follows the sheets.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/model/tied_faces.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

// Two 4 x 3 mm plies 0.5 mm thick, the upper on the lower, meshes n x n and m x m.
Model stacked(int n, int m) {
  Model model;
  const auto law = std::make_shared<NeoHookean>(NeoHookeanParams::from_young_poisson(10.0, 0.3));
  model.add_ply(
      PlyMesh(mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 4.0, 3.0, n, n), 0.5, 0.0), law);
  model.add_ply(
      PlyMesh(mesh::make_rectangle_mesh(Vec3(0, 0, 0.5), Vec3::UnitX(), Vec3::UnitY(), 4.0, 3.0, m, m), 0.5, 0.0), law);
  return model;
}

// x with body b moved by the rigid map p -> R p + t.
VecX moved(const Model& model, const VecX& x, int b, const Mat3& R, const Vec3& t) {
  VecX out = x;
  MatX P = PlyMesh::unflatten(x.segment(model.offset(b), model.ply(b).n_dofs()));
  for (Index r = 0; r < P.rows(); ++r) {
    const bool value = r % 4 == 0;  // rows: value, d/ds1, d/ds2, d2/ds1ds2 per node
    P.row(r) = (R * P.row(r).transpose() + (value ? t : Vec3::Zero())).transpose();
  }
  out.segment(model.offset(b), model.ply(b).n_dofs()) = PlyMesh::flatten(P);
  return out;
}

TEST(TiedFaces, RigidMotionIsFreeAndSlidingCostsTheTieEnergy) {
  const double k = 50.0, A = 12.0;
  for (const auto& [n, m] : {std::pair{2, 2}, std::pair{3, 2}}) {
    const Model model = stacked(n, m);
    const TiedFaces tie("upper/lower", model, 1, false, 0, true, k);
    EXPECT_EQ(tie.paired_points(), m * m * 36);
    const VecX X = model.reference_positions();
    const auto sums_at = [&](const VecX& x) {
      InteractionSums s;
      s.force = VecX::Zero(model.n_dofs());
      tie.add_to(x, InteractionContext{}, s);
      return s;
    };
    // Rigid motion of both plies: a rotation about z and a translation.
    const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(0.2, 0.3, 1).normalized()).toRotationMatrix();
    VecX x = moved(model, moved(model, X, 0, R, Vec3(1, -2, 0.5)), 1, R, Vec3(1, -2, 0.5));
    // The rotation acts about the origin on both bodies alike.
    InteractionSums s = sums_at(x);
    EXPECT_LT(std::abs(s.energy), 1e-9) << n << " on " << m;
    EXPECT_LT(s.force.norm(), 1e-9) << n << " on " << m;
    // The upper ply slid by delta.
    const Vec3 delta(0.01, -0.02, 0.005);
    x = moved(model, X, 1, Mat3::Identity(), delta);
    s = sums_at(x);
    EXPECT_NEAR(s.energy, 0.5 * k * delta.squaredNorm() * A, 1e-10) << n << " on " << m;
    Vec3 on_upper = Vec3::Zero(), on_lower = Vec3::Zero();
    for (Index dof = 0; dof < model.n_dofs(); dof += 1) {
      const int body = dof >= model.offset(1) ? 1 : 0;
      const Index local = dof - model.offset(body);
      if ((local / 3) % 4 != 0) continue;  // value parameters carry the resultant
      (body == 1 ? on_upper : on_lower)[local % 3] += s.force(dof);
    }
    EXPECT_LT((on_upper - k * A * delta).norm(), 1e-9 * k * A * delta.norm()) << on_upper.transpose();
    EXPECT_LT((on_lower + k * A * delta).norm(), 1e-9 * k * A * delta.norm()) << on_lower.transpose();
  }
  EXPECT_THROW(TiedFaces("bad", stacked(2, 2), 0, true, 0, false, 50.0), InputError);
  EXPECT_THROW(TiedFaces("bad", stacked(2, 2), 1, false, 0, true, -1.0), InputError);
}

// The coarse double-diaphragm bend with the vacuum's grip as a tie.
std::string tie_case() {
  std::string text = fixtures::kDiaphragmBend;
  const std::string vacuum = "vacuum: {pressure: 0.02, ramp: linear}";
  return text.replace(text.find(vacuum), vacuum.size(), "vacuum: {pressure: 0.02, ramp: linear, hold: tie}");
}

TEST(TiedFaces, VacuumHoldTieTiesTheLaminateToTheDiaphragms) {
  const std::string kTie = tie_case();
  const CaseCheck c = check_case_text(kTie, "tie.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  ASSERT_EQ(c.spec.contacts.size(), 5u);
  for (std::size_t i = 0; i < c.spec.contacts.size(); ++i)
    EXPECT_EQ(c.spec.contacts[i].tie, i == 1 || i == 2) << c.spec.contacts[i].label;
  std::string bad = kTie;
  bad.replace(bad.find("hold: tie"), 9, "hold: glue");
  const CaseCheck b = check_case_text(bad, "bad.yaml");
  ASSERT_EQ(b.problems.size(), 1u);
  EXPECT_EQ(b.problems[0].place.line, 28);
  EXPECT_NE(b.problems[0].message.find("expected friction"), std::string::npos) << b.problems[0].message;
  // The coarse bend with the tie: the pack sinks into the slot.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_tied_faces_test";
  const fixtures::RunOutput out = fixtures::run_into(c.spec, dir);
  ASSERT_TRUE(out.report.ok()) << out.report.message;
  EXPECT_LT(out.report.max_displacement.z(), -0.5);
}

}  // namespace
}  // namespace sf::forming

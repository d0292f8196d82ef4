// Total Lagrangian ply elements (forming/element/element.hpp) and their assembly
// (forming/solve/static_solver.hpp Model): tangent against central finite differences of
// the internal force and force against finite differences of the energy (neo-Hookean
// and the compressible transversely isotropic law, random distorted reference and
// current states, several fibre directions), zero force in the reference state and
// under a large rigid rotation about an oblique axis, exact F under homogeneous
// deformation; the same for the plane-strain element; the assembled tangent of a
// graded ply mesh (scale factors through the element map) against finite differences.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "common/core/error.hpp"
#include "common/linalg/dense_kernels.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/element/element.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/solve/static_solver.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using fixtures::max_abs;

// ---- Named tolerances (what each bounds and why it is that size) ----------------
// Central-difference step in positions (element size O(1) mm): truncation
// h^2 f'''/6 ~ 1e-12 relative, roundoff eps |f| / h ~ 1e-10 relative.
constexpr double kFdStep = 1e-6;
// FD tangent / force against the analytic ones, relative to the largest entry
// (brief: 1e-6). Measured worst values are printed by the tests.
constexpr double kFdRel = 1e-6;
// Forces that vanish in exact arithmetic (reference state, rigid motion), relative to
// the size of the stiffness times the element size (sums of ~1e3 O(1) products).
constexpr double kZeroForceRel = 1e-12;
// F under homogeneous deformation (products of O(1) numbers).
constexpr double kExactF = 1e-12;

std::shared_ptr<const Material> neo_hookean() { return fixtures::neo_hookean(1.0, 4.0); }

std::shared_ptr<const Material> trans_iso(const Vec3& a0) {
  return std::make_shared<TransverselyIsotropic>(fixtures::ti_compressible(1.0, 3.0, 50.0, 4.0), a0);
}

// Materials under test: neo-Hookean, and the TI law at in-plane layup angles and one
// fibre out of the ply plane.
std::vector<std::shared_ptr<const Material>> materials_under_test() {
  return {neo_hookean(), trans_iso(fibre_from_layup_angle(0.0)), trans_iso(fibre_from_layup_angle(30.0)),
          trans_iso(fibre_from_layup_angle(-75.0)), trans_iso(Vec3(0.6, -0.3, 0.5))};
}

// Worst relative errors of the tangent against FD of the force and of the force
// against FD of the energy.
struct FdErrors {
  double tangent = 0.0;
  double force = 0.0;
};

template <class Params, class Eval>
FdErrors fd_errors(const Params& X, const Params& x, Eval eval) {
  const ElementResult r = eval(X, x, true);
  EXPECT_TRUE(r.ok());
  const int n = static_cast<int>(r.force.size());
  const int dim = static_cast<int>(Params::ColsAtCompileTime);
  MatX k_fd(n, n);
  VecX f_fd(n);
  for (int j = 0; j < n; ++j) {
    Params xp = x, xm = x;
    xp(j / dim, j % dim) += kFdStep;
    xm(j / dim, j % dim) -= kFdStep;
    const ElementResult rp = eval(X, xp, false), rm = eval(X, xm, false);
    k_fd.col(j) = (rp.force - rm.force) / (2.0 * kFdStep);
    f_fd(j) = (rp.energy - rm.energy) / (2.0 * kFdStep);
  }
  FdErrors e;
  e.tangent = max_abs(k_fd - r.tangent) / max_abs(r.tangent);
  e.force = max_abs(f_fd - r.force) / max_abs(r.force);
  EXPECT_LT(max_abs(r.tangent - r.tangent.transpose()), 1e-12 * max_abs(r.tangent)) << "tangent not symmetric";
  return e;
}

TEST(FormingElement, TangentAndForceMatchFiniteDifferences) {
  std::mt19937 rng(test::kSeed);
  const quadrature::TensorRule<3> rule = ElementRule{}.brick();
  double worst_k = 0.0, worst_f = 0.0;
  for (const auto& material : materials_under_test())
    for (int trial = 0; trial < 3; ++trial) {
      const BrickParams X = fixtures::distorted_brick(rng, 0.08);
      const BrickParams x = fixtures::deformed_brick(rng, X, 0.05, rule, 0.2);
      const FdErrors e = fd_errors(X, x, [&](const BrickParams& Xa, const BrickParams& xa, bool tangent) {
        return brick_element(Xa, xa, *material, rule, tangent);
      });
      EXPECT_LT(e.tangent, kFdRel) << material->name() << " trial " << trial;
      EXPECT_LT(e.force, kFdRel) << material->name() << " trial " << trial;
      worst_k = std::max(worst_k, e.tangent);
      worst_f = std::max(worst_f, e.force);
    }
  std::printf("brick: worst FD error tangent %.2e, force %.2e (relative)\n", worst_k, worst_f);
}

// The fast kernel (BrickKernel: permuted order, lower-triangle products, vector code)
// against the straightforward per-point one, on every instruction set this processor
// has, with and without constraint terms. Rounding differs (order of sums, FMA), so
// the bound is relative: 1e-12 of the largest entry.
TEST(FormingElement, FastKernelMatchesReferenceOnEveryInstructionSet) {
  std::mt19937 rng(test::kSeed + 11);
  const quadrature::TensorRule<3> rule = ElementRule{}.brick();
  const linalg::KernelIsa saved = linalg::kernel_isa();
  ConstraintTerms both;
  both.incompressible = true;
  both.kappa = 30.0;
  both.p = 0.4;
  both.inextensible = true;
  both.k_fibre = 200.0;
  both.T = -0.2;
  const BrickKernel kernel(rule);
  BrickScratch scratch;
  ElementResult fast;  // reused across calls, as the assembly does
  for (int isa = 0; isa <= static_cast<int>(linalg::best_kernel_isa()); ++isa) {
    linalg::set_kernel_isa(static_cast<linalg::KernelIsa>(isa));
    double worst = 0.0;
    for (const auto& material : materials_under_test()) {
      const BrickParams X = fixtures::distorted_brick(rng, 0.08);
      const BrickParams x = fixtures::deformed_brick(rng, X, 0.05, rule, 0.2);
      for (const ConstraintTerms& c : {ConstraintTerms{}, both}) {
        if (c.inextensible && material->fibre_direction().isZero(0.0)) continue;
        const ElementResult ref = brick_element_reference(X, x, *material, rule, true, c);
        kernel.evaluate(X, x, *material, true, c, scratch, fast);
        ASSERT_TRUE(fast.ok());
        const double k_err = max_abs(fast.tangent - ref.tangent) / max_abs(ref.tangent);
        const double f_err = max_abs(fast.force - ref.force) / max_abs(ref.force);
        EXPECT_LT(k_err, 1e-12) << material->name() << " " << linalg::to_string(linalg::kernel_isa());
        EXPECT_LT(f_err, 1e-12) << material->name() << " " << linalg::to_string(linalg::kernel_isa());
        EXPECT_NEAR(fast.energy, ref.energy, 1e-12 * std::abs(ref.energy));
        EXPECT_EQ(fast.tangent, fast.tangent.transpose());
        if (c.active()) {
          EXPECT_NEAR(fast.g_J, ref.g_J, 1e-13);
          EXPECT_NEAR(fast.T_eff, ref.T_eff, 1e-10);
        }
        worst = std::max({worst, k_err, f_err});
        // Without the tangent: the same force.
        ElementResult force_only;
        kernel.evaluate(X, x, *material, false, c, scratch, force_only);
        EXPECT_EQ(force_only.force, fast.force);
      }
    }
    std::printf("brick kernel %s: worst relative difference from the reference %.2e\n",
                linalg::to_string(linalg::kernel_isa()).c_str(), worst);
  }
  linalg::set_kernel_isa(saved);
}

TEST(FormingElement, ZeroForceInReferenceStateAndUnderRigidRotation) {
  std::mt19937 rng(test::kSeed + 1);
  const quadrature::TensorRule<3> rule = ElementRule{}.brick();
  const Mat3 R = Eigen::AngleAxisd(60.0 * kPi / 180.0, Vec3(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Vec3 t(0.7, -1.1, 0.4);
  double worst_ref = 0.0, worst_rot = 0.0;
  for (const auto& material : materials_under_test()) {
    const BrickParams X = fixtures::distorted_brick(rng, 0.08);
    const ElementResult r0 = brick_element(X, X, *material, rule, true);
    ASSERT_TRUE(r0.ok());
    const double scale = max_abs(r0.tangent) * 2.0;  // stiffness x element size
    // Rigid motion x = R X + t: derivative parameters rotate, values also translate.
    BrickParams x = X * R.transpose();
    for (int k = 0; k < kBrickFunctions; k += 4) x.row(k) += t.transpose();
    const ElementResult rr = brick_element(X, x, *material, rule, false);
    ASSERT_TRUE(rr.ok());
    EXPECT_LT(max_abs(r0.force), kZeroForceRel * scale) << material->name();
    EXPECT_LT(max_abs(rr.force), kZeroForceRel * scale) << material->name();
    EXPECT_NEAR(rr.energy, 0.0, kZeroForceRel * scale) << material->name();
    worst_ref = std::max(worst_ref, max_abs(r0.force) / scale);
    worst_rot = std::max(worst_rot, max_abs(rr.force) / scale);
    for (const Mat3& F : brick_deformation_gradients(X, x, rule)) EXPECT_LT(max_abs(F - R), kExactF);
  }
  std::printf("brick: |f| / (|K| L) reference %.2e, rotated 60 deg %.2e\n", worst_ref, worst_rot);
}

TEST(FormingElement, HomogeneousDeformationGivesExactF) {
  std::mt19937 rng(test::kSeed + 2);
  const quadrature::TensorRule<3> rule = ElementRule{}.brick();
  const BrickParams X = fixtures::distorted_brick(rng, 0.1);
  Mat3 F0;
  F0 << 1.3, 0.2, -0.1, 0.05, 0.8, 0.3, -0.2, 0.1, 1.1;
  BrickParams x = X * F0.transpose();
  for (int k = 0; k < kBrickFunctions; k += 4) x.row(k) += Vec3(1, 2, 3).transpose();
  double worst = 0.0;
  for (const Mat3& F : brick_deformation_gradients(X, x, rule)) worst = std::max(worst, max_abs(F - F0));
  EXPECT_LT(worst, kExactF);
}

TEST(FormingElement, InvertedStateIsReportedNotThrown) {
  std::mt19937 rng(test::kSeed + 3);
  const quadrature::TensorRule<3> rule = ElementRule{}.brick();
  const BrickParams X = fixtures::distorted_brick(rng, 0.0);
  BrickParams x = X;
  x.col(2) *= -1.0;  // mirror through the ply plane: det F = -1
  const ElementResult r = brick_element(X, x, *neo_hookean(), rule, true);
  EXPECT_EQ(r.status, ElementResult::Status::kInverted);
  EXPECT_LT(r.min_det_f, 0.0);
  const ElementResult rr = brick_element(x, X, *neo_hookean(), rule, true);
  EXPECT_EQ(rr.status, ElementResult::Status::kInvertedReference);
  const ElementRule bad{0, 2};
  EXPECT_THROW(bad.validate(), InputError);
}

// ---- Plane-strain element -------------------------------------------------------

// Strip 2 x 0.4 mm (xi1 along, xi2 through the thickness), parameters perturbed.
PlaneParams reference_plane(std::mt19937& rng, double distortion) {
  PlaneParams X;
  for (int c = 0; c < 2; ++c)
    for (int a = 0; a < 2; ++a) {
      const int n = a + 2 * c;
      X.row(2 * n + 0) << 2.0 * a, 0.4 * c;  // value
      X.row(2 * n + 1) << 2.0, 0.0;          // d/dxi1
    }
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 8; ++k)
    for (int i = 0; i < 2; ++i) X(k, i) += distortion * u(rng);
  return X;
}

TEST(FormingElementPlane, TangentForceRigidRotationAndExactF) {
  std::mt19937 rng(test::kSeed + 4);
  const quadrature::TensorRule<2> rule = ElementRule{}.plane();
  const double th = 60.0 * kPi / 180.0;
  Eigen::Matrix2d R;
  R << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
  double worst_k = 0.0, worst_f = 0.0;
  for (const auto& material : materials_under_test()) {
    const PlaneParams X = reference_plane(rng, 0.05);
    // Random state: homogeneous 2-D F plus noise, all det F > 0.2.
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    PlaneParams x;
    for (;;) {
      Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) F(i, j) += 0.3 * u(rng);
      x = X * F.transpose();
      for (int k = 0; k < 8; ++k)
        for (int i = 0; i < 2; ++i) x(k, i) += 0.03 * u(rng);
      bool ok = F.determinant() > 0.5;
      for (const Mat3& f : plane_deformation_gradients(X, x, rule)) ok = ok && f.determinant() > 0.2;
      if (ok) break;
    }
    const FdErrors e = fd_errors(X, x, [&](const PlaneParams& Xa, const PlaneParams& xa, bool tangent) {
      return plane_element(Xa, xa, *material, rule, tangent);
    });
    EXPECT_LT(e.tangent, kFdRel) << material->name();
    EXPECT_LT(e.force, kFdRel) << material->name();
    worst_k = std::max(worst_k, e.tangent);
    worst_f = std::max(worst_f, e.force);

    const ElementResult r0 = plane_element(X, X, *material, rule, true);
    const double scale = max_abs(r0.tangent) * 2.0;
    PlaneParams xr = X * R.transpose();
    for (int k = 0; k < 8; k += 2) xr.row(k) += Eigen::RowVector2d(0.3, -0.8);
    const ElementResult rr = plane_element(X, xr, *material, rule, false);
    ASSERT_TRUE(rr.ok());
    EXPECT_LT(max_abs(r0.force), kZeroForceRel * scale) << material->name();
    EXPECT_LT(max_abs(rr.force), kZeroForceRel * scale) << material->name();
    Mat3 R3 = Mat3::Identity();
    R3.topLeftCorner<2, 2>() = R;
    for (const Mat3& F : plane_deformation_gradients(X, xr, rule)) EXPECT_LT(max_abs(F - R3), kExactF);
  }
  std::printf("plane: worst FD error tangent %.2e, force %.2e (relative)\n", worst_k, worst_f);
}

// ---- Ply mesh -------------------------------------------------------------------

TEST(FormingElementPlyMesh, LayersNumberingMapAndFibre) {
  const double h = 0.4;
  const mesh::SurfaceMesh s =
      mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 3.0, 2.0, 3, 2, {0.0, 0.5, 2.0, 3.0}, {});
  const PlyMesh bottom(s, h, 30.0, PlyPlacement::kBottom);
  const PlyMesh mid(s, h, 30.0, PlyPlacement::kMiddle);
  const Index ns = s.n_nodes();
  EXPECT_EQ(bottom.n_nodes(), 2 * ns);
  EXPECT_EQ(bottom.n_dofs(), 24 * ns);
  EXPECT_EQ(PlyMesh::dof(bottom.node(5, 1), 2, 1), 3 * (4 * (5 + ns) + 2) + 1);
  for (Index node = 0; node < ns; ++node)
    for (int d = 0; d < 4; ++d) {
      const Eigen::RowVector3d g = s.geometry().row(mesh::SurfaceMesh::dof(node, d));
      const Eigen::RowVector3d up = d == 0 ? Eigen::RowVector3d(0, 0, h) : Eigen::RowVector3d::Zero();
      EXPECT_LT((bottom.reference().row(PlyMesh::param(bottom.node(node, 0), d)) - g).norm(), 1e-15);
      EXPECT_LT((bottom.reference().row(PlyMesh::param(bottom.node(node, 1), d)) - g - up).norm(), 1e-15);
      EXPECT_LT((mid.reference().row(PlyMesh::param(mid.node(node, 0), d)) - g + 0.5 * up).norm(), 1e-15);
    }
  // Brick map: top-layer functions (k >= 16) use the surface map shifted by one layer.
  const mesh::ElementMap sm = s.element_map(1);
  const BrickMap bm = bottom.element_map(1);
  for (int k = 0; k < 16; ++k) {
    ASSERT_EQ(bm.n_terms[k], 1);
    EXPECT_EQ(bm.terms[k][0].dof, sm.terms[k][0].dof);
    EXPECT_EQ(bm.terms[k + 16][0].dof, sm.terms[k][0].dof + 4 * ns);
    EXPECT_EQ(bm.terms[k + 16][0].coef, sm.terms[k][0].coef);
  }
  EXPECT_EQ(bottom.boundary_surface_nodes().size(), 10u);
  EXPECT_LT((bottom.fibre_direction() - fibre_from_layup_angle(30.0)).norm(), 1e-15);
  // A ply in a tilted plane: layup angles from the projected x axis towards N x t1.
  const double c = std::cos(0.3), sn = std::sin(0.3);
  const PlyMesh tilted(mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3(0, c, sn), 1, 1, 1, 1), h, 90.0);
  EXPECT_LT((tilted.fibre_direction() - Vec3(0, c, sn)).norm(), 1e-15);
  // Not flat: rejected, naming the problem.
  mesh::SurfaceMesh bent = s;
  bent.geometry()(mesh::SurfaceMesh::dof(5, mesh::kValue), 2) = 0.1;
  EXPECT_THROW(PlyMesh(bent, h, 0.0), InputError);
  // Round trip of the flattened layout.
  EXPECT_EQ(PlyMesh::unflatten(bottom.reference_dofs()), bottom.reference());
}

// ---- Assembly ------------------------------------------------------------------

TEST(FormingElementAssembly, AssembledTangentMatchesFiniteDifferencesOnGradedMesh) {
  std::mt19937 rng(test::kSeed + 5);
  Model model;
  PlyMesh ply(mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 3.0, 2.0, 2, 2, {0.0, 1.2, 3.0},
                                        {0.0, 0.7, 2.0}),
              0.3, 30.0);
  const Vec3 a0 = ply.fibre_direction();
  EXPECT_LT((a0 - fibre_from_layup_angle(30.0)).norm(), 1e-15);
  model.add_ply(std::move(ply), trans_iso(a0));
  const VecX X = model.reference_positions();
  // Random state: x = F X + noise on every parameter.
  Mat3 F;
  F << 1.1, 0.15, 0.0, -0.05, 0.95, 0.1, 0.02, -0.1, 1.05;
  MatX xm = PlyMesh::unflatten(X);
  for (Index p = 0; p < xm.rows(); ++p) xm.row(p) = (F * xm.row(p).transpose()).transpose();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX x = PlyMesh::flatten(xm);
  for (Index d = 0; d < x.size(); ++d) x(d) += 0.01 * u(rng);
  const Assembly a = model.assemble(x, true);
  ASSERT_TRUE(a.ok) << a.message;
  const MatX K = MatX(a.tangent);
  MatX k_fd(x.size(), x.size());
  for (Index j = 0; j < x.size(); ++j) {
    VecX xp = x, xmn = x;
    xp(j) += kFdStep;
    xmn(j) -= kFdStep;
    k_fd.col(j) = (model.assemble(xp, false).force - model.assemble(xmn, false).force) / (2.0 * kFdStep);
  }
  const double err = max_abs(k_fd - K) / max_abs(K);
  EXPECT_LT(err, kFdRel);
  std::printf("assembled 2x2 graded TI ply (%lld dofs): FD tangent error %.2e (relative)\n",
              static_cast<long long>(x.size()), err);
  // Rigid rotation of the whole ply: zero assembled force.
  const Mat3 R = Eigen::AngleAxisd(60.0 * kPi / 180.0, Vec3(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  MatX xr = PlyMesh::unflatten(X);
  for (Index p = 0; p < xr.rows(); ++p) xr.row(p) = (R * xr.row(p).transpose()).transpose();
  const Assembly ar = model.assemble(PlyMesh::flatten(xr), false);
  EXPECT_LT(max_abs(ar.force), kZeroForceRel * max_abs(K) * 3.0);
}

}  // namespace
}  // namespace sf::forming

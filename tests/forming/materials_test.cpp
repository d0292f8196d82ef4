// Hyperelastic laws of forming/material/ (neo_hookean, transversely_isotropic): stress against central finite
// differences of the energy and tangent against finite differences of the stress
// (random C = F^T F, fixed seeds, several fibre angles), stress-free reference
// states, material symmetry and objectivity, the closed-form homogeneous
// deformations of an incompressible transversely isotropic block
// (notes/forming-verification.md section 2.5: uniaxial tension along the fibres,
// tension across inextensible fibres, simple shear along the fibres), small-strain
// moduli recovered from engineering constants, and the messages of bad parameters.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "common/core/error.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using fixtures::max_abs;

using ::testing::AllOf;
using ::testing::HasSubstr;

// ---- Named tolerances (what each bounds and why it is that size) ----------------
// Central-difference step in the entries of C (O(1)): truncation h^2 W'''/6 ~ 1e-12
// relative, roundoff eps |W| / h ~ 1e-10 relative.
constexpr double kFdStepC = 1e-6;
// FD stress/tangent against the analytic ones, relative to max(1, largest entry);
// measured worst 5.6e-10 (stress), 2.6e-10 (tangent) at stretches up to ~1.5 and
// 1.2e-8 (tangent) at stretches up to ~2.5.
constexpr double kFdRel = 1e-7;
// Identities that hold in exact arithmetic, relative to the size of the numbers
// (stress-free reference states, symmetry transformations, closed forms).
constexpr double kExactRel = 1e-12;
// Reference values quoted to 6 decimals in the notes (half a unit in the last place).
constexpr double kQuoted6 = 5e-7;
// Small-strain moduli from the tangent against the engineering constants (brief: 1e-6).
constexpr double kModuliRel = 1e-6;
// Linear response measured as a secant at strain 1e-6: the quadratic term is ~1e-6
// of the modulus times the stiffness ratio of the law.
constexpr double kSecantRel = 1e-4;

Mat3 rotation(const Vec3& axis, double angle) { return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(); }

Mat3 random_rotation(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec3 axis(u(rng), u(rng), u(rng));
  if (axis.norm() < 0.1) axis = Vec3::UnitZ();
  return rotation(axis, kPi * u(rng));
}

// F = I + amplitude * U(-1, 1) entries, redrawn until det F > 0.3.
Mat3 random_deformation(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    Mat3 F = Mat3::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F(i, j) += amplitude * u(rng);
    if (F.determinant() > 0.3) return F;
  }
}

Mat3 random_symmetric(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat3 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = u(rng);
  return 0.5 * (m + m.transpose());
}

// Voigt pairs (11, 22, 33, 12, 23, 13).
constexpr int kPair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};

// C with Voigt component J moved by t (both off-diagonal entries for shear).
Mat3 perturbed(const Mat3& C, int J, double t) {
  Mat3 c = C;
  const int k = kPair[J][0], l = kPair[J][1];
  c(k, l) += t;
  if (k != l) c(l, k) += t;
  return c;
}

// S = 2 dW/dC by central differences: moving C_kk by h changes W by dW/dC_kk h;
// moving C_kl and C_lk together by h changes it by 2 dW/dC_kl h = S_kl h.
Mat3 fd_stress(const Material& m, const Mat3& C, double h) {
  Mat3 S;
  for (int J = 0; J < 6; ++J) {
    const double dw =
        (m.evaluate(perturbed(C, J, h), false).energy - m.evaluate(perturbed(C, J, -h), false).energy) / (2.0 * h);
    const int k = kPair[J][0], l = kPair[J][1];
    S(k, l) = S(l, k) = (k == l ? 2.0 : 1.0) * dw;
  }
  return S;
}

// CC by central differences of S: the move of C_kk by h is dE_kk = h/2 (Voigt dE_J
// = h/2); the move of C_kl, C_lk by h is 2 dE_kl = h (Voigt dE_J = h).
Mat6 fd_tangent(const Material& m, const Mat3& C, double h) {
  Mat6 CC;
  for (int J = 0; J < 6; ++J) {
    const Vec6 ds = (voigt_stress(m.evaluate(perturbed(C, J, h), false).stress) -
                     voigt_stress(m.evaluate(perturbed(C, J, -h), false).stress)) /
                    (2.0 * h);
    CC.col(J) = (kPair[J][0] == kPair[J][1] ? 2.0 : 1.0) * ds;
  }
  return CC;
}

struct NamedMaterial {
  std::string label;
  std::shared_ptr<const Material> material;
};

using fixtures::ti_compressible;
// The incompressible law's constants (the default form).
TransverselyIsotropicParams ti(double mu_t, double mu_l, double kappa_f) {
  return fixtures::ti_incompressible(mu_t, mu_l, kappa_f);
}

// Molten unidirectional GF/PP scale: fibre stiffness 25000 times transverse.
TransverselyIsotropicEngineering gfpp(bool incompressible) {
  TransverselyIsotropicEngineering e;
  e.E_f = 25000.0;
  e.E_T = 1.0;
  e.G_L = 0.5;
  e.incompressible = incompressible;
  if (!incompressible) e.G_T = 0.4;
  return e;
}

std::vector<NamedMaterial> neo_hookeans() {
  return {{"neo-Hookean E=10 nu=0.3", std::make_shared<NeoHookean>(NeoHookeanParams::from_young_poisson(10.0, 0.3))},
          {"neo-Hookean mu=1 kappa=200", std::make_shared<NeoHookean>(NeoHookeanParams::from_shear_bulk(1.0, 200.0))}};
}

// Both TI variants at several layup angles, an out-of-plane fibre, mu_L < mu_T, and
// the GF/PP stiffness ratio.
std::vector<NamedMaterial> transversely_isotropics() {
  std::vector<NamedMaterial> out;
  for (const double angle : {0.0, 30.0, 45.0, 90.0, -60.0}) {
    const Vec3 a0 = fibre_from_layup_angle(angle);
    const std::string at = " at " + std::to_string(angle) + " deg";
    out.push_back({"TI incompressible (1,3,50)" + at, std::make_shared<TransverselyIsotropic>(ti(1.0, 3.0, 50.0), a0)});
    out.push_back({"TI compressible (1,3,50,lambda 5)" + at,
                   std::make_shared<TransverselyIsotropic>(ti_compressible(1.0, 3.0, 50.0, 5.0), a0)});
  }
  out.push_back({"TI incompressible, fibre (1,2,3)",
                 std::make_shared<TransverselyIsotropic>(ti(1.0, 3.0, 50.0), Vec3(1.0, 2.0, 3.0))});
  out.push_back({"TI compressible mu_L < mu_T, fibre (-1,0.5,2)",
                 std::make_shared<TransverselyIsotropic>(ti_compressible(2.0, 1.0, 20.0, -0.5), Vec3(-1.0, 0.5, 2.0))});
  out.push_back({"TI incompressible GF/PP at 20 deg",
                 std::make_shared<TransverselyIsotropic>(gfpp(true).to_params(), fibre_from_layup_angle(20.0))});
  out.push_back({"TI compressible GF/PP at 70 deg",
                 std::make_shared<TransverselyIsotropic>(gfpp(false).to_params(), fibre_from_layup_angle(70.0))});
  return out;
}

// Worst relative FD errors (stress, tangent) over `n` random C for one material;
// also checks the tangent's major symmetry and that want_tangent does not change W, S.
void check_against_finite_differences(const NamedMaterial& nm, unsigned seed, double& worst_s, double& worst_cc) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 8; ++trial) {
    const Mat3 F = random_deformation(rng, 0.3);
    const Mat3 C = F.transpose() * F;
    const MaterialResponse r = nm.material->evaluate(C, true);
    const MaterialResponse r0 = nm.material->evaluate(C, false);
    EXPECT_EQ(r.energy, r0.energy) << nm.label;
    EXPECT_EQ(max_abs(r.stress - r0.stress), 0.0) << nm.label;

    const double s_scale = std::max(1.0, max_abs(r.stress));
    const double es = max_abs(fd_stress(*nm.material, C, kFdStepC) - r.stress) / s_scale;
    EXPECT_LT(es, kFdRel) << nm.label << ", trial " << trial << "\nS =\n" << r.stress;
    worst_s = std::max(worst_s, es);

    const double cc_scale = std::max(1.0, max_abs(r.tangent));
    const double ec = max_abs(fd_tangent(*nm.material, C, kFdStepC) - r.tangent) / cc_scale;
    EXPECT_LT(ec, kFdRel) << nm.label << ", trial " << trial << "\nCC =\n" << r.tangent;
    worst_cc = std::max(worst_cc, ec);
    EXPECT_LT(max_abs(r.tangent - r.tangent.transpose()) / cc_scale, kExactRel) << nm.label;
  }
}

void print_measured(const char* what, double value) { std::printf("[ measured ] %s: %.3e\n", what, value); }

// ---------------------------------------------------------------------------------
// Neo-Hookean

TEST(FormingMaterialNeoHookean, StressAndTangentMatchFiniteDifferences) {
  double ws = 0.0, wc = 0.0;
  for (const NamedMaterial& nm : neo_hookeans()) check_against_finite_differences(nm, sf::test::kSeed, ws, wc);
  print_measured("neo-Hookean FD stress rel. error", ws);
  print_measured("neo-Hookean FD tangent rel. error", wc);
}

TEST(FormingMaterialNeoHookean, StressFreeAtReferenceWithIsotropicTangent) {
  const NeoHookeanParams p = NeoHookeanParams::from_young_poisson(10.0, 0.3);
  const MaterialResponse r = NeoHookean(p).evaluate(Mat3::Identity(), true);
  EXPECT_EQ(r.energy, 0.0);
  EXPECT_LT(max_abs(r.stress), kExactRel * p.mu);
  // Small strain: CC = lambda 1 1^T + mu diag(2, 2, 2, 1, 1, 1), so E and nu come back.
  const Mat6 compliance = r.tangent.inverse();
  EXPECT_NEAR(1.0 / compliance(0, 0), 10.0, kModuliRel * 10.0);
  EXPECT_NEAR(-compliance(0, 1) / compliance(0, 0), 0.3, kModuliRel);
  EXPECT_NEAR(1.0 / compliance(3, 3), p.mu, kModuliRel * p.mu);
  const NeoHookeanParams q = NeoHookeanParams::from_shear_bulk(2.0, 50.0);
  EXPECT_NEAR(q.bulk_modulus(), 50.0, kExactRel * 50.0);
  EXPECT_NEAR(q.lambda, 50.0 - 4.0 / 3.0, kExactRel * 50.0);
}

// Pure dilation F = s I: sigma = (mu (s^2 - 1) + lambda ln J) / J I, J = s^3; simple
// shear F = I + g e1 (x) e2: sigma12 = mu g (J = 1).
TEST(FormingMaterialNeoHookean, HomogeneousDeformationsInClosedForm) {
  const NeoHookeanParams p = NeoHookeanParams::from_shear_bulk(1.5, 20.0);
  const NeoHookean m(p);
  for (const double s : {0.8, 0.95, 1.1, 1.5}) {
    const Mat3 F = s * Mat3::Identity();
    const Mat3 sigma = cauchy_stress(F, m.evaluate(F.transpose() * F, false).stress);
    const double j = s * s * s;
    const double expected = (p.mu * (s * s - 1.0) + p.lambda * std::log(j)) / j;
    EXPECT_LT(max_abs(sigma - expected * Mat3::Identity()), kExactRel * (1.0 + std::abs(expected))) << "s = " << s;
  }
  for (const double g : {0.1, 1.0, 3.0}) {
    Mat3 F = Mat3::Identity();
    F(0, 1) = g;
    const Mat3 sigma = cauchy_stress(F, m.evaluate(F.transpose() * F, false).stress);
    EXPECT_NEAR(sigma(0, 1), p.mu * g, kExactRel * p.mu * (1.0 + g)) << "g = " << g;
  }
}

TEST(FormingMaterialNeoHookean, InvertedPointGivesInfiniteEnergyNotAThrow) {
  const NeoHookean m(NeoHookeanParams::from_young_poisson(1.0, 0.3));
  const MaterialResponse r = m.evaluate(Vec3(1.0, 1.0, 0.0).asDiagonal(), true);
  EXPECT_TRUE(std::isinf(r.energy));
  EXPECT_TRUE(std::isnan(r.stress(0, 0)));
  const TransverselyIsotropic t(ti_compressible(1.0, 3.0, 50.0, 5.0), Vec3::UnitX());
  EXPECT_TRUE(std::isinf(t.evaluate(Vec3(1.0, 1.0, 0.0).asDiagonal(), false).energy));
}

TEST(FormingMaterialNeoHookean, BadParametersAreNamed) {
  const auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected sf::InputError";
    return {};
  };
  EXPECT_THAT(message([] { NeoHookeanParams::from_young_poisson(-1.0, 0.3); }),
              AllOf(HasSubstr("neo-Hookean"), HasSubstr("E:"), HasSubstr("-1")));
  EXPECT_THAT(message([] { NeoHookeanParams::from_young_poisson(1.0, 0.5); }),
              AllOf(HasSubstr("nu:"), HasSubstr("0.5")));
  EXPECT_THAT(message([] { NeoHookeanParams::from_shear_bulk(1.0, 0.0); }), HasSubstr("kappa:"));
  NeoHookeanParams p;
  p.mu = 1.0;
  p.lambda = -1.0;
  EXPECT_THAT(message([&] { p.validate(); }), HasSubstr("lambda:"));
  p.mu = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(message([&] { (void)NeoHookean{p}; }), AllOf(HasSubstr("mu:"), HasSubstr("finite")));
}

// ---------------------------------------------------------------------------------
// Transversely isotropic

TEST(FormingMaterialTransverselyIsotropic, StressAndTangentMatchFiniteDifferences) {
  double ws = 0.0, wc = 0.0;
  unsigned seed = sf::test::kSeed;
  for (const NamedMaterial& nm : transversely_isotropics()) check_against_finite_differences(nm, seed++, ws, wc);
  print_measured("TI FD stress rel. error", ws);
  print_measured("TI FD tangent rel. error", wc);
}

// The same check with large deformations (stretches up to ~2.5) where the fibre
// terms dominate.
TEST(FormingMaterialTransverselyIsotropic, TangentMatchesFiniteDifferencesAtLargeStrain) {
  std::mt19937 rng(sf::test::kSeed + 7u);
  double worst = 0.0;
  for (const NamedMaterial& nm : transversely_isotropics()) {
    for (int trial = 0; trial < 4; ++trial) {
      const Mat3 F = random_deformation(rng, 0.8);
      const Mat3 C = F.transpose() * F;
      const MaterialResponse r = nm.material->evaluate(C, true);
      const double h = kFdStepC * std::max(1.0, max_abs(C));
      const double e = max_abs(fd_tangent(*nm.material, C, h) - r.tangent) / std::max(1.0, max_abs(r.tangent));
      EXPECT_LT(e, kFdRel) << nm.label << ", trial " << trial;
      worst = std::max(worst, e);
    }
  }
  print_measured("TI FD tangent rel. error, large strain", worst);
}

TEST(FormingMaterialTransverselyIsotropic, ReferenceStateIsStressFree) {
  for (const double angle : {0.0, 37.0, 90.0}) {
    const Vec3 a0 = fibre_from_layup_angle(angle);
    // Compressible: S(I) = 0, W(I) = 0.
    const MaterialResponse rc =
        TransverselyIsotropic(ti_compressible(1.0, 3.0, 50.0, 5.0), a0).evaluate(Mat3::Identity(), false);
    EXPECT_EQ(rc.energy, 0.0);
    EXPECT_LT(max_abs(rc.stress), kExactRel);
    // Incompressible: S(I) = mu_T I, cancelled by the element's pressure p = mu_T.
    const TransverselyIsotropicParams p = gfpp(true).to_params();
    const MaterialResponse ri = TransverselyIsotropic(p, a0).evaluate(Mat3::Identity(), false);
    EXPECT_EQ(ri.energy, 0.0);
    EXPECT_LT(max_abs(ri.stress - p.mu_T * Mat3::Identity()), kExactRel * p.kappa_f);
  }
}

// With mu_L = mu_T and kappa_f = 0 the compressible law is the neo-Hookean one.
TEST(FormingMaterialTransverselyIsotropic, ReducesToNeoHookeanWithoutFibreTerms) {
  NeoHookeanParams nh;
  nh.mu = 1.3;
  nh.lambda = 7.0;
  const NeoHookean iso(nh);
  const TransverselyIsotropic t(ti_compressible(1.3, 1.3, 0.0, 7.0), Vec3(0.3, -1.0, 0.2));
  std::mt19937 rng(sf::test::kSeed);
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 F = random_deformation(rng, 0.4);
    const Mat3 C = F.transpose() * F;
    const MaterialResponse a = iso.evaluate(C, true), b = t.evaluate(C, true);
    EXPECT_NEAR(a.energy, b.energy, kExactRel * (1.0 + std::abs(a.energy)));
    EXPECT_LT(max_abs(a.stress - b.stress), kExactRel * (1.0 + max_abs(a.stress)));
    EXPECT_LT(max_abs(a.tangent - b.tangent), kExactRel * (1.0 + max_abs(a.tangent)));
  }
}

// Material symmetry. (1) Turning the reference configuration by Q together with the
// fibre (a0 -> Q a0, C -> Q C Q^T) gives the same W, S -> Q S Q^T and the tangent
// rotated alike; (2) rotation about the fibre and reversing the fibre change nothing
// (transverse isotropy); (3) a rigid rotation after the deformation, F -> R F, leaves
// W alone and turns the Cauchy stress, sigma -> R sigma R^T (objectivity).
TEST(FormingMaterialTransverselyIsotropic, MaterialSymmetryAndObjectivity) {
  std::mt19937 rng(sf::test::kSeed + 11u);
  for (const bool incompressible : {true, false}) {
    TransverselyIsotropicParams p = ti_compressible(1.0, 3.0, 50.0, 5.0);
    p.incompressible = incompressible;
    for (const double angle : {0.0, 25.0, 90.0, 135.0}) {
      const Vec3 a0 = fibre_from_layup_angle(angle);
      const TransverselyIsotropic m(p, a0);
      for (int trial = 0; trial < 4; ++trial) {
        const Mat3 F = random_deformation(rng, 0.4);
        const Mat3 C = F.transpose() * F;
        const MaterialResponse r = m.evaluate(C, true);
        const double w_tol = kExactRel * (1.0 + std::abs(r.energy));
        const double s_tol = kExactRel * (1.0 + max_abs(r.stress));
        const double cc_tol = kExactRel * (1.0 + max_abs(r.tangent));

        const Mat3 Q = random_rotation(rng);
        const TransverselyIsotropic mq(p, Q * a0);
        const MaterialResponse rq = mq.evaluate(Q * C * Q.transpose(), true);
        EXPECT_NEAR(rq.energy, r.energy, w_tol) << "angle " << angle;
        EXPECT_LT(max_abs(rq.stress - Q * r.stress * Q.transpose()), s_tol) << "angle " << angle;
        const Mat3 dE = random_symmetric(rng);
        const Mat3 dS = from_voigt_stress(r.tangent * voigt_strain(dE));
        const Mat3 dSq = from_voigt_stress(rq.tangent * voigt_strain(Q * dE * Q.transpose()));
        EXPECT_LT(max_abs(dSq - Q * dS * Q.transpose()), cc_tol) << "angle " << angle;

        const Mat3 Ra = rotation(a0, 2.0 * kPi * std::uniform_real_distribution<double>(0, 1)(rng));
        const MaterialResponse ra = m.evaluate(Ra * C * Ra.transpose(), false);
        EXPECT_NEAR(ra.energy, r.energy, w_tol) << "angle " << angle;
        EXPECT_LT(max_abs(ra.stress - Ra * r.stress * Ra.transpose()), s_tol);
        const MaterialResponse rm = TransverselyIsotropic(p, -a0).evaluate(C, false);
        EXPECT_NEAR(rm.energy, r.energy, w_tol);
        EXPECT_LT(max_abs(rm.stress - r.stress), s_tol);

        const Mat3 R = random_rotation(rng);
        const Mat3 RF = R * F;
        const MaterialResponse rr = m.evaluate(RF.transpose() * RF, false);
        EXPECT_NEAR(rr.energy, r.energy, w_tol);
        const Mat3 sigma = cauchy_stress(F, r.stress);
        EXPECT_LT(max_abs(cauchy_stress(RF, rr.stress) - R * sigma * R.transpose()),
                  kExactRel * (1.0 + max_abs(sigma)));
      }
    }
  }
  // A rotation that is not about the fibre does change the energy (the test can see
  // anisotropy): stretch along x with fibres along x versus along y (the fibre terms
  // give 0.59535 and 0.11157).
  const TransverselyIsotropic m(ti(1.0, 3.0, 50.0), Vec3::UnitX());
  const Mat3 C = Vec3(1.21, 1.0 / 1.1, 1.0 / 1.1).asDiagonal();
  const Mat3 Rz = rotation(Vec3::UnitZ(), kPi / 2);
  EXPECT_GT(std::abs(m.evaluate(Rz * C * Rz.transpose(), false).energy - m.evaluate(C, false).energy), 0.4);
}

TEST(FormingMaterialTransverselyIsotropic, FibreDirectionFromLayupAngle) {
  EXPECT_LT((fibre_from_layup_angle(0.0) - Vec3::UnitX()).norm(), kExactRel);
  EXPECT_LT((fibre_from_layup_angle(90.0) - Vec3::UnitY()).norm(), kExactRel);
  EXPECT_LT((fibre_from_layup_angle(-45.0) - Vec3(1.0, -1.0, 0.0).normalized()).norm(), kExactRel);
  EXPECT_LT((fibre_from_layup_angle(30.0) - Vec3(std::sqrt(3.0) / 2, 0.5, 0.0)).norm(), kExactRel);
  const TransverselyIsotropic m(ti(1.0, 3.0, 50.0), Vec3(0.0, 3.0, 4.0));
  EXPECT_LT((m.fibre_direction() - Vec3(0.0, 0.6, 0.8)).norm(), kExactRel);
  EXPECT_THAT(m.name(), HasSubstr("incompressible"));
  // A 90 degree ply stretched along y responds as a 0 degree ply stretched along x.
  const TransverselyIsotropic m90(ti(1.0, 3.0, 50.0), fibre_from_layup_angle(90.0));
  const TransverselyIsotropic m0(ti(1.0, 3.0, 50.0), fibre_from_layup_angle(0.0));
  const double w90 = m90.evaluate(Vec3(0.9, 1.3, 1.0).asDiagonal(), false).energy;
  const double w0 = m0.evaluate(Vec3(1.3, 0.9, 1.0).asDiagonal(), false).energy;
  EXPECT_NEAR(w90, w0, kExactRel * w0);
  EXPECT_THROW(fibre_from_layup_angle(std::numeric_limits<double>::infinity()), InputError);
}

// Notes 2.5 (A): F = diag(l, l^-1/2, l^-1/2) along the fibre, p = mu_T / l from the
// traction-free sides, sigma11 = mu_T (l^2 - 1/l) + (kappa_f + 2 (mu_L - mu_T)) l^2 (l^2 - 1).
// Run in the fibre's own frame for several layup angles.
TEST(FormingMaterialTransverselyIsotropic, UniaxialTensionAlongFibresClosedForm) {
  const TransverselyIsotropicParams p = ti(1.0, 3.0, 50.0);
  const struct { double stretch, sigma11; } cases[] = {{1.05, 6.252457}, {1.2, 34.821067}};
  for (const double angle : {0.0, 30.0, 90.0, -75.0}) {
    const Mat3 R = rotation(Vec3::UnitZ(), angle * kPi / 180.0);  // fibre frame -> global
    const TransverselyIsotropic m(p, fibre_from_layup_angle(angle));
    for (const auto& c : cases) {
      const double l = c.stretch;
      const Mat3 F = R * Vec3(l, 1.0 / std::sqrt(l), 1.0 / std::sqrt(l)).asDiagonal() * R.transpose();
      const double pressure = p.mu_T / l;  // analytic, from sigma22 = sigma33 = 0
      const Mat3 sigma_global =
          cauchy_stress(F, m.evaluate(F.transpose() * F, false).stress) - pressure * Mat3::Identity();
      const Mat3 sigma = R.transpose() * sigma_global * R;
      const double formula = p.mu_T * (l * l - 1.0 / l) + (p.kappa_f + 2.0 * (p.mu_L - p.mu_T)) * l * l * (l * l - 1.0);
      EXPECT_NEAR(sigma(0, 0), c.sigma11, kQuoted6) << "stretch " << l << ", angle " << angle;
      EXPECT_NEAR(sigma(0, 0), formula, kExactRel * formula);
      EXPECT_NEAR(sigma(1, 1), 0.0, kExactRel * formula);
      EXPECT_NEAR(sigma(2, 2), 0.0, kExactRel * formula);
      EXPECT_NEAR(sigma(0, 1), 0.0, kExactRel * formula);
      if (angle == 0.0)
        std::printf("[ measured ] case A l=%.2f: sigma11 = %.9f (notes %.6f)\n", l, sigma(0, 0), c.sigma11);
    }
  }
}

// Notes 2.5 (B): fibres along e1 held inextensible, load along e2, F = diag(1, l, 1/l).
// p = mu_T / l^2 (sigma33 = 0), T = mu_T (1/l^2 - 1) (sigma11 = 0), sigma22 =
// mu_T (l^2 - 1/l^2); independent of mu_L and kappa_f because I4 = I5 = 1.
TEST(FormingMaterialTransverselyIsotropic, TensionAcrossInextensibleFibresClosedForm) {
  const struct {
    double mu_t, stretch, sigma22, tension;
  } cases[] = {{1.0, 2.0, 3.75, -0.75}, {1.0, 1.3, 1.098284, -0.408284}, {0.7, 2.0, 3.75 * 0.7, -0.75 * 0.7}};
  for (const auto& c : cases) {
    for (const TransverselyIsotropicParams& p : {ti(c.mu_t, 3.0, 50.0), ti(c.mu_t, 0.5, 12500.0)}) {
      const TransverselyIsotropic m(p, Vec3::UnitX());
      const double l = c.stretch;
      const Mat3 F = Vec3(1.0, l, 1.0 / l).asDiagonal();
      const double pressure = p.mu_T / (l * l);
      const double tension = p.mu_T * (1.0 / (l * l) - 1.0);
      const Vec3 a = F * m.fibre_direction();
      // S_total = S - p J C^-1 + T a0 (x) a0, pushed forward with J = 1.
      const Mat3 sigma = cauchy_stress(F, m.evaluate(F.transpose() * F, false).stress) - pressure * Mat3::Identity() +
                         tension * a * a.transpose();
      EXPECT_NEAR(tension, c.tension, kQuoted6);
      EXPECT_NEAR(sigma(1, 1), c.sigma22, kQuoted6) << "stretch " << l;
      EXPECT_NEAR(sigma(0, 0), 0.0, kExactRel * c.sigma22) << "stretch " << l;
      EXPECT_NEAR(sigma(2, 2), 0.0, kExactRel * c.sigma22) << "stretch " << l;
      if (p.mu_L == 3.0)
        std::printf("[ measured ] case B mu_T=%.1f l=%.1f: sigma22 = %.9f, T = %.9f\n", c.mu_t, l, sigma(1, 1),
                    tension);
    }
  }
}

// Notes 2.5 (C): simple shear along the fibres, F = I + g a0 (x) n0 (n0 in the ply
// plane, normal to a0): the shear stress on the fibre planes is mu_L g for any g.
// Holds for both variants (J = 1; the pressure and T have no shear component).
TEST(FormingMaterialTransverselyIsotropic, SimpleShearAlongFibresGivesMuL) {
  double worst = 0.0;
  for (const bool incompressible : {true, false}) {
    TransverselyIsotropicParams p = ti_compressible(1.0, 3.0, 50.0, 10.0);
    p.incompressible = incompressible;
    for (const double angle : {0.0, 30.0, 90.0, -45.0}) {
      const Vec3 a0 = fibre_from_layup_angle(angle);
      const Vec3 n0 = Vec3::UnitZ().cross(a0);
      const TransverselyIsotropic m(p, a0);
      for (const double g : {0.05, 0.5, 2.0}) {
        const Mat3 F = Mat3::Identity() + g * a0 * n0.transpose();
        const Mat3 sigma = cauchy_stress(F, m.evaluate(F.transpose() * F, false).stress);
        const double tau = a0.dot(sigma * n0);
        EXPECT_NEAR(tau, p.mu_L * g, kExactRel * p.mu_L * (1.0 + g)) << "angle " << angle << " g " << g;
        worst = std::max(worst, std::abs(tau - p.mu_L * g) / (p.mu_L * g));
      }
    }
  }
  print_measured("case C simple shear rel. error", worst);
}

// Compressible TI under pure dilation F = s I (C = s^2 I, J = s^3):
//   S = (mu_T + (lambda ln J - mu_T) / s^2) I + (2 (mu_L - mu_T) + kappa_f)(s^2 - 1) A.
// The fibre term is nonzero because the law uses I4; an isochoric J^(-2/3) I4 would
// give none (notes 3.2).
TEST(FormingMaterialTransverselyIsotropic, DilationStretchesTheFibresThroughI4) {
  const TransverselyIsotropicParams p = ti_compressible(1.0, 3.0, 50.0, 5.0);
  const Vec3 a0 = fibre_from_layup_angle(40.0);
  const TransverselyIsotropic m(p, a0);
  for (const double s : {0.9, 1.1}) {
    const Mat3 S = m.evaluate(s * s * Mat3::Identity(), false).stress;
    const double j = s * s * s;
    const Mat3 expected = (p.mu_T + (p.lambda * std::log(j) - p.mu_T) / (s * s)) * Mat3::Identity() +
                          (2.0 * (p.mu_L - p.mu_T) + p.kappa_f) * (s * s - 1.0) * a0 * a0.transpose();
    EXPECT_LT(max_abs(S - expected), kExactRel * (1.0 + max_abs(expected))) << "s = " << s;
    EXPECT_GT(std::abs(a0.dot(S * a0) - Vec3::UnitZ().dot(S * Vec3::UnitZ())), 1.0);
  }
}

// Small-strain engineering moduli from the tangent at C = I (incompressible: the
// constrained problem with the pressure; see moduli_from_tangent).
struct MeasuredModuli {
  double E_L, E_T, G_L, G_T, nu_LT, nu_TT, G_L13;
};

// Linearising S - p J C^-1 at C = I, p = mu_T + dp, tr dE = 0 gives
// dS = (CC + mu_T diag(2,2,2,1,1,1)) dE - dp 1 (Voigt, engineering shear); solve
// it with the constraint for unit stresses. Compressible: invert CC.
MeasuredModuli moduli_from_tangent(const TransverselyIsotropic& m) {
  const TransverselyIsotropicParams& p = m.params();
  const Mat6 CC = m.evaluate(Mat3::Identity(), true).tangent;
  Mat6 compliance;
  if (p.incompressible) {
    Eigen::Matrix<double, 7, 7> K = Eigen::Matrix<double, 7, 7>::Zero();
    K.topLeftCorner<6, 6>() = CC;
    for (int i = 0; i < 6; ++i) K(i, i) += p.mu_T * (i < 3 ? 2.0 : 1.0);
    for (int i = 0; i < 3; ++i) K(i, 6) = K(6, i) = 1.0;  // -dp 1 and tr dE = 0 (sign-flipped dp)
    const Eigen::Matrix<double, 7, 7> Ki = K.inverse();
    compliance = Ki.topLeftCorner<6, 6>();
  } else {
    compliance = CC.inverse();
  }
  MeasuredModuli r{};
  r.E_L = 1.0 / compliance(0, 0);
  r.E_T = 1.0 / compliance(1, 1);
  r.G_L = 1.0 / compliance(3, 3);
  r.G_L13 = 1.0 / compliance(5, 5);
  r.G_T = 1.0 / compliance(4, 4);
  r.nu_LT = -compliance(1, 0) / compliance(0, 0);
  r.nu_TT = -compliance(2, 1) / compliance(1, 1);
  return r;
}

void expect_rel(double actual, double expected, const std::string& what) {
  EXPECT_NEAR(actual, expected, kModuliRel * std::abs(expected)) << what;
}

TEST(FormingMaterialTransverselyIsotropic, EngineeringConstantsRecoveredIncompressible) {
  const TransverselyIsotropicEngineering cases[] = {
      gfpp(true), {40.0, 5.0, 4.0, 0.0, true}, {3.0, 3.0, 1.0, 0.0, true}};
  double worst = 0.0;
  for (const TransverselyIsotropicEngineering& e : cases) {
    const TransverselyIsotropicParams p = e.to_params();
    const TransverselyIsotropic m(p, Vec3::UnitX());
    const MeasuredModuli got = moduli_from_tangent(m);
    const std::string at = "E_f " + std::to_string(e.E_f) + ", E_T " + std::to_string(e.E_T);
    expect_rel(got.E_L, e.E_f, "E_L, " + at);
    expect_rel(got.E_T, e.E_T, "E_T, " + at);
    expect_rel(got.G_L, e.G_L, "G_L, " + at);
    expect_rel(got.G_L13, e.G_L, "G_L (13), " + at);
    expect_rel(got.G_T, p.mu_T, "G_T = mu_T, " + at);
    expect_rel(got.nu_LT, 0.5, "nu_LT, " + at);
    const TransverselyIsotropicModuli f = small_strain_moduli(p);
    expect_rel(got.E_T, f.E_T, "E_T formula, " + at);
    expect_rel(got.nu_TT, f.nu_TT, "nu_TT formula, " + at);
    worst = std::max(
        {worst, std::abs(got.E_L / e.E_f - 1.0), std::abs(got.E_T / e.E_T - 1.0), std::abs(got.G_L / e.G_L - 1.0)});
  }
  // The identity E_L = 3 mu_T + 2 kappa_f + 4 (mu_L - mu_T) against the finite-strain
  // closed form (A) as a secant at stretch 1 + 1e-6.
  const TransverselyIsotropicParams p = ti(1.0, 3.0, 50.0);
  const double l = 1.0 + 1e-6;
  const double sigma11 = p.mu_T * (l * l - 1.0 / l) + (p.kappa_f + 2.0 * (p.mu_L - p.mu_T)) * l * l * (l * l - 1.0);
  const double e_l = 3.0 * p.mu_T + 2.0 * p.kappa_f + 4.0 * (p.mu_L - p.mu_T);
  EXPECT_NEAR(sigma11 / (l - 1.0), e_l, kSecantRel * e_l);
  EXPECT_NEAR(small_strain_moduli(p).E_L, e_l, kExactRel * e_l);
  print_measured("incompressible moduli round trip, worst rel. error", worst);
}

TEST(FormingMaterialTransverselyIsotropic, EngineeringConstantsRecoveredCompressible) {
  const TransverselyIsotropicEngineering cases[] = {gfpp(false),
                                                    {50.0, 4.0, 3.0, 1.5, false},
                                                    {10.0, 2.0, 1.0, 1.2, false},         // nu_TT < 0
                                                    {25000.0, 1.0, 0.5, 0.2502, false}};  // nu_TT ~ 1
  double worst = 0.0;
  for (const TransverselyIsotropicEngineering& e : cases) {
    const TransverselyIsotropicParams p = e.to_params();
    const TransverselyIsotropic m(p, Vec3::UnitX());
    const MeasuredModuli got = moduli_from_tangent(m);
    const std::string at = "E_f " + std::to_string(e.E_f) + ", G_T " + std::to_string(e.G_T);
    expect_rel(got.E_L, e.E_f, "E_L, " + at);
    expect_rel(got.E_T, e.E_T, "E_T, " + at);
    expect_rel(got.G_L, e.G_L, "G_L, " + at);
    expect_rel(got.G_L13, e.G_L, "G_L (13), " + at);
    expect_rel(got.G_T, e.G_T, "G_T, " + at);
    expect_rel(got.nu_TT, e.E_T / (2.0 * e.G_T) - 1.0, "nu_TT, " + at);
    const TransverselyIsotropicModuli f = small_strain_moduli(p);
    expect_rel(got.nu_LT, f.nu_LT, "nu_LT formula, " + at);
    expect_rel(got.E_T, f.E_T, "E_T formula, " + at);
    worst = std::max({worst, std::abs(got.E_L / e.E_f - 1.0), std::abs(got.E_T / e.E_T - 1.0),
                      std::abs(got.G_L / e.G_L - 1.0), std::abs(got.G_T / e.G_T - 1.0)});
  }
  print_measured("compressible moduli round trip, worst rel. error", worst);
}

TEST(FormingMaterialTransverselyIsotropic, BadParametersAreNamed) {
  const auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected sf::InputError";
    return {};
  };
  TransverselyIsotropicParams p = ti(1.0, 3.0, 50.0);
  p.mu_T = 0.0;
  EXPECT_THAT(message([&] { p.validate(); }), AllOf(HasSubstr("mu_T:"), HasSubstr("found 0")));
  p = ti(1.0, -3.0, 50.0);
  EXPECT_THAT(message([&] { p.validate(); }), HasSubstr("mu_L:"));
  p = ti(1.0, 3.0, -1.0);
  EXPECT_THAT(message([&] { (void)TransverselyIsotropic(p, Vec3::UnitX()); }), HasSubstr("kappa_f:"));
  p = ti(1.0, 0.1, 0.0);  // E_L = 3 + 0 + 4 (0.1 - 1) < 0
  EXPECT_THAT(message([&] { p.validate(); }), AllOf(HasSubstr("kappa_f:"), HasSubstr("E_L")));
  p = ti_compressible(3.0, 3.0, 50.0, -2.5);
  EXPECT_THAT(message([&] { p.validate(); }), HasSubstr("lambda:"));
  EXPECT_THAT(message([] { (void)TransverselyIsotropic(ti(1.0, 3.0, 50.0), Vec3::Zero()); }),
              HasSubstr("fibre direction"));

  TransverselyIsotropicEngineering e = gfpp(true);
  e.E_T = -1.0;
  EXPECT_THAT(message([&] { e.to_params(); }), AllOf(HasSubstr("E_T:"), HasSubstr("-1")));
  e = gfpp(true);
  e.G_T = 0.3;  // follows from E_f, E_T in the incompressible law
  EXPECT_THAT(message([&] { e.to_params(); }), HasSubstr("G_T:"));
  e = gfpp(true);
  e.G_L = 1e5;  // kappa_f would be negative
  EXPECT_THAT(message([&] { e.to_params(); }), HasSubstr("G_L:"));
  e = gfpp(true);
  e.E_T = 4.0 * e.E_f;
  EXPECT_THAT(message([&] { e.to_params(); }), HasSubstr("E_T:"));
  e = gfpp(false);
  e.G_T = 0.0;
  EXPECT_THAT(message([&] { e.validate(); }), HasSubstr("G_T:"));
  e = gfpp(false);
  e.G_T = 0.2;  // nu_TT = 1.5
  EXPECT_THAT(message([&] { e.to_params(); }), HasSubstr("G_T:"));
  e = gfpp(false);
  e.E_f = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(message([&] { e.to_params(); }), AllOf(HasSubstr("E_f:"), HasSubstr("finite")));
}

}  // namespace
}  // namespace sf::forming

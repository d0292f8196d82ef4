// Compressible Mooney-Rivlin law (forming/material/mooney_rivlin.hpp, the diaphragm
// option beside neo-Hookean): stress against central finite differences of the energy
// and tangent against finite differences of the stress at random C = F^T F (fixed
// seed, stretches up to ~1.5 and ~2.5), the reduction to neo-Hookean at c01 = 0, the
// small-strain moduli, simple shear in closed form (sigma_12 = 2 (c10 + c01) g, exact
// for the compressible form too since J = 1) and the messages of bad parameters.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "common/core/error.hpp"
#include "forming/material/mooney_rivlin.hpp"
#include "forming/material/neo_hookean.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using fixtures::max_abs;
using ::testing::AllOf;
using ::testing::HasSubstr;

// Central-difference step in the entries of C (O(1)): truncation ~1e-12, roundoff
// ~1e-10 relative (as in materials_test.cpp).
constexpr double kFdStepC = 1e-6;
// FD stress/tangent against the analytic ones, relative to max(1, largest entry).
constexpr double kFdRel = 1e-7;
// Identities exact in exact arithmetic, relative to the size of the numbers.
constexpr double kExactRel = 1e-12;
// Moduli recovered from the tangent at C = I (inverse of a 6x6).
constexpr double kModuliRel = 1e-9;

constexpr int kPair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};

Mat3 perturbed(const Mat3& C, int J, double t) {
  Mat3 c = C;
  const int k = kPair[J][0], l = kPair[J][1];
  c(k, l) += t;
  if (k != l) c(l, k) += t;
  return c;
}

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

Mat3 random_deformation(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    Mat3 F = Mat3::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F(i, j) += amplitude * u(rng);
    if (F.determinant() > 0.3) return F;
  }
}

TEST(FormingMaterialMooneyRivlin, StressAndTangentMatchFiniteDifferences) {
  const MooneyRivlin laws[] = {MooneyRivlin(MooneyRivlinParams::from_poisson(0.3, 0.1, 0.45)),
                               MooneyRivlin(MooneyRivlinParams::from_bulk(0.1, 0.4, 50.0)),
                               MooneyRivlin(MooneyRivlinParams::from_poisson(1.0, 0.0, 0.3))};
  double worst_s = 0.0, worst_cc = 0.0;
  std::mt19937 rng(sf::test::kSeed);
  for (const MooneyRivlin& m : laws) {
    for (const double amplitude : {0.3, 0.6}) {
      for (int trial = 0; trial < 8; ++trial) {
        const Mat3 F = random_deformation(rng, amplitude);
        const Mat3 C = F.transpose() * F;
        const MaterialResponse r = m.evaluate(C, true);
        const MaterialResponse r0 = m.evaluate(C, false);
        EXPECT_EQ(r.energy, r0.energy);
        EXPECT_EQ(max_abs(r.stress - r0.stress), 0.0);
        const double es = max_abs(fd_stress(m, C, kFdStepC) - r.stress) / std::max(1.0, max_abs(r.stress));
        const double ec = max_abs(fd_tangent(m, C, kFdStepC) - r.tangent) / std::max(1.0, max_abs(r.tangent));
        EXPECT_LT(es, kFdRel) << "c01 = " << m.params().c01 << ", trial " << trial;
        EXPECT_LT(ec, kFdRel) << "c01 = " << m.params().c01 << ", trial " << trial;
        EXPECT_LT(max_abs(r.tangent - r.tangent.transpose()), kExactRel * std::max(1.0, max_abs(r.tangent)));
        worst_s = std::max(worst_s, es);
        worst_cc = std::max(worst_cc, ec);
      }
    }
  }
  std::printf("[ measured ] Mooney-Rivlin FD stress rel. error: %.3e\n", worst_s);
  std::printf("[ measured ] Mooney-Rivlin FD tangent rel. error: %.3e\n", worst_cc);
}

TEST(FormingMaterialMooneyRivlin, ReducesToNeoHookeanWithoutC01) {
  MooneyRivlinParams p;
  p.c10 = 0.7;
  p.c01 = 0.0;
  p.lambda = 3.0;
  const MooneyRivlin mr(p);
  const NeoHookean nh(NeoHookeanParams{2.0 * p.c10, p.lambda});
  std::mt19937 rng(sf::test::kSeed + 1);
  for (int trial = 0; trial < 5; ++trial) {
    const Mat3 F = random_deformation(rng, 0.4);
    const Mat3 C = F.transpose() * F;
    const MaterialResponse a = mr.evaluate(C, true);
    const MaterialResponse b = nh.evaluate(C, true);
    EXPECT_NEAR(a.energy, b.energy, kExactRel * (1.0 + std::abs(b.energy)));
    EXPECT_LT(max_abs(a.stress - b.stress), kExactRel * (1.0 + max_abs(b.stress)));
    EXPECT_LT(max_abs(a.tangent - b.tangent), kExactRel * (1.0 + max_abs(b.tangent)));
  }
}

TEST(FormingMaterialMooneyRivlin, StressFreeAtReferenceWithTheStatedModuli) {
  const MooneyRivlinParams p = MooneyRivlinParams::from_poisson(0.25, 0.15, 0.45);
  const MaterialResponse r = MooneyRivlin(p).evaluate(Mat3::Identity(), true);
  EXPECT_EQ(r.energy, 0.0);
  EXPECT_LT(max_abs(r.stress), kExactRel);
  const Mat6 compliance = r.tangent.inverse();
  EXPECT_NEAR(1.0 / compliance(3, 3), 0.8, kModuliRel);  // mu = 2 (c10 + c01)
  EXPECT_NEAR(-compliance(0, 1) / compliance(0, 0), 0.45, kModuliRel);
  EXPECT_NEAR(1.0 / compliance(0, 0), p.young_modulus(), kModuliRel * p.young_modulus());
  EXPECT_NEAR(p.poisson_ratio(), 0.45, kModuliRel);
  const MooneyRivlinParams q = MooneyRivlinParams::from_bulk(0.25, 0.15, 40.0);
  EXPECT_NEAR(q.bulk_modulus(), 40.0, kExactRel * 40.0);
}

// Simple shear F = I + g e1 (x) e2 (J = 1): sigma = 2 c10 B + 2 c01 (I1 B - B^2) - 2 (c10 +
// 2 c01) I gives sigma_12 = 2 (c10 + c01) g and sigma_11 - sigma_22 = 2 (c10 + c01) g^2.
TEST(FormingMaterialMooneyRivlin, SimpleShearInClosedForm) {
  const MooneyRivlinParams p = MooneyRivlinParams::from_bulk(0.3, 0.2, 100.0);
  const MooneyRivlin m(p);
  for (const double g : {0.1, 1.0, 2.5}) {
    Mat3 F = Mat3::Identity();
    F(0, 1) = g;
    const Mat3 sigma = cauchy_stress(F, m.evaluate(F.transpose() * F, false).stress);
    EXPECT_NEAR(sigma(0, 1), 2.0 * (p.c10 + p.c01) * g, kExactRel * (1.0 + g)) << "g = " << g;
    EXPECT_NEAR(sigma(0, 0) - sigma(1, 1), 2.0 * (p.c10 + p.c01) * g * g, kExactRel * (1.0 + g * g)) << "g = " << g;
  }
}

TEST(FormingMaterialMooneyRivlin, BadParametersAreNamed) {
  const auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected sf::InputError";
    return {};
  };
  EXPECT_THAT(message([] { MooneyRivlinParams::from_poisson(0.0, 0.1, 0.3); }),
              AllOf(HasSubstr("Mooney-Rivlin"), HasSubstr("c10:")));
  EXPECT_THAT(message([] { MooneyRivlinParams::from_poisson(0.1, -0.1, 0.3); }), HasSubstr("c01:"));
  EXPECT_THAT(message([] { MooneyRivlinParams::from_poisson(0.1, 0.1, 0.5); }), HasSubstr("nu:"));
  EXPECT_THAT(message([] { MooneyRivlinParams::from_bulk(0.1, 0.1, -2.0); }), HasSubstr("kappa:"));
  MooneyRivlinParams p;
  p.c10 = 0.1;
  p.c01 = 0.1;
  p.lambda = -10.0;
  EXPECT_THAT(message([&] { (void)MooneyRivlin{p}; }), HasSubstr("lambda:"));
}

}  // namespace
}  // namespace sf::forming

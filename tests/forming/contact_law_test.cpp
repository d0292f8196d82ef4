// Tests of the normal contact law (forming/contact/contact_law.hpp, normal_response):
//  * pressure = d energy / d(-g) and stiffness = d pressure / d(-g), by central
//    differences, at gaps across the rounded band (open, in the band, closed) for the
//    plain penalty and with an augmented-Lagrangian multiplier;
//  * C1 across the band's ends: pressure and stiffness continuous at t = +-b/2
//    (t = lambda - S_n g, b = S_n delta), p = 0 and dp = 0 at the open end, p = S_n delta / 8
//    and stiffness S_n / 2 where the surfaces just touch (g = 0, lambda = 0);
//  * the energy is continuous across the band's ends too (a potential, so the Newton
//    tangent of a frictionless tool contact is symmetric).
//  * the tail (a weak spring about the open end): its pressure and stiffness the
//    derivatives of its energy, stiffness > 0 at every gap, p = 0 with stiffness S_t at
//    the open end (a simple root), the bearing part the plain law's;
//  * the released linear tail (tail_release R): the same derivative checks, the linear
//    tail up to a parting R / 2, its tie falling to nothing with zero slope at R (C1: no
//    jump where a point leaves the search distance), energy 0 from there on.
// Why: the dome's Newton iterations were suspected to cycle through a jump of the law
// at the band's ends (data/forming/processes/notes/studies.md); these pin the law's smoothness.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/core/error.hpp"
#include "forming/contact/contact_law.hpp"

namespace sf::forming {
namespace {

constexpr double kS = 50.0;      // N/mm^3
constexpr double kBand = 0.005;  // mm
constexpr double kH = 1e-8;      // mm, finite-difference step in the gap
constexpr double kFdRel = 1e-6;  // relative to S_n (stiffness) or S_n delta (pressure)

NormalLaw penalty() {
  NormalLaw law;
  law.stiffness = kS;
  return law;
}

// Gaps across the band for a multiplier lambda (MPa): the band is centred on g = lambda / S.
std::vector<double> gaps_across(double lambda) {
  const double centre = lambda / kS;
  std::vector<double> g;
  for (double u : {-3.0, -1.0, -0.49, -0.3, -0.1, 0.0, 0.1, 0.3, 0.49, 1.0, 3.0}) g.push_back(centre + u * kBand);
  return g;
}

TEST(ContactLaw, PressureAndStiffnessAreTheDerivativesOfEnergyAndPressure) {
  for (double lambda : {0.0, 0.3}) {
    const NormalLaw law = penalty();
    for (double g : gaps_across(lambda)) {
      const NormalResponse r = normal_response(law, g, lambda, kBand);
      const NormalResponse rp = normal_response(law, g + kH, lambda, kBand);
      const NormalResponse rm = normal_response(law, g - kH, lambda, kBand);
      // d/d(-g) = -d/dg.
      const double p_fd = -(rp.energy - rm.energy) / (2 * kH);
      const double k_fd = -(rp.pressure - rm.pressure) / (2 * kH);
      EXPECT_NEAR(r.pressure, p_fd, kFdRel * kS * kBand) << "lambda " << lambda << " g " << g;
      EXPECT_NEAR(r.stiffness, k_fd, kFdRel * kS) << "lambda " << lambda << " g " << g;
      EXPECT_GE(r.pressure, 0.0);
      EXPECT_GE(r.stiffness, 0.0);
      EXPECT_LE(r.stiffness, kS);
    }
  }
}

TEST(ContactLaw, C1AcrossTheBandsEnds) {
  const NormalLaw law = penalty();
  constexpr double kTiny = 1e-12;  // mm either side of an end
  for (double lambda : {0.0, 0.3}) {
    const double centre = lambda / kS;
    for (double end : {-0.5 * kBand, 0.5 * kBand}) {  // closed end (g < centre), open end
      const NormalResponse a = normal_response(law, centre + end - kTiny, lambda, kBand);
      const NormalResponse b = normal_response(law, centre + end + kTiny, lambda, kBand);
      EXPECT_NEAR(a.pressure, b.pressure, 1e-9 * kS * kBand) << "end " << end;
      EXPECT_NEAR(a.stiffness, b.stiffness, 1e-9 * kS) << "end " << end;
      EXPECT_NEAR(a.energy, b.energy, 1e-9 * kS * kBand * kBand) << "end " << end;
    }
    // The open end: nothing, and nothing beyond it.
    const NormalResponse open = normal_response(law, centre + 0.5 * kBand, lambda, kBand);
    EXPECT_EQ(open.pressure, 0.0);
    EXPECT_EQ(open.stiffness, 0.0);
    EXPECT_EQ(normal_response(law, centre + 2 * kBand, lambda, kBand).energy, 0.0);
    // The closed end: the plain penalty p = t, S_n.
    const NormalResponse closed = normal_response(law, centre - 0.5 * kBand, lambda, kBand);
    EXPECT_NEAR(closed.pressure, 0.5 * kS * kBand, 1e-12);
    EXPECT_NEAR(closed.stiffness, kS, 1e-12);
  }
  // Touching (g = 0, no multiplier): p = S_n delta / 8, stiffness S_n / 2.
  const NormalResponse touch = normal_response(law, 0.0, 0.0, kBand);
  EXPECT_NEAR(touch.pressure, kS * kBand / 8.0, 1e-12);
  EXPECT_NEAR(touch.stiffness, kS / 2.0, 1e-12);
}

// The tail (contact_law.hpp): a weak spring about the band's open end, so that pressure and
// stiffness no longer vanish together there (the double root behind the dome's
// crawling Newton iterations, data/forming/processes/notes/dome_0_90s.md).
NormalLaw with_tail(double tail, double reach) {
  NormalLaw law = penalty();
  law.tail = tail;
  law.tail_reach = reach;
  return law;
}

TEST(ContactLaw, TailIsTheDerivativeOfItsEnergyWithStiffnessEverywhere) {
  constexpr double kTail = 0.05;  // N/mm^3 (1e-3 S_n)
  for (double reach : {0.0, 0.02}) {
    const NormalLaw law = with_tail(kTail, reach);
    std::vector<double> gaps = gaps_across(0.0);
    for (double g : {0.01, 0.05, 0.3}) gaps.push_back(g);  // well beyond the open end
    for (double g : gaps) {
      const NormalResponse r = normal_response(law, g, 0.0, kBand);
      const NormalResponse rp = normal_response(law, g + kH, 0.0, kBand);
      const NormalResponse rm = normal_response(law, g - kH, 0.0, kBand);
      EXPECT_NEAR(r.pressure, -(rp.energy - rm.energy) / (2 * kH), kFdRel * kS * kBand) << "reach " << reach << " g " << g;
      EXPECT_NEAR(r.stiffness, -(rp.pressure - rm.pressure) / (2 * kH), kFdRel * kS) << "reach " << reach << " g " << g;
      // The bearing part is the plain law's, the tail's the rest.
      const NormalResponse plain = normal_response(penalty(), g, 0.0, kBand);
      EXPECT_EQ(r.bearing, plain.pressure);
      EXPECT_EQ(r.bearing_stiffness, plain.stiffness);
      EXPECT_GT(r.stiffness, 0.0) << "reach " << reach << " g " << g;  // never a flat spot
      if (g > 0.5 * kBand) {
        EXPECT_LT(r.pressure, 0.0) << "beyond the open end: a tie";
      }
    }
    // The open end is a simple root: p = 0, stiffness S_t.
    const NormalResponse open = normal_response(law, 0.5 * kBand, 0.0, kBand);
    EXPECT_NEAR(open.pressure, 0.0, 1e-15);
    EXPECT_NEAR(open.stiffness, kTail, 1e-12);
    // The bounded tail: the tie never exceeds S_t r; the linear one grows with the gap.
    if (reach > 0.0) {
      EXPECT_GT(normal_response(law, 10.0, 0.0, kBand).pressure, -kTail * reach * (1 + 1e-12));
      EXPECT_NEAR(normal_response(law, 10.0, 0.0, kBand).pressure, -kTail * reach, 1e-9);
    } else {
      EXPECT_NEAR(normal_response(law, 1.0, 0.0, kBand).pressure, -kTail * (1.0 - 0.5 * kBand), 1e-12);
    }
  }
}

// The released tail: the linear tie of the dome's interface grew with the parting and
// dropped to nothing where a point left the search distance, a jump Newton cannot see;
// released, it is unchanged up to a parting R / 2 and falls smoothly (C1) to nothing at R.
TEST(ContactLaw, ReleasedTailFallsSmoothlyToNothing) {
  constexpr double kTail = 0.05;
  constexpr double kRelease = 0.4;  // mm
  NormalLaw law = with_tail(kTail, 0.0);
  law.tail_release = kRelease;
  EXPECT_NO_THROW(law.validate());
  const NormalLaw linear = with_tail(kTail, 0.0);
  const double open_end = 0.5 * kBand;  // the gap of the band's open end (x = 0)
  std::vector<double> gaps = gaps_across(0.0);
  for (double d : {0.01, 0.1, 0.2 - 1e-6, 0.2 + 1e-6, 0.25, 0.3, 0.35, 0.39, kRelease - 1e-6, kRelease + 1e-6, 0.6})
    gaps.push_back(open_end + d);
  double smallest = 0.0, largest_tie = 0.0;
  for (double g : gaps) {
    const NormalResponse r = normal_response(law, g, 0.0, kBand);
    const NormalResponse rp = normal_response(law, g + kH, 0.0, kBand);
    const NormalResponse rm = normal_response(law, g - kH, 0.0, kBand);
    EXPECT_NEAR(r.pressure, -(rp.energy - rm.energy) / (2 * kH), kFdRel * kS * kBand) << "g " << g;
    EXPECT_NEAR(r.stiffness, -(rp.pressure - rm.pressure) / (2 * kH), kFdRel * kS) << "g " << g;
    const NormalResponse plain = normal_response(penalty(), g, 0.0, kBand);
    EXPECT_EQ(r.bearing, plain.pressure);
    const double d = g - open_end;
    if (d < 0.5 * kRelease) {  // up to R / 2 the linear tail's pressure and stiffness
      const NormalResponse lin = normal_response(linear, g, 0.0, kBand);
      EXPECT_EQ(r.pressure, lin.pressure) << "g " << g;
      EXPECT_EQ(r.stiffness, lin.stiffness) << "g " << g;
    }
    if (d > 0.0 && d < kRelease) {
      EXPECT_LT(r.pressure, 0.0) << "a tie within the release";
    }
    smallest = std::min(smallest, r.stiffness);
    largest_tie = std::max(largest_tie, -r.pressure);
  }
  EXPECT_GT(smallest, -1.98 * kTail);  // the taper's softening, at most (1 - 6s - 3s^2 + 8s^3) S_t = -1.97 S_t
  EXPECT_LT(largest_tie, 0.55 * kTail * kRelease);  // at most about 1.08 S_t R / 2
  // The open end unchanged (p = 0, stiffness S_t).
  const NormalResponse open = normal_response(law, open_end, 0.0, kBand);
  EXPECT_NEAR(open.pressure, 0.0, 1e-15);
  EXPECT_NEAR(open.stiffness, kTail, 1e-12);
  // Pressure, stiffness and energy all reach 0 at d = R and stay there: nothing to drop.
  for (double d : {kRelease, kRelease + 1e-9, 0.7, 5.0}) {
    const NormalResponse r = normal_response(law, open_end + d, 0.0, kBand);
    EXPECT_NEAR(r.pressure, 0.0, 1e-15) << "d " << d;
    EXPECT_NEAR(r.stiffness, 0.0, 1e-12) << "d " << d;
    EXPECT_NEAR(r.energy, 0.0, 1e-15) << "d " << d;
  }
  // Just inside the release the values are within O(h^2) of 0 (C1, not a jump).
  const double h = 1e-4;
  const NormalResponse near = normal_response(law, open_end + kRelease - h, 0.0, kBand);
  EXPECT_LT(std::abs(near.pressure), 3.0 * kTail * kRelease * (h / (0.5 * kRelease)) * (h / (0.5 * kRelease)));
  EXPECT_LT(std::abs(near.stiffness), 13.0 * kTail * h / (0.5 * kRelease));  // slope 12 S_t / L
  // Continuous at d = R / 2 (value and slope; the energy too).
  const NormalResponse a = normal_response(law, open_end + 0.5 * kRelease - 1e-9, 0.0, kBand);
  const NormalResponse b = normal_response(law, open_end + 0.5 * kRelease + 1e-9, 0.0, kBand);
  EXPECT_NEAR(a.pressure, b.pressure, 3e-9 * kTail);  // 2e-9 x the slope S_t
  EXPECT_NEAR(a.stiffness, b.stiffness, 1e-7);
  EXPECT_NEAR(a.energy, b.energy, 1e-10);
  law.tail_release = -0.1;
  EXPECT_THROW(law.validate(), InputError);
}

TEST(ContactLaw, TailIsRejectedWhereItCannotWork) {
  NormalLaw law = with_tail(-1.0, 0.0);
  EXPECT_THROW(law.validate(), InputError);
  law = with_tail(0.1, -0.01);
  EXPECT_THROW(law.validate(), InputError);
  law = with_tail(0.1, 0.0);
  law.augmented = true;
  law.tolerance = 1e-3;
  EXPECT_THROW(law.validate(), InputError);
  law.augmented = false;
  EXPECT_NO_THROW(law.validate());
}

}  // namespace
}  // namespace sf::forming

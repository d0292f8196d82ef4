// Fit weights from per-point sigma (gsa/weights.hpp): equal sigmas give the unweighted fit,
// a point with a huge sigma has no influence, noisier points with larger given sigma hurt
// less than unweighted, and the option turns weighting off.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "gsa/accuracy.hpp"
#include "gsa/analysis.hpp"
#include "gsa/synthetic.hpp"
#include "gsa/weights.hpp"

namespace sf::gsa {
namespace {

GridData dome(int n, double noise, unsigned seed, std::vector<ExactStrain>* exact = nullptr) {
  SyntheticGridOptions go;
  go.n = n;
  go.noise = noise;
  go.seed = seed;
  return make_synthetic_grid(synthetic_case("dome"), go, exact);
}

// Explicit smoothing weights (no automatic choice): the fits are plain weighted least squares.
AnalyseOptions explicit_smoothing() {
  AnalyseOptions o;
  o.smoothing.delta = 1e3;
  o.smoothing.gamma = 0.0;
  o.smoothing.beta = 0.0;
  o.smoothing.alpha = 0.0;
  return o;
}

double max_strain_difference(const AnalysisResult& a, const AnalysisResult& b, Index skip = -1) {
  double worst = 0;
  for (std::size_t p = 0; p < a.points.size(); ++p) {
    if (static_cast<Index>(p) == skip || !a.points[p].strain || !b.points[p].strain) continue;
    worst = std::max({worst, std::abs(a.points[p].strain->lambda1 - b.points[p].strain->lambda1),
                      std::abs(a.points[p].strain->lambda2 - b.points[p].strain->lambda2)});
  }
  return worst;
}

TEST(GsaWeights, NormalisedToTheMedianSigma) {
  const std::vector<double> sigma = {0.01, 0.02, 0.01, std::nan(""), 0.0, 1e9, -1.0};
  const SigmaWeights w = sigma_weights(sigma, {0, 1, 2, 3, 4, 5, 6});
  EXPECT_TRUE(w.used);
  EXPECT_EQ(w.n_with_sigma, 4);  // 0.01, 0.02, 0.01, 1e9
  EXPECT_EQ(w.sigma_ref, 0.02);  // median of {0.01, 0.01, 0.02, 1e9}: the upper middle
  EXPECT_DOUBLE_EQ(w.weight[0], 4.0);
  EXPECT_EQ(w.weight[1], 1.0);
  EXPECT_EQ(w.weight[3], 1.0);                                       // no sigma
  EXPECT_DOUBLE_EQ(w.weight[4], 1.0 / (kSigmaFloor * kSigmaFloor));  // zero: the floor
  EXPECT_EQ(w.n_floored, 1);
  EXPECT_EQ(w.weight[5], 0.0);  // negligible: left out
  EXPECT_EQ(w.n_left_out, 1);
  EXPECT_EQ(w.weight[6], 1.0);  // negative: none
  EXPECT_FALSE(sigma_weights(sigma, {0, 1}, false).used);
  EXPECT_FALSE(sigma_weights({}, {0, 1}).used);
}

TEST(GsaWeights, EqualSigmasReproduceTheUnweightedFit) {
  GridData g = dome(17, 0.01, 3);
  const AnalysisResult plain = analyse(g, AnalyseOptions{});
  g.sigma_undeformed.assign(static_cast<std::size_t>(g.n_points()), 0.0137);
  g.sigma_deformed = g.sigma_undeformed;
  const AnalysisResult weighted = analyse(g, AnalyseOptions{});
  EXPECT_TRUE(weighted.weights_deformed.used);
  EXPECT_EQ(weighted.weights_deformed.min_weight, 1.0);
  EXPECT_EQ(weighted.weights_deformed.max_weight, 1.0);
  EXPECT_LE(max_strain_difference(plain, weighted), 1e-13);
  EXPECT_EQ(plain.gauge_length, weighted.gauge_length);
}

TEST(GsaWeights, PointWithHugeSigmaHasNoInfluence) {
  // One mark displaced 0.3 mm in its deformed state (30 x the noise) and given a huge
  // sigma: the fit equals the fit without that mark. Outlier flagging off, so the weight
  // alone does it.
  GridData g = dome(15, 0.01, 5);
  const Index bad = 7 * 15 + 6;
  g.deformed(bad, 2) += 0.3;
  AnalyseOptions o = explicit_smoothing();
  o.outliers.sigma = 1e9;
  GridData without = g;
  without.deformed.row(bad).setConstant(std::nan(""));
  without.undeformed.row(bad).setConstant(std::nan(""));
  const AnalysisResult ref = analyse(without, o);
  g.sigma_undeformed.assign(static_cast<std::size_t>(g.n_points()), 0.01);
  g.sigma_undeformed[static_cast<std::size_t>(bad)] = 1e9;
  g.sigma_deformed = g.sigma_undeformed;
  const AnalysisResult weighted = analyse(g, o);
  o.sigma_weights = false;
  const AnalysisResult unweighted = analyse(g, o);
  const double d_weighted = max_strain_difference(ref, weighted, bad);
  const double d_unweighted = max_strain_difference(ref, unweighted, bad);
  EXPECT_LT(d_weighted, 1e-9);    // measured ~1e-14
  EXPECT_GT(d_unweighted, 1e-4);  // the displaced mark does move the unweighted fit
  // With automatic smoothing: a huge sigma of the deformed position only is the same as no
  // deformed position (negligible weights are 0: left out of the choice's counts too).
  AnalyseOptions automatic;
  automatic.outliers.sigma = 1e9;
  GridData deformed_only = g, missing = g;
  deformed_only.sigma_undeformed.assign(static_cast<std::size_t>(g.n_points()), 0.01);
  missing.deformed.row(bad).setConstant(std::nan(""));
  missing.sigma_undeformed = deformed_only.sigma_undeformed;
  const AnalysisResult ref_auto = analyse(missing, automatic);
  const AnalysisResult weighted_auto = analyse(deformed_only, automatic);
  EXPECT_EQ(weighted_auto.weights_deformed.n_left_out, 1);
  EXPECT_EQ(ref_auto.gauge_length, weighted_auto.gauge_length);
  EXPECT_LT(max_strain_difference(ref_auto, weighted_auto, bad), 1e-12);
  EXPECT_TRUE(weighted_auto.points[static_cast<std::size_t>(bad)].strain.has_value());  // still gets a strain
}

TEST(GsaWeights, NoisySubsetWithLargerSigmaGivesSmallerStrainErrorThanUnweighted) {
  // A fifth of the marks measured 6 x worse, and saying so in their sigma.
  std::vector<ExactStrain> exact;
  GridData g = dome(25, 0.0, 1, &exact);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double base = 0.005, bad = 0.03;
  g.sigma_undeformed.assign(static_cast<std::size_t>(g.n_points()), base);
  g.sigma_deformed = g.sigma_undeformed;
  for (Index p = 0; p < g.n_points(); ++p) {
    const bool noisy = u(rng) < 0.2;
    const double s = noisy ? bad : base;
    g.sigma_undeformed[static_cast<std::size_t>(p)] = g.sigma_deformed[static_cast<std::size_t>(p)] = s;
    for (int c = 0; c < 3; ++c) {
      g.undeformed(p, c) += s * gauss(rng);
      g.deformed(p, c) += s * gauss(rng);
    }
  }
  AnalyseOptions o;
  const StrainError weighted = strain_error(g, analyse(g, o), exact);
  o.sigma_weights = false;
  const StrainError unweighted = strain_error(g, analyse(g, o), exact);
  std::printf("RMS strain error: weighted %.3g, unweighted %.3g\n", weighted.rms(), unweighted.rms());
  EXPECT_LT(weighted.rms(), 0.8 * unweighted.rms()) << weighted.rms() << " vs " << unweighted.rms();
}

}  // namespace
}  // namespace sf::gsa

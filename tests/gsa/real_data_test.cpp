// gsa on measurements shaped like real ones (gsa/synthetic_measurement.hpp): spatially
// correlated noise as digital image correlation gives, a localised neck on a tensile
// strip, a dimple, isolated blunders. Seeded; the figures of the whole study are
// printed by bench/gsa_realdata_bench and bench/gsa_blunder_bench (docs/theory/strain.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "common/io/grid_file.hpp"
#include "gsa/analysis.hpp"
#include "gsa/blunders.hpp"
#include "gsa/frame_mesh.hpp"
#include "gsa/local_fit.hpp"
#include "gsa/synthetic_measurement.hpp"

namespace sf::gsa {
namespace {

double green(double l) { return 0.5 * (l * l - 1.0); }

// RMS error of the Green principal strains at points at least two spacings inside the
// outline; `get` gives a point's stretches (false: none).
template <class Get>
double interior_rms(const SyntheticMeasurement& m, double spacing, Get get) {
  double sum = 0.0;
  Index n = 0;
  for (std::size_t p = 0; p < m.exact.size(); ++p) {
    double l1 = 0, l2 = 0;
    if (m.edge_distance[p] < 2.0 * spacing || !get(static_cast<Index>(p), l1, l2)) continue;
    const double d1 = green(l1) - green(m.exact[p].lambda1), d2 = green(l2) - green(m.exact[p].lambda2);
    sum += d1 * d1 + d2 * d2;
    n += 2;
  }
  return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

double analysis_rms(const SyntheticMeasurement& m, double spacing, const AnalysisResult& r) {
  return interior_rms(m, spacing, [&](Index p, double& l1, double& l2) {
    const auto& s = r.points[static_cast<std::size_t>(p)].strain;
    if (!s) return false;
    l1 = s->lambda1, l2 = s->lambda2;
    return true;
  });
}

Index flagged(const AnalysisResult& r) {
  return std::count_if(r.points.begin(), r.points.end(), [](const PointResult& p) { return p.flag.has_value(); });
}

Index without_strain(const AnalysisResult& r) {
  return std::count_if(r.points.begin(), r.points.end(), [](const PointResult& p) { return !p.strain; });
}

// DIC-like noise: correlated over `spacings` point spacings (sigma 0.4 % of the
// spacing) plus 30 % of it independent, in both states.
SyntheticMeasurementOptions dic_like(const PointLayout& layout, double spacings, unsigned seed) {
  SyntheticMeasurementOptions o;
  o.layout = layout;
  const double sigma = 0.004 * layout.spacing;
  o.undeformed_noise = o.deformed_noise = NoiseModel{sigma, spacings * layout.spacing, 0.3 * sigma};
  o.seed = seed;
  return o;
}

PointLayout plate() {
  PointLayout p;
  p.length_x = p.length_y = 100.0;
  p.spacing = 2.5;
  return p;
}

PointLayout tensile_strip() {  // a gauge section at the density of a stereo-DIC export
  PointLayout p;
  p.length_x = 30.0;
  p.length_y = 12.0;
  p.spacing = 0.3;
  return p;
}

// RMS strain error of the 24-nearest-neighbour local fit of F (the yardstick).
double local_fit_rms(const SyntheticMeasurement& m, double spacing) {
  const auto local = local_fit_stretches(m.grid, 24);
  return interior_rms(m, spacing, [&](Index p, double& l1, double& l2) {
    if (!local[static_cast<std::size_t>(p)]) return false;
    l1 = local[static_cast<std::size_t>(p)]->lambda1, l2 = local[static_cast<std::size_t>(p)]->lambda2;
    return true;
  });
}

// Correlated noise over 2.5 spacings: the noise model finds its length and amplitudes,
// and the smoothing it chooses is far better than cross-validation's (which takes the
// correlated error for signal) and than the local 24-neighbour fit of F.
// Measured (seed 1): L 2.19 spacings, sigma_c 0.91 and sigma_w 0.96 of the truth; RMS
// strain error 5.0e-4 against 4.9e-4 for the best fixed smoothing, 1.8e-3 for the
// local fit; GCV several times worse.
TEST(GsaRealData, CorrelatedNoiseIsModelledAndSmoothedAsItShouldBe) {
  const PointLayout layout = plate();
  const SyntheticMeasurement m = make_measurement(deformation_of(synthetic_case("stretch")), dic_like(layout, 2.5, 1));
  const AnalysisResult noise_model = analyse(m.grid, {});
  const double d = layout.spacing;
  EXPECT_NEAR(noise_model.noise_undeformed.effective_length() / (2.5 * d), 1.0, 0.3);
  // The deformed model is of the displacement: both states' noise, sqrt(2) x each.
  const double sc = 0.004 * d * std::sqrt(2.0), sw = 0.3 * sc;
  EXPECT_NEAR(noise_model.noise.sigma_correlated / sc, 1.0, 0.25);
  EXPECT_NEAR(noise_model.noise.sigma_white / sw, 1.0, 0.35);
  AnalyseOptions gcv_options;
  gcv_options.smoothing.rule = SmoothingRule::kGcv;
  const AnalysisResult gcv = analyse(m.grid, gcv_options);
  const double e_model = analysis_rms(m, d, noise_model), e_gcv = analysis_rms(m, d, gcv);
  const double e_local = local_fit_rms(m, d);
  EXPECT_LT(e_model, 0.5 * e_gcv) << "noise model " << e_model << ", GCV " << e_gcv;
  EXPECT_LT(e_model, 0.5 * e_local) << "noise model " << e_model << ", 24-neighbour fit " << e_local;
  EXPECT_EQ(flagged(noise_model), 0);
  EXPECT_EQ(noise_model.smoothing_criterion, "Cp");
}

// Noise correlated over 5 spacings (12.5 mm) on the 100 mm plate, seed 1: the light pilots
// of the deformed estimate take most of it up themselves and found 0.15 x its amplitude, so
// Cp under-smoothed to 1.1 x the 24-neighbour fit's error. The blank's heavy pilots see it
// (0.76 x): its amplitude, sqrt(2) x for both states, is the floor of the deformed one.
// Measured (seed 1): sigma_c 0.76 x the truth, error 0.68 x the local fit's (the issue's
// 0.5 is not reached here; the oracle, the best fixed smoothing, gets 0.56 on two seeds).
TEST(GsaRealData, LongCorrelatedNoiseIsSeenFromTheBlank) {
  const PointLayout layout = plate();
  const SyntheticMeasurement m = make_measurement(deformation_of(synthetic_case("stretch")), dic_like(layout, 5.0, 1));
  const AnalysisResult r = analyse(m.grid, {});
  const double d = layout.spacing;
  const double sc = 0.004 * d * std::sqrt(2.0);
  EXPECT_GT(r.noise.sigma_correlated / sc, 0.5);
  EXPECT_LT(r.noise.sigma_correlated / sc, 2.0);
  EXPECT_EQ(r.smoothing_criterion, "Cp");
  const double e = analysis_rms(m, d, r), e_local = local_fit_rms(m, d);
  EXPECT_LT(e, 0.8 * e_local) << "surface fit " << e << ", 24-neighbour fit " << e_local;
  EXPECT_EQ(flagged(r), 0);
  EXPECT_EQ(without_strain(r), 0);
}

// The MatchID-like rubber strip (20 x 10 mm, about 450 jittered points 0.7 mm apart, 23 %
// strain) with noise correlated over one spacing, seed 1: the blank's estimate of the
// length is 0.85 spacings, which the old rule (length >= one spacing) took for independent
// noise, so GCV chose a gauge of 0.6 spacings and 3.3 x the 24-neighbour fit's error
// (the "chose a gauge length of about one point spacing"). Neighbouring points'
// noise is correlated by 0.5 there: Cp. Measured: gauge 5.7 spacings, 0.20 x the local fit.
TEST(GsaRealData, RubberStripWithNoiseCorrelatedOverASpacingIsSmoothed) {
  PointLayout layout;
  layout.kind = PointLayout::Kind::kJittered;
  layout.length_x = 20.0;
  layout.length_y = 10.0;
  layout.spacing = 0.7;
  SyntheticMeasurementOptions o;
  o.layout = layout;
  const double sigma = 0.005 * layout.spacing;
  o.undeformed_noise = o.deformed_noise = NoiseModel{sigma, layout.spacing, 0.3 * sigma};
  o.seed = 1;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.23, 0.23, 1.0), o);
  const AnalysisResult r = analyse(m.grid, {});
  EXPECT_EQ(r.smoothing_criterion, "Cp");
  EXPECT_GT(r.gauge_length, 2.0 * r.mark_spacing);
  const double e = analysis_rms(m, layout.spacing, r), e_local = local_fit_rms(m, layout.spacing);
  EXPECT_LT(e, 0.5 * e_local) << "surface fit " << e << ", 24-neighbour fit " << e_local;
  EXPECT_EQ(without_strain(r), 0);
}

// The rule that picks Cp over GCV: independent noise on a grid fits as a short length
// (0.5-0.7 spacings, correlation at one spacing 0.08-0.16, gsa_accuracy_bench's grid) and
// stays with GCV; a length just under a spacing with the noise mostly correlated counts.
TEST(GsaRealData, CorrelationAtOneSpacingDecidesTheRule) {
  const double d = 1.0;
  auto estimate = [](double sigma_c, double length, double sigma_w) {
    NoiseEstimate e;
    e.sigma_correlated = sigma_c, e.correlation_length = length, e.sigma_white = sigma_w;
    return e;
  };
  const NoiseEstimate none;
  EXPECT_FALSE(none.correlated_over(d));
  const NoiseEstimate white_on_grid = estimate(0.0065, 0.707, 0.0076);  // 21 x 21 marks, 0.01 white noise
  EXPECT_LT(white_on_grid.correlation_at(d), 0.2);
  EXPECT_FALSE(white_on_grid.correlated_over(d));
  const NoiseEstimate short_length = estimate(0.0035, 0.85, 0.0003);  // the rubber strip's blank, seed 1
  EXPECT_GT(short_length.correlation_at(d), 0.45);
  EXPECT_TRUE(short_length.correlated_over(d));
  const NoiseEstimate long_length = estimate(0.01, 5.0, 0.003);
  EXPECT_TRUE(long_length.correlated_over(d));
  const NoiseEstimate mostly_white = estimate(0.001, 5.0, 0.01);  // correlated part below 30 %: independent
  EXPECT_FALSE(mostly_white.correlated_over(d));
}

// A neck from 20 % to 100 % engineering strain, about 7 spacings wide, under DIC-like
// noise: no point is flagged, every point gets a strain, the peak is kept (the issue:
// an earlier rule flagged the whole neck and reported a fifth of its peak).
TEST(GsaRealData, NeckIsNeverFlaggedAndItsPeakIsKept) {
  const PointLayout layout = tensile_strip();
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.2, 1.0, 1.0), dic_like(layout, 2.5, 1));
  const AnalysisResult r = analyse(m.grid, {});
  EXPECT_LE(flagged(r), m.grid.n_points() / 1000);
  EXPECT_EQ(without_strain(r), 0);
  double peak = 0.0, peak_exact = 0.0;
  for (std::size_t p = 0; p < m.exact.size(); ++p) {
    peak_exact = std::max(peak_exact, green(m.exact[p].lambda1));
    if (r.points[p].strain) peak = std::max(peak, green(r.points[p].strain->lambda1));
  }
  EXPECT_NEAR(peak / peak_exact, 1.0, 0.05) << "peak " << peak << " of " << peak_exact;
  EXPECT_GT(r.relaxed_elements, 0) << "the neck's elements get a lighter smoothing";
  EXPECT_GT(r.local_gauge_length, 0.0);
  EXPECT_LT(r.local_gauge_length, r.gauge_length);
}

// A neck narrower than an element (width parameter 0.4 mm, peak 30 % engineering strain,
// on 1.2 mm elements of the automatic mesh): the misfit band is found and the mesh refined
// there, so the peak is kept within 5 % and the strain error is about half the
// 24-nearest-neighbour local fit's. Without refinement (measured, seed 1): peak 12 % high,
// error 0.77 of the local fit's. Refined in halves (0.6 mm): 0.46; in thirds (0.4 mm, as
// now, for the 100 % neck's peak, next test): 0.52, so the bound is 0.55 (the bench's
// neckn30 cases: 0.18-0.48 of the local fit's, 0-14 % more than with halves).
TEST(GsaRealData, NeckNarrowerThanAnElementIsRefined) {
  const PointLayout layout = tensile_strip();
  SyntheticMeasurementOptions o = dic_like(layout, 1.0, 1);
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.1, 0.3, 0.4), o);
  const AnalysisResult r = analyse(m.grid, {});
  EXPECT_GE(r.refinement_rounds, 1);
  EXPECT_LT(r.smallest_element, 1.0);
  EXPECT_EQ(without_strain(r), 0);
  EXPECT_LE(flagged(r), m.grid.n_points() / 1000);
  double peak = 0.0, peak_exact = 0.0;
  for (std::size_t p = 0; p < m.exact.size(); ++p) {
    peak_exact = std::max(peak_exact, green(m.exact[p].lambda1));
    if (r.points[p].strain) peak = std::max(peak, green(r.points[p].strain->lambda1));
  }
  EXPECT_NEAR(peak / peak_exact, 1.0, 0.05) << "peak " << peak << " of " << peak_exact;
  const double e_local = local_fit_rms(m, layout.spacing);
  const double e = analysis_rms(m, layout.spacing, r);
  EXPECT_LT(e, 0.55 * e_local) << "surface fit " << e << ", 24-neighbour fit " << e_local;
  // Switched off with the local smoothing: the uniform mesh.
  AnalyseOptions plain;
  plain.smoothing.local = false;
  EXPECT_EQ(analyse(m.grid, plain).refinement_rounds, 0);
}

// A 100 % neck of width parameter 0.4 mm (1.3 spacings) on the strip, noise correlated over
// 2.5 spacings (sigma 0.5 % of the spacing), seed 1. Its peak lies at the strip's edges,
// where the neck's contraction shears the strip (the shear Y dmu/dX grows with the distance
// from the axis). Split in halves (0.6 mm) the refined elements let that shear ring between
// the marks: peak 1.094 x the exact one, at the edge. Split in thirds (0.4 mm): 1.019.
TEST(GsaRealData, NarrowHundredPercentNeckKeepsItsPeakAtTheEdges) {
  const PointLayout layout = tensile_strip();
  SyntheticMeasurementOptions o;
  o.layout = layout;
  const double sigma = 0.005 * layout.spacing;
  o.undeformed_noise = o.deformed_noise = NoiseModel{sigma, 2.5 * layout.spacing, 0.3 * sigma};
  o.seed = 1;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.2, 1.0, 0.4), o);
  const AnalysisResult r = analyse(m.grid, {});
  EXPECT_GE(r.refinement_rounds, 1);
  EXPECT_LT(r.smallest_element, 1.5 * layout.spacing);
  EXPECT_EQ(without_strain(r), 0);
  EXPECT_LE(flagged(r), m.grid.n_points() / 1000);
  double peak = 0.0, peak_exact = 0.0;
  for (std::size_t p = 0; p < m.exact.size(); ++p) {
    peak_exact = std::max(peak_exact, green(m.exact[p].lambda1));
    if (r.points[p].strain) peak = std::max(peak, green(r.points[p].strain->lambda1));
  }
  EXPECT_NEAR(peak / peak_exact, 1.0, 0.05) << "peak " << peak << " of " << peak_exact;
}

// A 30 % neck about 1 mm wide (2-3 elements of the automatic mesh) under DIC-like noise
// correlated over 5 spacings (sigma 0.5 % of the spacing, 30 % of it independent), seed 1:
// the neck's misfit is no noise. The old estimate took it for noise, 23 x too high at the
// light pilots where the misfit stands out less against the median, so the smoothing
// flattened the peak (0.219 of the exact 0.346 on the first, uniform mesh; the refinement
// round then caught the misfit, with 1.6 x the error of the other seeds). Measured after:
// sigma_c 0.86 of the truth, peak 0.348, no refinement, error 0.62 of the 24-neighbour fit.
TEST(GsaRealData, NeckUnderLongCorrelatedNoiseIsNotTakenForNoise) {
  const PointLayout layout = tensile_strip();
  SyntheticMeasurementOptions o;
  o.layout = layout;
  const double sigma = 0.005 * layout.spacing;
  o.undeformed_noise = o.deformed_noise = NoiseModel{sigma, 5.0 * layout.spacing, 0.3 * sigma};
  o.seed = 1;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.1, 0.3, 1.0), o);
  double peak_exact = 0.0;
  for (const ExactStrain& e : m.exact) peak_exact = std::max(peak_exact, green(e.lambda1));
  auto peak_of = [&](const AnalysisResult& r) {
    double peak = 0.0;
    for (const PointResult& p : r.points)
      if (p.strain) peak = std::max(peak, green(p.strain->lambda1));
    return peak;
  };
  // The first round alone (the uniform automatic mesh): the estimate and the peak.
  const AnalyseOptions defaults;
  const AnalysisResult first = analyse_deformed(analyse_undeformed(m.grid, defaults), m.grid, defaults);
  const double truth = sigma * std::sqrt(2.0);  // both states' noise in the displacement
  EXPECT_NEAR(first.noise.sigma_correlated / truth, 1.0, 0.35);
  EXPECT_NEAR(peak_of(first) / peak_exact, 1.0, 0.05) << "peak " << peak_of(first) << " of " << peak_exact;
  // The whole analysis: nothing to refine, every point a strain, better than the local fit.
  const AnalysisResult r = analyse(m.grid, defaults);
  EXPECT_EQ(r.refinement_rounds, 0);
  EXPECT_EQ(without_strain(r), 0);
  EXPECT_LE(flagged(r), m.grid.n_points() / 1000);
  EXPECT_NEAR(peak_of(r) / peak_exact, 1.0, 0.05);
  const double e_local = local_fit_rms(m, layout.spacing);
  EXPECT_LT(analysis_rms(m, layout.spacing, r), 0.75 * e_local);
}

// Smooth parts are not refined: the dome under correlated noise and the wavy part.
TEST(GsaRealData, SmoothPartsAreNotRefined) {
  const SyntheticMeasurement dome = make_measurement(deformation_of(synthetic_case("dome")), dic_like(plate(), 2.5, 2));
  EXPECT_EQ(analyse(dome.grid, {}).refinement_rounds, 0);
  PointLayout wide = plate();
  wide.spacing = 1.0;
  SyntheticMeasurementOptions o;
  o.layout = wide;
  o.undeformed_noise = o.deformed_noise = NoiseModel{0.0, 0.0, 0.01};
  const SyntheticMeasurement wavy = make_measurement(deformation_of(synthetic_case("wavy")), o);
  EXPECT_EQ(analyse(wavy.grid, {}).refinement_rounds, 0);
}

// The strain test of the local relaxation (gsa/local_smoothing.hpp) runs where
// cross-validation chose the heaviest smoothing it may; a homogeneous stretch under
// independent noise is such a part (its deformation is in the penalty's null space), and
// holds no feature: the residuals' local gradients are noise, their scores near 1 (under
// 6), so no element is relaxed. With the threshold at 4 the test relaxes one element in
// each seed here (measured; at 2 without the median scaling, 7 and 42).
TEST(GsaRealData, StrainTestRelaxesNothingOnAHomogeneousStretch) {
  for (unsigned seed : {1u, 2u}) {
    SyntheticMeasurementOptions o;
    o.layout = plate();
    o.undeformed_noise = o.deformed_noise = NoiseModel{0.0, 0.0, 0.004 * o.layout.spacing};
    o.seed = seed;
    const SyntheticMeasurement m = make_measurement(deformation_of(synthetic_case("stretch")), o);
    const AnalysisResult r = analyse(m.grid, {});
    EXPECT_GE(r.log10_delta_optimum, 5.5) << "seed " << seed;  // the test ran
    EXPECT_EQ(r.relaxed_elements, 0) << "seed " << seed;
  }
}

// A 50 um dimple 1.5 mm across on a strip: a coherent feature, never flagged.
TEST(GsaRealData, DimpleIsNotFlagged) {
  const PointLayout layout = tensile_strip();
  const SyntheticMeasurement m =
      make_measurement(dimple_deformation(1.1, 0.95, 0.05, 1.5, 0.0, 0.0), dic_like(layout, 1.0, 2));
  const AnalysisResult r = analyse(m.grid, {});
  EXPECT_LE(flagged(r), m.grid.n_points() / 1000);
  EXPECT_EQ(without_strain(r), 0);
}

// The same dimple under independent noise (0.5 % of the spacing): cross-validation,
// which must follow the dimple's 50 um, chose a weight 1000 x lighter than the best one
// for the strain (a gauge of 2.5 spacings). The residual test, run there as a trial
// that GCV judges, relaxes the dimple's elements and the rest is smoothed 100 x more:
// measured (seed 1) the RMS strain error 2.2e-4 -> 1.0e-4 (the best fixed smoothing
// chosen with the exact answer: 6.9e-5); without the trial nothing is relaxed.
TEST(GsaRealData, DimpleUnderIndependentNoiseIsRelaxedAndTheRestSmoothed) {
  const PointLayout layout = tensile_strip();
  SyntheticMeasurementOptions o;
  o.layout = layout;
  o.undeformed_noise = o.deformed_noise = NoiseModel{0.0, 0.0, 0.005 * layout.spacing};
  o.seed = 1;
  const SyntheticMeasurement m = make_measurement(dimple_deformation(1.1, 0.95, 0.05, 1.5, 0.0, 0.0), o);
  const AnalysisResult r = analyse(m.grid, {});
  AnalyseOptions plain;
  plain.smoothing.local = false;
  const AnalysisResult rp = analyse(m.grid, plain);
  EXPECT_EQ(without_strain(r), 0);
  EXPECT_LE(flagged(r), m.grid.n_points() / 1000);
  EXPECT_GT(r.relaxed_elements, 0);
  EXPECT_LT(r.relaxed_elements, r.elements1 * r.elements2 / 4) << "the dimple's elements, not the strip";
  EXPECT_GT(r.log10_delta_optimum, rp.log10_delta_optimum + 1.0) << "the rest smoothed more";
  const double e = analysis_rms(m, layout.spacing, r), e_plain = analysis_rms(m, layout.spacing, rp);
  EXPECT_LT(e, 0.6 * e_plain) << "relaxed " << e << ", one weight " << e_plain;
}

// The trial is kept only where GCV falls clearly: on the dome under independent noise
// relaxing raised GCV (and the strain error 1.24 x, measured), so nothing is relaxed.
TEST(GsaRealData, TrialRelaxationIsRefusedOnASmoothDome) {
  for (unsigned seed : {1u, 2u}) {
    SyntheticMeasurementOptions o;
    o.layout = plate();
    o.undeformed_noise = o.deformed_noise = NoiseModel{0.0, 0.0, 0.004 * o.layout.spacing};
    o.seed = seed;
    const SyntheticMeasurement m = make_measurement(deformation_of(synthetic_case("dome")), o);
    const AnalysisResult r = analyse(m.grid, {});
    EXPECT_LT(r.log10_delta_optimum, 5.5) << "seed " << seed;  // not the strain test's case
    EXPECT_EQ(r.relaxed_elements, 0) << "seed " << seed;
  }
}

// Isolated blunders of 10 noise sigmas in the deformed state, one per 500 points, on a
// dome measured with correlated noise: all found, each flagged mark still has a strain,
// and the clean copy has at most 0.1 % flagged.
TEST(GsaRealData, IsolatedBlundersAreFoundAndKeepAStrain) {
  const PointLayout layout = plate();
  SyntheticMeasurementOptions o = dic_like(layout, 1.0, 3);
  const Deformation dome = deformation_of(synthetic_case("dome"));
  const SyntheticMeasurement clean = make_measurement(dome, o);
  const std::vector<bool> all(static_cast<std::size_t>(clean.grid.n_points()), true);
  const BlunderCheck none = find_blunders(clean.grid.undeformed, clean.grid.deformed, all, false);
  EXPECT_LE(none.n_flagged(), clean.grid.n_points() / 1000);
  o.blunders = static_cast<int>(clean.grid.n_points() / 500);
  o.blunder_size = 10.0 * o.deformed_noise.sigma_total();
  const SyntheticMeasurement m = make_measurement(dome, o);
  ASSERT_GE(m.blunder_points.size(), 3u);
  const AnalysisResult r = analyse(m.grid, {});
  for (Index p : m.blunder_points) {
    const PointResult& pr = r.points[static_cast<std::size_t>(p)];
    EXPECT_EQ(pr.status, kStatusOutlierDeformed) << m.grid.ids[static_cast<std::size_t>(p)];
    EXPECT_TRUE(pr.strain) << m.grid.ids[static_cast<std::size_t>(p)];
    if (pr.flag) {
      EXPECT_GT(pr.flag->deviation, pr.flag->threshold);
    }
  }
  EXPECT_LE(flagged(r), static_cast<Index>(m.blunder_points.size()) + m.grid.n_points() / 1000);
}

// Stereo-like noise: the out-of-plane (z) noise 5 x the in-plane noise, in both states,
// correlated over 2.5 spacings, on the tensile strip with a 100 % neck; isolated blunders
// of 10 in-plane sigmas in the plane, one per 500 points. One noise level for all three
// components is set by the z noise: the one-level rule (BlunderOptions::two_level =
// false, the rule before) flags clean points of the neck (53 of 3 x 4141 in
// gsa_blunder_bench) and misses blunders (22 of 24). Under the robust noise covariance
// every blunder is found and the clean copy has at most 0.1 % flagged.
TEST(GsaRealData, InPlaneBlundersUnderStereoNoiseAreFound) {
  const PointLayout layout = tensile_strip();
  SyntheticMeasurementOptions o = dic_like(layout, 2.5, 1);
  o.undeformed_noise.normal_factor = o.deformed_noise.normal_factor = 5.0;
  const Deformation neck = neck_deformation(0.2, 1.0, 1.0);
  const SyntheticMeasurement clean = make_measurement(neck, o);
  const std::vector<bool> all(static_cast<std::size_t>(clean.grid.n_points()), true);
  const BlunderCheck none = find_blunders(clean.grid.undeformed, clean.grid.deformed, all, false);
  BlunderOptions one_level;
  one_level.two_level = false;
  const BlunderCheck none_one = find_blunders(clean.grid.undeformed, clean.grid.deformed, all, false, one_level);
  EXPECT_LE(none.n_flagged(), clean.grid.n_points() / 1000);
  EXPECT_GT(none_one.n_flagged(), clean.grid.n_points() / 1000);  // what the change mends
  // The two levels found: along the cameras' axis (z) several times across it.
  EXPECT_GT(none.noise_axis, 3.0 * none.noise_across);
  EXPECT_GT(std::abs(none.axis.z()), 0.95);
  o.blunders = static_cast<int>(clean.grid.n_points() / 500);
  o.blunder_size = 10.0 * o.deformed_noise.sigma_total();
  o.blunders_in_plane = true;
  const SyntheticMeasurement m = make_measurement(neck, o);
  ASSERT_GE(m.blunder_points.size(), 3u);
  const BlunderCheck two = find_blunders(m.grid.undeformed, m.grid.deformed, all, false);
  const BlunderCheck one = find_blunders(m.grid.undeformed, m.grid.deformed, all, false, one_level);
  Index found_two = 0, found_one = 0;
  for (Index p : m.blunder_points) {
    found_two += two.flagged[static_cast<std::size_t>(p)] ? 1 : 0;
    found_one += one.flagged[static_cast<std::size_t>(p)] ? 1 : 0;
  }
  EXPECT_EQ(found_two, static_cast<Index>(m.blunder_points.size()));
  EXPECT_LT(found_one, found_two);  // seed 1: 7 of 8, and 15 clean points flagged
  EXPECT_LE(two.n_flagged(), static_cast<Index>(m.blunder_points.size()) + m.grid.n_points() / 1000);
}

// The two noise levels of the deformed data (NoiseEstimate::sigma_tangent, sigma_normal)
// as the analysis reports them: about 5 : 1 under stereo-like noise, about 1 : 1 under
// isotropic noise, on the sheared plate (in plane: z stays the normal) with noise correlated over
// one spacing.
TEST(GsaRealData, TwoNoiseLevelsAreEstimated) {
  for (double factor : {1.0, 5.0}) {
    SyntheticMeasurementOptions o = dic_like(plate(), 1.0, 2);
    o.undeformed_noise.normal_factor = o.deformed_noise.normal_factor = factor;
    const SyntheticMeasurement m = make_measurement(deformation_of(synthetic_case("shear")), o);
    const AnalysisResult r = analyse(m.grid, {});
    ASSERT_GT(r.noise.sigma_tangent, 0.0) << factor;
    const double ratio = r.noise.sigma_normal / r.noise.sigma_tangent;
    EXPECT_GT(ratio, 0.75 * factor) << factor;
    EXPECT_LT(ratio, 1.35 * factor) << factor;
  }
}

// A narrow strip gets at least three elements across its width.
TEST(GsaRealData, NarrowStripGetsThreeElementsAcross) {
  PointLayout layout = tensile_strip();
  layout.length_y = 3.0;  // 11 points across
  SyntheticMeasurementOptions o;
  o.layout = layout;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.1, 0.3, 1.0), o);
  const FitMarks marks = fit_marks(m.grid);
  const FrameAndMesh setup = build_frame_and_mesh(m.grid, marks, {});
  EXPECT_GE(std::min(setup.elements1, setup.elements2), 3) << setup.layout;
}

// Noise-free marks (a simulated part's virtual grid: simform --grid-out of the uniaxial
// sample, 11 x 11 marks on a 100 x 20 mm strip stretched 1 % along it) have round-off
// residuals, some cells ten times the median: no feature to refine at (refining there made
// the fit singular and the whole analysis fail, forming.cli.grid_roundtrip).
TEST(GsaRealData, RoundOffResidualsOfNoiseFreeMarksAreNoFeature) {
  const GridData g = io::read_grid_file(std::string(SF_SOURCE_DIR) + "/tests/gsa/cases/simulated_uniaxial_grid.csv");
  ASSERT_EQ(g.n_points(), 121);
  const AnalysisResult r = analyse(g, {});
  EXPECT_EQ(r.refinement_rounds, 0);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  EXPECT_EQ(without_strain(r), 0);
  for (const PointResult& p : r.points) {
    if (p.status != kStatusOk || !p.strain) continue;
    EXPECT_NEAR(p.strain->lambda1, 1.01, 1e-8);
    EXPECT_NEAR(p.strain->lambda2, 0.998009525956993, 1e-8);
  }
}

// Exact reference positions (nominal subset centres of a 2-D DIC export, --pitch): all
// the noise is in the deformed state and the blank's estimate is zero. The best of a few
// fixed smoothings (chosen with the exact answer) at log10(delta / d^6) = `lgs`, one pass,
// no outlier flags: an upper bound of bench/gsa_realdata_bench's oracle.
double best_fixed_rms(const SyntheticMeasurement& m, double spacing, double mark_spacing,
                      std::initializer_list<double> lgs) {
  double best = std::numeric_limits<double>::infinity();
  for (double lg : lgs) {
    AnalyseOptions o;
    o.outliers.sigma = 1e12;
    o.smoothing.gamma = 1e-6 * std::pow(mark_spacing, 4);
    o.smoothing.delta = std::pow(10.0, lg) * std::pow(mark_spacing, 6);
    best = std::min(best, analysis_rms(m, spacing, analyse(m.grid, o)));
  }
  return best;
}

// The rubber strip with noise correlated over one spacing in the deformed state only
// (rubber_L1.0_ref0 of gsa_realdata_bench, seed 1). The rule used to read the blank's zero
// as independent noise: GCV, a gauge of 0.6 spacings, 10 x the best fixed smoothing's
// error. The displacement's local fits find the length (0.96 spacings over two seeds) and
// Cp smooths: 1.00 x the oracle (measured on two seeds).
TEST(GsaRealData, ExactBlankStillSeesCorrelatedDeformedNoise) {
  PointLayout layout;
  layout.kind = PointLayout::Kind::kJittered;
  layout.length_x = 20.0;
  layout.length_y = 10.0;
  layout.spacing = 0.7;
  SyntheticMeasurementOptions o;
  o.layout = layout;
  const double sigma = 0.005 * layout.spacing;
  o.deformed_noise = NoiseModel{sigma, layout.spacing, 0.3 * sigma};
  o.undeformed_noise = NoiseModel{0.0, 0.0, 0.0};
  o.seed = 1;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.23, 0.23, 1.0), o);
  const AnalysisResult r = analyse(m.grid, {});
  EXPECT_EQ(r.noise_undeformed.sigma_total(), 0.0);
  EXPECT_EQ(r.smoothing_criterion, "Cp");
  EXPECT_NEAR(r.noise_displacement.correlation_length / layout.spacing, 1.0, 0.5);
  EXPECT_NEAR(r.noise_displacement.sigma_correlated / sigma, 1.0, 0.5);
  const double e = analysis_rms(m, layout.spacing, r);
  const double oracle = best_fixed_rms(m, layout.spacing, r.mark_spacing, {5.0, 5.5, 6.0});
  EXPECT_LT(e, 1.3 * oracle) << "automatic " << e << ", best fixed " << oracle;
  EXPECT_LT(e, 0.5 * local_fit_rms(m, layout.spacing));
}

// Exact blank, curved part: the misfit of the local quadratic fits on a dome grows with
// the radius as long correlated noise would (alone it was taken for noise correlated over
// 3.1 spacings, and Cp smoothed to 2.5 x the oracle's error); the quartic fits do not
// confirm it, so the noise counts as independent (GCV, as before). Independent noise in
// the deformed state (dome_white_ref0, seed 1), and no noise at all.
TEST(GsaRealData, CurvedPartOnExactBlankIsNotTakenForCorrelatedNoise) {
  const PointLayout layout = plate();
  const double d = layout.spacing;
  for (const double sigma : {0.004 * d, 0.0}) {
    SyntheticMeasurementOptions o;
    o.layout = layout;
    o.deformed_noise = NoiseModel{0.0, 0.0, sigma};
    o.undeformed_noise = NoiseModel{0.0, 0.0, 0.0};
    o.seed = 1;
    const SyntheticMeasurement m = make_measurement(deformation_of(synthetic_case("dome")), o);
    const AnalysisResult r = analyse(m.grid, {});
    EXPECT_EQ(r.noise_displacement.correlation_length, 0.0) << "sigma " << sigma;
    EXPECT_EQ(r.smoothing_criterion, "GCV") << "sigma " << sigma;
    const double e = analysis_rms(m, d, r);
    if (sigma > 0) {
      const double oracle = best_fixed_rms(m, d, r.mark_spacing, {3.5, 4.0, 4.5});
      EXPECT_LT(e, 1.3 * oracle) << "automatic " << e << ", best fixed " << oracle;
    } else {
      EXPECT_LT(e, 2e-5) << "noise-free dome";
    }
  }
}

}  // namespace
}  // namespace sf::gsa

// Strain accuracy on measurements shaped like real ones (gsa/synthetic_measurement.hpp):
// spatially correlated noise, necks, a dimple, narrow strips, DIC-like scattered
// points. For each case: the automatic smoothing, the best fixed smoothing chosen
// with the exact answer (the oracle), and the 24-nearest-neighbour local fit of
// the deformation gradient (gsa/local_fit.hpp), as RMS errors of the Green
// strains at points at least two spacings from the outline, plus the error near
// the outline, the neck peak and the points flagged or left without a strain.
// neckn*: necks narrower than an element (refined there, docs/theory/strain.md); band3*:
// a band narrower than an element along a narrow strip, as the ARAMIS crack band; bandn6*:
// the same opening in a sharper band (neither is relaxed yet, docs/theory/strain.md).
// sc/t, L/h, sw/t: the deformed noise estimate's correlated level over the true one (where
// the noise has no correlated part, over the true independent level: the correlated level
// the estimate makes up), its correlation length in spacings, its independent level over
// the true one (both states' noise, hence the sqrt(2)).
// Environment: NOORACLE, NOLOCAL, NOREFINE, GCV, SCALE=s (the automatic weights x s),
// ELEM1/ELEM2, PERSEED, PEAKDIAG.
//   build/bin/gsa_realdata_bench [seeds=2] [filter]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "gsa/analysis.hpp"
#include "gsa/local_fit.hpp"
#include "gsa/synthetic_measurement.hpp"

using namespace sf;
using namespace sf::gsa;

namespace {

// An estimated level over the true one; where the true one is 0, over `otherwise` (a
// level of the same noise that is not 0), so the ratio says how much was made up.
double level_ratio(double estimate, double truth, double otherwise) {
  const double d = truth > 0 ? truth : otherwise;
  return d > 0 ? estimate / d : 0.0;
}

struct Study {
  std::string name;
  Deformation deformation;
  SyntheticMeasurementOptions options;
};

struct Errors {
  double interior = 0.0, edge = 0.0;    // RMS of (E1, E2) errors
  double peak = 0.0, peak_exact = 0.0;  // largest E1
  Index without = 0, flagged = 0;
};

double green(double l) { return 0.5 * (l * l - 1.0); }

template <class Get>
Errors errors_of(const SyntheticMeasurement& m, double spacing, Get get) {
  Errors e;
  double si = 0, se = 0;
  Index ni = 0, ne = 0;
  for (std::size_t p = 0; p < m.exact.size(); ++p) {
    e.peak_exact = std::max(e.peak_exact, green(m.exact[p].lambda1));
    double l1 = 0, l2 = 0;
    if (!get(static_cast<Index>(p), l1, l2)) {
      ++e.without;
      continue;
    }
    e.peak = std::max(e.peak, green(l1));
    const double d1 = green(l1) - green(m.exact[p].lambda1), d2 = green(l2) - green(m.exact[p].lambda2);
    if (m.edge_distance[p] >= 2.0 * spacing - 1e-9) {
      si += d1 * d1 + d2 * d2;
      ni += 2;
    } else {
      se += d1 * d1 + d2 * d2;
      ne += 2;
    }
  }
  e.interior = ni ? std::sqrt(si / ni) : 0.0;
  e.edge = ne ? std::sqrt(se / ne) : 0.0;
  return e;
}

Errors analysis_errors(const SyntheticMeasurement& m, double spacing, const AnalysisResult& r) {
  Errors e = errors_of(m, spacing, [&](Index p, double& l1, double& l2) {
    const PointResult& pr = r.points[p];
    if (!pr.strain) return false;
    l1 = pr.strain->lambda1;
    l2 = pr.strain->lambda2;
    return true;
  });
  for (const PointResult& pr : r.points)
    if (pr.status == kStatusOutlierDeformed || pr.status == kStatusOutlierUndeformed) ++e.flagged;
  return e;
}

NoiseModel correlated(double sigma, double length, double white) { return {sigma, length, white}; }

std::vector<Study> studies() {
  std::vector<Study> out;
  auto add = [&](std::string name, Deformation d, PointLayout layout, double sigma_ratio, double corr_spacings) {
    Study s{std::move(name), std::move(d), {}};
    s.options.layout = layout;
    const double sigma = sigma_ratio * layout.spacing;
    const NoiseModel nm = corr_spacings > 0 ? correlated(sigma, corr_spacings * layout.spacing, 0.3 * sigma)
                                            : correlated(0.0, 0.0, sigma);
    s.options.undeformed_noise = nm;
    s.options.deformed_noise = nm;
    out.push_back(std::move(s));
  };
  PointLayout plate;
  plate.length_x = plate.length_y = 100.0;
  plate.spacing = 2.5;
  PointLayout strip;  // a tensile specimen's gauge section, ARAMIS-like density
  strip.length_x = 30.0;
  strip.length_y = 12.0;
  strip.spacing = 0.3;
  PointLayout rubber;  // MatchID-like: about 435 scattered points 0.7 mm apart
  rubber.kind = PointLayout::Kind::kJittered;
  rubber.length_x = 20.0;
  rubber.length_y = 10.0;
  rubber.spacing = 0.7;
  PointLayout scattered = plate;
  scattered.kind = PointLayout::Kind::kScattered;
  for (double corr : {0.0, 1.0, 2.5, 5.0}) {
    const std::string tag = corr > 0 ? "_L" + std::to_string(corr).substr(0, 3) : "_white";
    add("stretch" + tag, deformation_of(synthetic_case("stretch")), plate, 0.004, corr);
    add("cylinder" + tag, deformation_of(synthetic_case("cylinder")), plate, 0.004, corr);
    add("dome" + tag, deformation_of(synthetic_case("dome")), plate, 0.004, corr);
    add("dome_scat" + tag, deformation_of(synthetic_case("dome")), scattered, 0.004, corr);
    add("neck30" + tag, neck_deformation(0.1, 0.3, 1.0), strip, 0.005, corr);
    add("neck100" + tag, neck_deformation(0.2, 1.0, 1.0), strip, 0.005, corr);
    // Necks narrower than an element (1.2-1.4 mm on the strip): width parameter 0.4 mm.
    add("neckn30" + tag, neck_deformation(0.1, 0.3, 0.4), strip, 0.005, corr);
    add("neckn100" + tag, neck_deformation(0.2, 1.0, 0.4), strip, 0.005, corr);
    add("rubber" + tag, neck_deformation(0.23, 0.23, 1.0), rubber, 0.005, corr);
    add("dimple" + tag, dimple_deformation(1.1, 0.95, 0.05, 1.5, 0.0, 0.0), strip, 0.005, corr);
  }
  // A band narrower than an element along the long side of a narrow strip, as the ARAMIS
  // crack band (data/real/aramis_mt_crack): 4.5 x 18 mm, facets 0.75 mm apart, strain
  // 3 % in a band of width parameter 0.6 mm (two facets at half height) on 0.2 % (two rows of elements, the band on
  // their border); noise 0.4 % of the spacing in plane, the same or (_z4) 4 x along z.
  PointLayout band;
  band.length_x = 4.5;
  band.length_y = 18.0;
  band.spacing = 0.75;
  for (double zf : {1.0, 4.0})
    for (double corr : {0.0, 1.0, 2.5}) {
      add("band3" + (corr > 0 ? "_L" + std::to_string(corr).substr(0, 3) : std::string("_white")) +
              (zf > 1 ? "_z4" : ""),
          band_deformation(0.002, 0.03, 0.6), band, 0.004, corr);
      out.back().options.undeformed_noise.normal_factor = out.back().options.deformed_noise.normal_factor = zf;
    }
  // Sharper, as the ARAMIS band is (its displacement jumps 0.02-0.04 mm between two facet
  // rows, a crack's opening): the same opening (0.022 mm) in a band of width parameter
  // 0.3 mm (0.4 spacings), 6 % at its centre.
  for (double corr : {0.0, 1.0})
    add("bandn6" + (corr > 0 ? "_L" + std::to_string(corr).substr(0, 3) : std::string("_white")),
        band_deformation(0.002, 0.06, 0.3), band, 0.004, corr);
  // Noise-free reference positions, as a 2-D DIC export gives them (nominal subset
  // centres): all the noise in the deformed state, none in the blank to estimate from.
  for (double corr : {0.0, 1.0, 2.5}) {
    const std::string tag = (corr > 0 ? "_L" + std::to_string(corr).substr(0, 3) : "_white") + "_ref0";
    const std::size_t first = out.size();
    add("stretch" + tag, deformation_of(synthetic_case("stretch")), plate, 0.004, corr);
    add("dome" + tag, deformation_of(synthetic_case("dome")), plate, 0.004, corr);
    add("neck30" + tag, neck_deformation(0.1, 0.3, 1.0), strip, 0.005, corr);
    add("neckn30" + tag, neck_deformation(0.1, 0.3, 0.4), strip, 0.005, corr);
    add("rubber" + tag, neck_deformation(0.23, 0.23, 1.0), rubber, 0.005, corr);
    for (std::size_t i = first; i < out.size(); ++i) out[i].options.undeformed_noise = NoiseModel{0.0, 0.0, 0.0};
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 2;
  const std::string filter = argc > 2 ? argv[2] : "";
  std::printf("%-16s %6s | %9s %9s %5s | %9s %6s | %9s %9s | %7s %7s | %6s %6s %6s | %5s %5s | %5s %5s %5s %5s %7s\n",
              "case", "points", "auto", "auto_edge", "gauge", "oracle", "lg_opt", "nn24", "nn24_edge", "a/orac",
              "a/nn24", "peak_a", "peak_o", "exact", "flag", "none", "sc/t", "L/h", "sw/t", "relax", "mesh");
  for (const Study& s : studies()) {
    if (!filter.empty() && s.name.find(filter) == std::string::npos) continue;
    double est_sc = 0, est_L = 0, est_sw = 0, relaxed = 0, a = 0, ae = 0, o = 0, nn = 0, nne = 0, gauge = 0, lg = 0,
           pa = 0, po = 0, pe = 0;
    Index flagged = 0, none = 0, npts = 0;
    std::string mesh;
    for (int seed = 1; seed <= seeds; ++seed) {
      SyntheticMeasurementOptions opt = s.options;
      opt.seed = static_cast<unsigned>(seed);
      const SyntheticMeasurement m = make_measurement(s.deformation, opt);
      npts = m.grid.n_points();
      const double h = opt.layout.spacing;
      AnalyseOptions ao;
      if (std::getenv("ELEM1"))
        ao.mesh.elements1 = std::atoi(std::getenv("ELEM1")), ao.mesh.elements2 = std::atoi(std::getenv("ELEM2"));
      if (std::getenv("GCV")) ao.smoothing.rule = SmoothingRule::kGcv;
      if (std::getenv("NOLOCAL")) ao.smoothing.local = false;
      if (std::getenv("SCALE")) ao.smoothing.scale = std::atof(std::getenv("SCALE"));
      // NOREFINE: the first round alone (the uniform automatic mesh, no refinement).
      const AnalysisResult ra =
          std::getenv("NOREFINE") ? analyse_deformed(analyse_undeformed(m.grid, ao), m.grid, ao) : analyse(m.grid, ao);
      const Errors ea = analysis_errors(m, h, ra);
      mesh = std::to_string(ra.elements1) + "x" + std::to_string(ra.elements2);
      a += ea.interior;
      ae += ea.edge;
      gauge += ra.gauge_length / ra.mark_spacing;
      pa += ea.peak;
      pe += ea.peak_exact;
      flagged += ea.flagged;
      none += ea.without;
      // Oracle: fixed smoothing (one pass), no outlier flags, best interior error.
      double best = std::numeric_limits<double>::infinity(), best_lg = 0, best_peak = 0;
      const bool oracle = !std::getenv("NOORACLE");
      for (double l = -3.0; oracle && l <= 6.01; l += 0.5) {
        AnalyseOptions fo;
        fo.outliers.sigma = 1e12;
        fo.mesh = ao.mesh;
        fo.smoothing.gamma = 1e-6 * std::pow(ra.mark_spacing, 4);
        fo.smoothing.delta = std::pow(10.0, l) * std::pow(ra.mark_spacing, 6);
        const AnalysisResult rf = analyse(m.grid, fo);
        const Errors ef = analysis_errors(m, h, rf);
        if (ef.interior < best) best = ef.interior, best_lg = l, best_peak = ef.peak;
      }
      o += best;
      lg += best_lg;
      po += best_peak;
      est_sc += level_ratio(ra.noise.sigma_correlated, opt.deformed_noise.sigma_correlated * std::sqrt(2.0),
                            opt.deformed_noise.sigma_white * std::sqrt(2.0));
      est_L += ra.noise.correlation_length / h;
      est_sw += ra.noise.sigma_white / (opt.deformed_noise.sigma_white * std::sqrt(2.0));
      relaxed += static_cast<double>(ra.relaxed_elements);
      const auto local = local_fit_stretches(m.grid, 24);
      const Errors en = errors_of(m, h, [&](Index p, double& l1, double& l2) {
        if (!local[p]) return false;
        l1 = local[p]->lambda1;
        l2 = local[p]->lambda2;
        return true;
      });
      nn += en.interior;
      nne += en.edge;
      if (std::getenv("PEAKDIAG")) {
        // Where the automatic peak is, and the exact strain there.
        std::size_t at = 0, at_exact = 0;
        double best_a = -1, best_e = -1;
        for (std::size_t p = 0; p < m.exact.size(); ++p) {
          if (green(m.exact[p].lambda1) > best_e) best_e = green(m.exact[p].lambda1), at_exact = p;
          if (ra.points[p].strain && green(ra.points[p].strain->lambda1) > best_a)
            best_a = green(ra.points[p].strain->lambda1), at = p;
        }
        if (std::getenv("EDGEROW"))
          for (std::size_t p = 0; p < m.exact.size(); ++p)
            if (std::abs(m.nominal[p].y() - 6.0) < 1e-6 && std::abs(m.nominal[p].x()) < 2.5 && ra.points[p].strain)
              std::printf("    X %6.2f exact %.3f got %.3f (%+.3f) E2 exact %.4f got %.4f\n", m.nominal[p].x(),
                          green(m.exact[p].lambda1), green(ra.points[p].strain->lambda1),
                          green(ra.points[p].strain->lambda1) - green(m.exact[p].lambda1), green(m.exact[p].lambda2),
                          green(ra.points[p].strain->lambda2));
        std::printf("  peak %.3f at (%.2f, %.2f) exact there %.3f edge %.2f h; exact peak %.3f at (%.2f, %.2f)\n",
                    best_a, m.nominal[at].x(), m.nominal[at].y(), green(m.exact[at].lambda1), m.edge_distance[at] / h,
                    best_e, m.nominal[at_exact].x(), m.nominal[at_exact].y());
      }
      if (std::getenv("PERSEED"))
        std::printf(
            "  seed %d: lg %.2f gauge %.2f auto %.2e peak %.3f/%.3f sc/t %.2f L/h %.2f sw/t %.2f relaxed %ld mesh %s "
            "rounds %d; blank sc/t %.2f L/h %.2f sw/t %.2f\n",
            seed, ra.log10_delta_optimum, ra.gauge_length / h, ea.interior, ea.peak, ea.peak_exact,
            level_ratio(ra.noise.sigma_correlated, opt.deformed_noise.sigma_correlated * std::sqrt(2.0),
                        opt.deformed_noise.sigma_white * std::sqrt(2.0)),
            ra.noise.correlation_length / h, ra.noise.sigma_white / (opt.deformed_noise.sigma_white * std::sqrt(2.0)),
            static_cast<long>(ra.relaxed_elements), mesh.c_str(), ra.refinement_rounds,
            level_ratio(ra.noise_undeformed.sigma_correlated, opt.undeformed_noise.sigma_correlated,
                        opt.undeformed_noise.sigma_white),
            ra.noise_undeformed.correlation_length / h,
            level_ratio(ra.noise_undeformed.sigma_white, opt.undeformed_noise.sigma_white,
                        opt.undeformed_noise.sigma_correlated));
    }
    const double k = 1.0 / seeds;
    std::printf(
        "%-16s %6ld | %9.2e %9.2e %5.2f | %9.2e %6.1f | %9.2e %9.2e | %7.2f %7.2f | %6.3f %6.3f %6.3f | %5ld %5ld | "
        "%5.2f %5.2f %5.2f %5.0f %7s\n",
        s.name.c_str(), static_cast<long>(npts), a * k, ae * k, gauge * k, o * k, lg * k, nn * k, nne * k, a / o,
        a / nn, pa * k, po * k, pe * k, static_cast<long>(flagged), static_cast<long>(none), est_sc * k, est_L * k,
        est_sw * k, relaxed * k, mesh.c_str());
    std::fflush(stdout);
  }
  return 0;
}

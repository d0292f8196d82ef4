// Strain error against the distance from the boundary of the measured region (strip
// ends and edges, a blank's rim), on measurements shaped like real ones
// (gsa/synthetic_measurement.hpp): regular grids of marks and DIC-like scattered
// points, independent and spatially correlated noise (correlation length 2.5 point
// spacings). For each case the RMS error of the Green strains (E1, E2) of the automatic
// analysis in bands of distance from the outline, in point spacings h: [0, 1), [1, 2),
// [2, 4) and >= 4, and the ratio of the outermost band to the innermost; the
// 24-nearest-neighbour local fit (gsa/local_fit.hpp) on the same data for comparison.
//   build/bin/gsa_edge_bench [seeds=2] [filter]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "gsa/analysis.hpp"
#include "gsa/local_fit.hpp"
#include "gsa/synthetic_measurement.hpp"

using namespace sf;
using namespace sf::gsa;

namespace {

constexpr int kBands = 4;
const double kBandEdges[kBands + 1] = {0.0, 1.0, 2.0, 4.0, 1e30};

struct Study {
  std::string name;
  Deformation deformation;
  SyntheticMeasurementOptions options;
};

double green(double l) { return 0.5 * (l * l - 1.0); }

struct Bands {
  double sum[kBands] = {0, 0, 0, 0};
  Index n[kBands] = {0, 0, 0, 0};
  Index missing = 0;
  void add(double distance_h, double d1, double d2) {
    for (int b = 0; b < kBands; ++b)
      if (distance_h >= kBandEdges[b] - 1e-9 && distance_h < kBandEdges[b + 1] - 1e-9) {
        sum[b] += d1 * d1 + d2 * d2;
        n[b] += 2;
      }
  }
  double rms(int b) const { return n[b] ? std::sqrt(sum[b] / n[b]) : std::nan(""); }
};

std::vector<Study> studies() {
  std::vector<Study> out;
  auto add = [&](const std::string& name, Deformation d, PointLayout layout, double sigma_ratio) {
    for (double corr : {0.0, 2.5}) {
      Study s{name + (corr > 0 ? "_L2.5" : "_white"), d, {}};
      s.options.layout = layout;
      const double sigma = sigma_ratio * layout.spacing;
      const NoiseModel nm =
          corr > 0 ? NoiseModel{sigma, corr * layout.spacing, 0.3 * sigma} : NoiseModel{0.0, 0.0, sigma};
      s.options.undeformed_noise = nm;
      s.options.deformed_noise = nm;
      out.push_back(std::move(s));
    }
  };
  PointLayout plate;  // 41 x 41 marks
  plate.length_x = plate.length_y = 100.0;
  plate.spacing = 2.5;
  PointLayout round = plate;  // a round blank: its rim
  round.round = true;
  PointLayout scattered = plate;  // DIC-like points at the same density
  scattered.kind = PointLayout::Kind::kScattered;
  PointLayout strip;  // a tensile specimen's gauge section, ARAMIS-like density
  strip.length_x = 30.0;
  strip.length_y = 12.0;
  strip.spacing = 0.3;
  PointLayout rubber;  // MatchID-like: about 435 points 0.7 mm apart, jittered
  rubber.kind = PointLayout::Kind::kJittered;
  rubber.length_x = 20.0;
  rubber.length_y = 10.0;
  rubber.spacing = 0.7;
  add("stretch", deformation_of(synthetic_case("stretch")), plate, 0.004);
  add("cylinder", deformation_of(synthetic_case("cylinder")), plate, 0.004);
  add("dome", deformation_of(synthetic_case("dome")), plate, 0.004);
  add("dome_round", deformation_of(synthetic_case("dome")), round, 0.004);
  add("dome_scat", deformation_of(synthetic_case("dome")), scattered, 0.004);
  add("wavy_scat", deformation_of(synthetic_case("wavy")), scattered, 0.004);
  add("neck30", neck_deformation(0.1, 0.3, 1.0), strip, 0.005);
  add("rubber", neck_deformation(0.23, 0.23, 1.0), rubber, 0.005);
  return out;
}

void print_row(const char* what, const std::string& name, Index n, const Bands& b) {
  std::printf("%-16s %-5s %6ld |", name.c_str(), what, static_cast<long>(n));
  for (int k = 0; k < kBands; ++k) std::printf(" %9.2e", b.rms(k));
  std::printf(" | %6.2f %6.2f\n", b.rms(0) / b.rms(3), b.rms(1) / b.rms(3));
}

}  // namespace

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 2;
  const std::string filter = argc > 2 ? argv[2] : "";
  std::printf("RMS error of the Green strains (E1, E2) by distance from the outline, in point spacings h\n");
  std::printf("%-16s %-5s %6s | %9s %9s %9s %9s | %6s %6s\n", "case", "fit", "points", "0-1h", "1-2h", "2-4h", ">4h",
              "0-1/>4", "1-2/>4");
  for (const Study& s : studies()) {
    if (!filter.empty() && s.name.find(filter) == std::string::npos) continue;
    Bands fit, nn;
    Index points = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
      SyntheticMeasurementOptions opt = s.options;
      opt.seed = static_cast<unsigned>(seed);
      const SyntheticMeasurement m = make_measurement(s.deformation, opt);
      points = m.grid.n_points();
      const double h = opt.layout.spacing;
      const AnalysisResult r = analyse(m.grid, AnalyseOptions{});
      const auto local = local_fit_stretches(m.grid, 24);
      for (Index p = 0; p < points; ++p) {
        const ExactStrain& e = m.exact[static_cast<std::size_t>(p)];
        const double dist = m.edge_distance[static_cast<std::size_t>(p)] / h;
        if (const auto& st = r.points[static_cast<std::size_t>(p)].strain)
          fit.add(dist, green(st->lambda1) - green(e.lambda1), green(st->lambda2) - green(e.lambda2));
        else
          ++fit.missing;
        if (const auto& l = local[static_cast<std::size_t>(p)])
          nn.add(dist, green(l->lambda1) - green(e.lambda1), green(l->lambda2) - green(e.lambda2));
      }
    }
    print_row("auto", s.name, points, fit);
    print_row("nn24", s.name, points, nn);
    std::fflush(stdout);
  }
  return 0;
}

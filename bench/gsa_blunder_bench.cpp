// Blunder detection (gsa/blunders.hpp) on measurement-like synthetic data: points
// flagged on clean data (false alarms) and isolated blunders of 10 noise sigmas found.
//   build/bin/gsa_blunder_bench [seeds=3]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "gsa/blunders.hpp"
#include "gsa/synthetic_measurement.hpp"

using namespace sf;
using namespace sf::gsa;

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 3;
  struct Case {
    std::string name;
    Deformation d;
    PointLayout layout;
    double corr;
  };
  PointLayout plate;
  plate.length_x = plate.length_y = 100;
  plate.spacing = 2.5;
  PointLayout strip;
  strip.length_x = 30;
  strip.length_y = 12;
  strip.spacing = 0.3;
  PointLayout scat = plate;
  scat.kind = PointLayout::Kind::kScattered;
  std::vector<Case> cases;
  for (double corr : {0.0, 1.0, 2.5, 5.0}) {
    cases.push_back({"dome", deformation_of(synthetic_case("dome")), plate, corr});
    cases.push_back({"dome_scat", deformation_of(synthetic_case("dome")), scat, corr});
    cases.push_back({"wavy", deformation_of(synthetic_case("wavy")), plate, corr});
    cases.push_back({"neck100", neck_deformation(0.2, 1.0, 1.0), strip, corr});
    cases.push_back({"neck100_narrow", neck_deformation(0.2, 1.0, 0.4), strip, corr});
    cases.push_back({"dimple", dimple_deformation(1.1, 0.95, 0.05, 1.5, 0, 0), strip, corr});
  }
  std::printf("%-15s %5s %6s | %8s %8s | %8s %8s | %6s %6s\n", "case", "corr", "points", "clean_u", "clean_d",
              "noise_d", "thr_d", "found", "of");
  for (const Case& c : cases) {
    long fu = 0, fd = 0, found = 0, total = 0, npts = 0;
    double noise = 0, thr = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
      SyntheticMeasurementOptions o;
      o.layout = c.layout;
      const double sigma = 0.004 * c.layout.spacing;
      o.deformed_noise =
          c.corr > 0 ? NoiseModel{sigma, c.corr * c.layout.spacing, 0.3 * sigma} : NoiseModel{0, 0, sigma};
      o.undeformed_noise = o.deformed_noise;
      o.seed = static_cast<unsigned>(seed);
      SyntheticMeasurement m = make_measurement(c.d, o);
      const Index n = m.grid.n_points();
      npts = n;
      std::vector<bool> all(static_cast<std::size_t>(n), true);
      const BlunderCheck bu = find_blunders(m.grid.undeformed, m.grid.undeformed, all, true);
      const BlunderCheck bd = find_blunders(m.grid.undeformed, m.grid.deformed, all, false);
      fu += bu.n_flagged();
      fd += bd.n_flagged();
      noise += bd.noise;
      thr += bd.threshold;
      // Blunders: 10 x the total per-coordinate noise sigma, 1 per 500 points.
      o.blunders = static_cast<int>(std::max<Index>(1, n / 500));
      o.blunder_size = 10.0 * o.deformed_noise.sigma_total();
      m = make_measurement(c.d, o);
      const BlunderCheck bb = find_blunders(m.grid.undeformed, m.grid.deformed, all, false);
      for (Index p : m.blunder_points) {
        found += bb.flagged[static_cast<std::size_t>(p)] ? 1 : 0;
        if (!bb.flagged[static_cast<std::size_t>(p)] && std::getenv("DEBUG"))
          std::printf("  missed %ld: deviation/threshold %.2f edge %.2f\n", static_cast<long>(p),
                      bb.deviation[static_cast<std::size_t>(p)] / bb.threshold,
                      m.edge_distance[static_cast<std::size_t>(p)] / c.layout.spacing);
      }
      total += static_cast<long>(m.blunder_points.size());
    }
    std::printf("%-15s %5.1f %6ld | %8ld %8ld | %8.2e %8.2e | %6ld %6ld\n", c.name.c_str(), c.corr,
                static_cast<long>(npts), fu, fd, noise / seeds, thr / seeds, found, total);
  }
  return 0;
}

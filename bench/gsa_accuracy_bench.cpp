// Accuracy of the surface fit against exact strains and against the classical
// triangle method, on the analytic cases of gsa/synthetic.hpp (21 x 21 marks at
// 5 mm). Prints RMS errors of the Green strains at interior marks.
//   build/bin/gsa_accuracy_bench [seeds=3] [smoothing_scale=1] [third|sobolev|jumps]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "gsa/accuracy.hpp"

using namespace sf;
using namespace sf::gsa;

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 3;
  const double scale = argc > 2 ? std::atof(argv[2]) : 1.0;
  const std::string penalty = argc > 3 ? argv[3] : "jumps";
  const char* cases[] = {"rigid", "stretch", "shear", "cylinder", "dome", "wavy", "trellis"};
  const double noises[] = {0.0, 0.01, 0.03};
  std::printf("%-9s %6s  %12s %12s %12s  %7s  %s\n", "case", "noise", "surface_rms", "triangle_rms", "surf_border3",
              "ratio", "gauge/spacing  gcv_lg(delta/d^6)  noise_rule_lg");
  for (const char* name : cases) {
    for (double noise : noises) {
      double s = 0, t = 0, s3 = 0, gauge = 0, gcv = 0, rule = 0;
      const int ns = noise > 0 ? seeds : 1;
      for (int seed = 1; seed <= ns; ++seed) {
        SyntheticGridOptions go;
        go.noise = noise;
        go.seed = static_cast<unsigned>(seed);
        std::vector<ExactStrain> exact;
        const GridData g = make_synthetic_grid(synthetic_case(name), go, &exact);
        AnalyseOptions o;
        o.smoothing.scale = scale;
        if (penalty == "sobolev") o.smoothing.penalty = PenaltyKind::kSobolev;
        if (penalty == "jumps") o.smoothing.penalty = PenaltyKind::kJumps;
        if (penalty == "third") o.smoothing.penalty = PenaltyKind::kThirdOrder;
        if (std::string(name) == "trellis") o.fibre_angles = {0, 90};
        const AnalysisResult rs = analyse(g, o);
        o.method = Method::kTriangles;
        const AnalysisResult rt = analyse(g, o);
        s += strain_error(g, rs, exact).rms();
        t += strain_error(g, rt, exact).rms();
        s3 += strain_error(g, rs, exact, 3).rms();
        gauge += rs.gauge_length / rs.mark_spacing;
        gcv += rs.log10_delta_optimum;
        rule += std::log10(2e4 * std::max(rs.noise_estimate / rs.mark_spacing, 1e-6));
      }
      s /= ns;
      t /= ns;
      s3 /= ns;
      std::printf("%-9s %6.3f  %12.3e %12.3e %12.3e  %7.3f  %.2f  %6.2f %6.2f\n", name, noise, s, t, s3,
                  t > 0 ? s / t : 0.0, gauge / ns, gcv / ns, rule / ns);
    }
  }
  return 0;
}

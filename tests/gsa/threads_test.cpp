// The results of `gsa analyse` do not depend on the number of threads: every parallel
// loop (neighbour searches, blunder check, probe fields, the fits' products with the
// collocation matrix, the strains.csv text) gives each item's numbers in the same order
// whatever the threads. Analysed with 1 and with 3 threads (sf::set_default_threads),
// the strains, flags, noise estimates and smoothing agree to the last bit and the
// written strains.csv byte for byte.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/core/parallel.hpp"
#include "common/io/atomic_file.hpp"
#include "common/linalg/dense_kernels.hpp"
#include "gsa/analysis.hpp"
#include "gsa/noise_model.hpp"
#include "gsa/output.hpp"
#include "gsa/synthetic.hpp"
#include "gsa/synthetic_measurement.hpp"

namespace sf::gsa {
namespace {

namespace fs = std::filesystem;

// Restores the default thread count when a test ends, passed or not.
struct ThreadSetting {
  explicit ThreadSetting(int n) { set_default_threads(n); }
  ~ThreadSetting() { set_default_threads(0); }
};

// The default analysis of `grid` on `threads` threads.
AnalysisResult analysed_on(int threads, const GridData& grid) {
  const ThreadSetting t(threads);
  return analyse(grid, AnalyseOptions{});
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every number of the two results that the analysis computed, compared bit for bit;
// returns the first difference ("" when none).
std::string first_difference(const AnalysisResult& a, const AnalysisResult& b) {
  if (a.points.size() != b.points.size()) return "point count";
  for (std::size_t p = 0; p < a.points.size(); ++p) {
    const PointResult &x = a.points[p], &y = b.points[p];
    const std::string at = " at point " + std::to_string(p);
    if (x.status != y.status) return "status" + at;
    if (x.element != y.element || !same_bits(x.xi[0], y.xi[0]) || !same_bits(x.xi[1], y.xi[1])) return "location" + at;
    if (!same_bits(x.residual, y.residual) || !same_bits(x.residual_undeformed, y.residual_undeformed))
      return "residual" + at;
    if (x.strain.has_value() != y.strain.has_value()) return "strain presence" + at;
    if (x.strain &&
        (!same_bits(x.strain->lambda1, y.strain->lambda1) || !same_bits(x.strain->lambda2, y.strain->lambda2) ||
         x.strain->dir1_deformed != y.strain->dir1_deformed))
      return "strain" + at;
    if (x.flag.has_value() != y.flag.has_value()) return "flag" + at;
    if (x.flag &&
        (!same_bits(x.flag->deviation, y.flag->deviation) || !same_bits(x.flag->threshold, y.flag->threshold)))
      return "flag numbers" + at;
  }
  if (a.undeformed_parameters != b.undeformed_parameters) return "undeformed parameters";
  if (a.deformed_parameters != b.deformed_parameters) return "deformed parameters";
  if (!same_bits(a.penalty_deformed.delta, b.penalty_deformed.delta)) return "deformed smoothing";
  if (!same_bits(a.noise_estimate, b.noise_estimate)) return "undeformed noise estimate";
  if (!same_bits(a.noise.sigma_correlated, b.noise.sigma_correlated) ||
      !same_bits(a.noise.sigma_white, b.noise.sigma_white) ||
      !same_bits(a.noise_undeformed.correlation_length, b.noise_undeformed.correlation_length))
    return "noise model";
  if (a.element_multiplier != b.element_multiplier) return "local smoothing";
  if (a.elements1 != b.elements1 || a.elements2 != b.elements2) return "mesh";
  return "";
}

// A tensile strip at DIC density (2747 points) with a neck under noise correlated over
// 2.5 spacings and two blunders: the noise model's path (probe fields, Cp, local
// relaxation, refinement at the neck) and the blunder check, with enough points that
// every parallel loop has blocks for several threads.
TEST(GsaThreads, NeckUnderCorrelatedNoiseGivesTheSameBitsOnOneAndThreeThreads) {
  SyntheticMeasurementOptions o;
  o.layout.length_x = 20.0;
  o.layout.length_y = 12.0;
  o.layout.spacing = 0.3;
  const double sigma = 0.004 * o.layout.spacing;
  o.undeformed_noise = o.deformed_noise = NoiseModel{sigma, 2.5 * o.layout.spacing, 0.3 * sigma};
  o.blunders = 2;
  o.seed = 3;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.2, 0.6, 1.0), o);
  const AnalysisResult one = analysed_on(1, m.grid), three = analysed_on(3, m.grid);
  ASSERT_GT(one.points.size(), 2500u);
  EXPECT_EQ(first_difference(one, three), "");
  // The case does what it is meant to exercise.
  EXPECT_EQ(one.smoothing_criterion, "Cp");
  EXPECT_GT(
      std::count_if(one.points.begin(), one.points.end(), [](const PointResult& p) { return p.flag.has_value(); }), 0);
}

// An exact blank (nominal reference positions) with noise correlated over a spacing in
// the deformed state: the displacement's local fits (displacement_noise, its query points
// on all threads) and, with more than one thread, the blank's noise estimate beside the
// deformed blunder check and first fit (analyse_once). Bits and the displacement's noise
// model the same on one and three threads.
TEST(GsaThreads, ExactBlankGivesTheSameBitsOnOneAndThreeThreads) {
  SyntheticMeasurementOptions o;
  o.layout.kind = PointLayout::Kind::kJittered;
  o.layout.length_x = 20.0;
  o.layout.length_y = 10.0;
  o.layout.spacing = 0.5;
  const double sigma = 0.005 * o.layout.spacing;
  o.deformed_noise = NoiseModel{sigma, o.layout.spacing, 0.3 * sigma};
  o.undeformed_noise = NoiseModel{0.0, 0.0, 0.0};
  o.seed = 2;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.23, 0.23, 1.0), o);
  const AnalysisResult one = analysed_on(1, m.grid), three = analysed_on(3, m.grid);
  EXPECT_EQ(first_difference(one, three), "");
  const NoiseEstimate &a = one.noise_displacement, &b = three.noise_displacement;
  EXPECT_TRUE(same_bits(a.sigma_correlated, b.sigma_correlated) && same_bits(a.sigma_white, b.sigma_white) &&
              same_bits(a.correlation_length, b.correlation_length) && same_bits(a.bias_slope, b.bias_slope));
  ASSERT_EQ(a.gamma.size(), b.gamma.size());
  for (std::size_t k = 0; k < a.gamma.size(); ++k) EXPECT_TRUE(same_bits(a.gamma[k], b.gamma[k])) << "radius " << k;
  EXPECT_EQ(a.count, b.count);
  // The case does what it is meant to exercise: the displacement's estimate found the
  // correlation and chose the smoothing by Cp.
  EXPECT_EQ(one.noise_undeformed.sigma_total(), 0.0);
  EXPECT_GT(a.correlation_length, 0.0);
  EXPECT_EQ(one.smoothing_criterion, "Cp");
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Independent noise (cross-validation's path) on 8464 marks of the wavy part, written:
// strains.csv is formatted in chunks of 8192 rows on all threads, so it has two here.
TEST(GsaThreads, WrittenStrainsAreTheSameBytesOnOneAndThreeThreads) {
  SyntheticGridOptions go;
  go.n = 92;  // 8464 marks: two chunks
  go.spacing = 1.0;
  go.noise = 0.01;
  go.outliers = 3;
  const GridData g = make_synthetic_grid(synthetic_case("wavy"), go);
  const fs::path root = fs::path(SF_BINARY_DIR) / "test_output" / "gsa_threads";
  fs::remove_all(root);
  fs::create_directories(root);
  AnalysisResult results[2];
  std::string text[2];
  const int threads[2] = {1, 3};
  for (int k = 0; k < 2; ++k) {
    const ThreadSetting t(threads[k]);
    results[k] = analyse(g, AnalyseOptions{});
    const fs::path dir = root / ("threads" + std::to_string(threads[k]));
    io::AtomicOutputDir out(dir.string());
    write_results(out, g, results[k], OutputOptions{}, RunInfo{"test", {"wavy.csv"}});
    out.commit();
    text[k] = file_text(dir / "strains.csv");
  }
  EXPECT_EQ(first_difference(results[0], results[1]), "");
  EXPECT_EQ(results[0].smoothing_criterion, "GCV");
  ASSERT_GT(text[0].size(), 1000000u);
  EXPECT_TRUE(text[0] == text[1]) << "strains.csv differs between 1 and 3 threads";
  EXPECT_EQ(file_text(root / "threads1" / "deformed.vtp"), file_text(root / "threads3" / "deformed.vtp"));
}

// The probe fields' cosines run on the widest vector registers the processor has
// (chosen at run time): every instruction set gives the bits of the one-point sum at(),
// so the noise estimate does not depend on the machine either.
TEST(GsaThreads, ProbeFieldRowsAreTheSameBitsOnEveryInstructionSet) {
  Points3 p(29, 3);
  for (Index i = 0; i < p.rows(); ++i) p.row(i) << 0.37 * i - 3.0, 1.3 * std::sin(0.7 * i), 0.05 * i * i;
  const CorrelatedField field(0.7, 2.3, 11u, 48);
  const linalg::KernelIsa best = linalg::kernel_isa();
  int compared = 0;
  for (linalg::KernelIsa isa : {linalg::KernelIsa::kGeneric, linalg::KernelIsa::kAvx2, linalg::KernelIsa::kAvx512}) {
    if (linalg::set_kernel_isa(isa) != isa) continue;  // the processor lacks it
    ++compared;
    for (Index first = 0; first < p.rows(); first += CorrelatedField::kBlock) {
      const int count = static_cast<int>(std::min<Index>(CorrelatedField::kBlock, p.rows() - first));
      Eigen::Matrix<double, CorrelatedField::kBlock, 3> v;
      field.at_rows(p, first, count, v);
      for (int i = 0; i < count; ++i) {
        const Vec3 one = field.at(p.row(first + i).transpose());
        for (int c = 0; c < 3; ++c)
          EXPECT_TRUE(same_bits(v(i, c), one[c])) << linalg::to_string(isa) << " row " << first + i << " comp " << c;
      }
    }
  }
  linalg::set_kernel_isa(best);
  EXPECT_GE(compared, 1);
}

}  // namespace
}  // namespace sf::gsa

// Tests of `gsa compare` (gsa/compare.hpp) with known answers: a part against itself, a
// rigidly misplaced copy, a known uniform strain offset, missing marks and outliers on
// either side, and bad inputs.

#include "gsa/compare.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "gsa/analysis.hpp"
#include "gsa/output.hpp"
#include "gsa/surfaces_file.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {
namespace {

constexpr double kStrainExact = 1e-10;    // identical or rigidly moved inputs: strains agree to round-off
constexpr double kLengthExact = 1e-9;     // mm, on a ~100 mm part
constexpr double kRotationExact = 1e-11;  // |R - R_exact|, registration by shared marks
constexpr unsigned kSeed = 20240611u;

GridData grid_of(const std::string& name, int n = 13, double spacing = 5.0) {
  SyntheticGridOptions go;
  go.n = n;
  go.spacing = spacing;
  return make_synthetic_grid(synthetic_case(name), go);
}

CompareSide side_of(const GridData& g, const std::string& source, const std::vector<double>& fibres = {}) {
  AnalyseOptions o;
  o.fibre_angles = fibres;
  const AnalysisResult r = analyse(g, o);
  return compare_side_from(g, r, source);
}

fe::RigidTransform misplacement() {
  fe::RigidTransform t;
  t.rotation = Eigen::AngleAxisd(0.3, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  t.translation = Vec3(12.5, -7.25, 3.0);
  return t;
}

GridData moved(GridData g, const fe::RigidTransform& t) {
  for (Index p = 0; p < g.n_points(); ++p)
    if (g.has_deformed(p)) g.deformed.row(p) = t.apply(Vec3(g.deformed.row(p).transpose())).transpose();
  return g;
}

double max_abs_difference(const CompareResult& r, Field f) {
  double m = 0;
  for (const auto& c : r.marks)
    if (c.matched) m = std::max(m, std::abs(c.difference[static_cast<std::size_t>(f)]));
  return m;
}

TEST(Compare, APartAgainstItselfHasNoDifference) {
  const GridData g = grid_of("dome");
  const CompareSide s = side_of(g, "dome");
  const CompareResult r = compare(s, s, {});
  EXPECT_EQ(r.registration.method, "shared marks (ids)");
  EXPECT_LT((r.registration.transform.rotation - Mat3::Identity()).norm(), kRotationExact);
  EXPECT_LT(r.registration.transform.translation.norm(), kLengthExact);
  for (const auto& c : r.marks) {
    ASSERT_TRUE(c.matched) << c.reason;
    EXPECT_EQ(c.mapping, "id");
    for (int q = 0; q < 3; ++q) EXPECT_LT(std::abs(c.difference[static_cast<std::size_t>(q)]), kStrainExact);
    EXPECT_LT(std::abs(c.shape_deviation), kLengthExact);
    EXPECT_LT(c.position_difference, kLengthExact);
  }
  // The tessellated differences are zero too (every point maps onto itself).
  for (double d : r.surface.difference[0])
    if (std::isfinite(d)) {
      EXPECT_LT(std::abs(d), 1e-8);
    }
}

TEST(Compare, ARigidMisplacementIsRecoveredToRoundoff) {
  const GridData g = grid_of("dome");
  const fe::RigidTransform t = misplacement();
  const CompareSide sim = side_of(g, "simulated");
  const CompareSide meas = side_of(moved(g, t), "measured");
  const CompareResult r = compare(meas, sim, {});
  const fe::RigidTransform expect = t.inverse();  // carries the measured part back onto the simulated
  EXPECT_LT((r.registration.transform.rotation - expect.rotation).norm(), 1e-9) << r.registration.brief();
  EXPECT_LT((r.registration.transform.translation - expect.translation).norm(), 1e-7) << r.registration.brief();
  EXPECT_LT(r.registration.rms, 1e-7);
  EXPECT_LT(max_abs_difference(r, Field::kMajor), 1e-8);
  EXPECT_LT(max_abs_difference(r, Field::kMinor), 1e-8);
  for (const auto& c : r.marks) EXPECT_LT(std::abs(c.shape_deviation), 1e-7);
}

TEST(Compare, ARigidMisplacementWithNoiseIsRecoveredWithinTheNoise) {
  const GridData g = grid_of("dome", 21);
  const fe::RigidTransform t = misplacement();
  GridData noisy = moved(g, t);
  std::mt19937 rng(kSeed);
  std::normal_distribution<double> noise(0.0, 0.02);  // mm, a good digitisation
  for (Index p = 0; p < noisy.n_points(); ++p)
    for (int k = 0; k < 3; ++k) noisy.deformed(p, k) += noise(rng);
  const CompareResult r = compare(side_of(noisy, "measured"), side_of(g, "simulated"), {});
  const fe::RigidTransform expect = t.inverse();
  // 441 marks, sigma 0.02 mm: the mean is good to ~1e-3 mm, the rotation to ~1e-5 rad.
  EXPECT_LT((r.registration.transform.rotation - expect.rotation).norm(), 2e-4) << r.registration.brief();
  EXPECT_LT((r.registration.transform.translation - expect.translation).norm(), 0.01) << r.registration.brief();
  EXPECT_LT(r.registration.rms, 0.03);
}

TEST(Compare, SurfaceRegistrationWithoutSharedIdsRecoversTheMotion) {
  // "wavy" has no rotational symmetry, so the closest points fix all six motions.
  const GridData g = grid_of("wavy", 17);
  fe::RigidTransform t;
  t.rotation = Eigen::AngleAxisd(0.12, Vec3(0.2, 0.5, 0.84).normalized()).toRotationMatrix();
  t.translation = Vec3(3.0, -2.0, 1.5);
  GridData renamed = moved(g, t);
  for (auto& id : renamed.ids) id = "m" + id;
  const CompareResult r = compare(side_of(renamed, "measured"), side_of(g, "simulated"), {});
  EXPECT_EQ(r.registration.method, "surface (ICP)");
  const fe::RigidTransform expect = t.inverse();
  EXPECT_LT((r.registration.transform.rotation - expect.rotation).norm(), 1e-6) << r.registration.brief();
  EXPECT_LT((r.registration.transform.translation - expect.translation).norm(), 1e-4) << r.registration.brief();
  EXPECT_EQ(r.blank_method, "ICP foot points");
  Index matched = 0;
  for (const auto& c : r.marks) {
    if (!c.matched) continue;
    ++matched;
    EXPECT_EQ(c.mapping, "material");
    EXPECT_LT(std::abs(c.difference[0]), 1e-5);
  }
  EXPECT_GT(matched, renamed.n_points() * 9 / 10);
}

// A flat 60 x 60 mm sheet stretched homogeneously: x = a1 X, y = a2 Y.
GridData stretched(double a1, double a2) {
  GridData g;
  const int n = 13;
  g.undeformed.resize(n * n, 3);
  g.deformed.resize(n * n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Index p = i * n + j;
      const double X = 5.0 * j - 30.0, Y = 5.0 * i - 30.0;
      g.ids.push_back("P" + std::to_string(i) + "_" + std::to_string(j));
      g.undeformed.row(p) = Vec3(X, Y, 0).transpose();
      g.deformed.row(p) = Vec3(a1 * X, a2 * Y, 0).transpose();
    }
  return g;
}

TEST(Compare, AKnownUniformStrainOffsetIsReportedExactly) {
  const CompareResult r =
      compare(side_of(stretched(1.10, 0.95), "measured"), side_of(stretched(1.08, 0.96), "simulated"), {});
  const double major = std::log(1.10) - std::log(1.08), minor = std::log(0.95) - std::log(0.96);
  const double thick = 100.0 * (1.0 / (1.10 * 0.95) - 1.0 / (1.08 * 0.96));
  Index on_part = 0;
  for (const auto& c : r.marks) {
    ASSERT_TRUE(c.matched);
    EXPECT_NEAR(c.difference[static_cast<std::size_t>(Field::kMajor)], major, kStrainExact);
    EXPECT_NEAR(c.difference[static_cast<std::size_t>(Field::kMinor)], minor, kStrainExact);
    EXPECT_NEAR(c.difference[static_cast<std::size_t>(Field::kThickness)], thick, 1e-8);
    // Both flat in one plane; the measured part is wider (1.10 > 1.08), so its outer marks
    // lie beyond the simulated part's edge and have no shape deviation.
    if (std::isnan(c.shape_deviation)) continue;
    ++on_part;
    EXPECT_NEAR(c.shape_deviation, 0.0, kLengthExact);
  }
  EXPECT_GT(on_part, static_cast<Index>(r.marks.size()) / 2);
  const Statistics st = statistics_of([&] {
    std::vector<double> v;
    for (const auto& c : r.marks) v.push_back(c.difference[0]);
    return v;
  }());
  EXPECT_NEAR(st.mean, major, kStrainExact);
  EXPECT_NEAR(st.p95, major, kStrainExact);
  EXPECT_LT(st.std_dev, kStrainExact);
}

TEST(Compare, MissingMarksOnEitherSideAreReportedNeverDifferenced) {
  const GridData g = grid_of("dome");
  GridData meas = g, sim = g;
  meas.deformed.row(3).setConstant(std::nan(""));  // not digitised on the part
  meas.deformed.row(40).setConstant(std::nan(""));
  sim.deformed.row(50).setConstant(std::nan(""));  // missing in the simulated grid
  // Drop a simulated mark entirely (no row of that id).
  const std::string dropped = sim.ids[60];
  GridData sim2;
  sim2.units = sim.units;
  std::vector<Index> keep;
  for (Index p = 0; p < sim.n_points(); ++p)
    if (p != 60) keep.push_back(p);
  sim2.undeformed.resize(static_cast<Index>(keep.size()), 3);
  sim2.deformed.resize(static_cast<Index>(keep.size()), 3);
  for (std::size_t k = 0; k < keep.size(); ++k) {
    sim2.ids.push_back(sim.ids[static_cast<std::size_t>(keep[k])]);
    sim2.undeformed.row(static_cast<Index>(k)) = sim.undeformed.row(keep[k]);
    sim2.deformed.row(static_cast<Index>(k)) = sim.deformed.row(keep[k]);
  }
  const CompareResult r = compare(side_of(meas, "measured"), side_of(sim2, "simulated"), {});
  for (Index p = 0; p < g.n_points(); ++p) {
    const MarkComparison& c = r.marks[static_cast<std::size_t>(p)];
    if (p == 3 || p == 40) {
      EXPECT_FALSE(c.matched);
      EXPECT_EQ(c.reason, "measured: missing_deformed");
    } else if (p == 50) {
      EXPECT_FALSE(c.matched);
      EXPECT_EQ(c.reason, "simulated: missing_deformed");
    } else if (p == 60) {
      EXPECT_FALSE(c.matched) << g.ids[static_cast<std::size_t>(p)] << " " << dropped;
      EXPECT_EQ(c.reason, "simulated: no mark of this id");
    } else {
      EXPECT_TRUE(c.matched) << p << " " << c.reason;
      continue;
    }
    for (double d : c.difference) EXPECT_TRUE(std::isnan(d));
    EXPECT_TRUE(std::isnan(c.shape_deviation));
  }
  // The marks both sides have still agree (the fits see nearly the same data).
  EXPECT_LT(max_abs_difference(r, Field::kMajor), 2e-3);
}

TEST(Compare, GrossOutliersOnOneSideDoNotMoveTheRegistration) {
  const GridData g = grid_of("dome", 17);
  GridData sim = g;
  for (Index p : {20, 100, 200}) sim.deformed(p, 2) += 3.0;  // three marks digitised 3 mm off
  const CompareResult r = compare(side_of(g, "measured"), side_of(sim, "simulated"), {});
  EXPECT_LT((r.registration.transform.rotation - Mat3::Identity()).norm(), 1e-4) << r.registration.brief();
  EXPECT_LT(r.registration.transform.translation.norm(), 0.01) << r.registration.brief();
  Index matched = 0;
  for (const auto& c : r.marks) matched += c.matched ? 1 : 0;
  EXPECT_EQ(matched, g.n_points());  // flagged marks keep the fitted surfaces' strain
}

TEST(Compare, MismatchedFibreModesAreRefusedWithAClearMessage) {
  const GridData g = grid_of("trellis", 9);
  const CompareSide with = side_of(g, "with", {0.0, 90.0}), without = side_of(g, "without");
  try {
    compare(with, without, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("mismatched fibre modes"));
    EXPECT_THAT(e.what(), testing::HasSubstr("with was analysed in fibre mode (0,90 deg)"));
    EXPECT_THAT(e.what(), testing::HasSubstr("without without fibres"));
  }
  // The same fibre mode on both sides compares the shear angle too.
  const CompareResult r = compare(with, with, {});
  EXPECT_TRUE(r.fibre_mode);
  EXPECT_LT(max_abs_difference(r, Field::kShear), 1e-9);
}

TEST(Compare, AMissingFolderOrAFolderWithoutSurfacesIsNamed) {
  EXPECT_THROW(
      {
        try {
          read_compare_side("/nonexistent/results");
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), testing::HasSubstr("/nonexistent/results: no such folder"));
          throw;
        }
      },
      InputError);
  const std::filesystem::path dir = std::filesystem::path(SF_BINARY_DIR) / "test_compare_no_surfaces";
  std::filesystem::create_directories(dir);
  io::write_file_atomic((dir / "strains.csv").string(), [](std::ostream& os) { os << "id,status\n"; });
  try {
    read_compare_side(dir.string());
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("no surfaces.json"));
  }
}

TEST(Compare, AResultsFolderReadsBackTheSameSide) {
  const GridData g = grid_of("dome", 11);
  AnalysisResult r = analyse(g, {});
  const std::filesystem::path dir = std::filesystem::path(SF_BINARY_DIR) / "test_compare_folder";
  {
    io::AtomicOutputDir out(dir);
    RunInfo info;
    write_results(out, g, r, {}, info);
    out.commit();
  }
  const CompareSide folder = read_compare_side(dir.string());
  const CompareSide memory = compare_side_from(g, r, "memory");
  // The surfaces come back to the last bit.
  EXPECT_EQ((folder.surfaces.undeformed - memory.surfaces.undeformed).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((folder.surfaces.deformed - memory.surfaces.deformed).cwiseAbs().maxCoeff(), 0.0);
  ASSERT_EQ(folder.n_marks(), memory.n_marks());
  const CompareResult c = compare(folder, memory, {});
  EXPECT_LT(max_abs_difference(c, Field::kMajor), 1e-14);
  EXPECT_LT(max_abs_difference(c, Field::kThickness), 1e-12);
}

TEST(Compare, StatisticsOfKnownValues) {
  const Statistics s = statistics_of({1, 2, 3, 4, std::nan(""), 5});
  EXPECT_EQ(s.n, 5);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_DOUBLE_EQ(s.rms, std::sqrt(11.0));
  EXPECT_DOUBLE_EQ(s.p50, 3.0);
  EXPECT_DOUBLE_EQ(s.p25, 2.0);
  EXPECT_DOUBLE_EQ(s.p05, 1.2);
  EXPECT_DOUBLE_EQ(s.max_abs, 5.0);
}

}  // namespace
}  // namespace sf::gsa

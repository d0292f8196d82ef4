// Stage series (gsa/series.hpp, gsa/series_output.hpp): per-stage strains against exact
// ones, a stage of the series equal to the one-state analysis of that stage, marks not
// measured in a stage, strain paths, the ParaView time series and the long table, and
// clear errors for stages of another part.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/vtk_xml.hpp"
#include "gsa/accuracy.hpp"
#include "gsa/series.hpp"
#include "gsa/series_output.hpp"
#include "gsa/synthetic_series.hpp"

namespace sf::gsa {
namespace {

namespace fs = std::filesystem;

// A linearly growing homogeneous stretch is in the bicubic space: exact to solver round-off
// (measured ~1e-13 on the 15 x 15 grid).
constexpr double kExactStrain = 1e-8;

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(GsaSeries, LinearlyGrowingStretchIsExactAtEveryStage) {
  SyntheticSeriesOptions so;
  so.n = 15;
  so.stages = 6;
  so.stretch = 0.3;
  so.contraction = 0.1;
  const SyntheticSeries syn = make_synthetic_series(so);
  const SeriesAnalysis a(syn.series, AnalyseOptions{});
  ASSERT_EQ(a.n_stages(), 6u);
  for (std::size_t k = 0; k < a.n_stages(); ++k) {
    const GridData g = a.stage_grid(k);
    const AnalysisResult r = a.analyse_stage(k, g);
    const double t = (k + 1.0) / 6.0;
    double worst = 0;
    for (Index p = 0; p < g.n_points(); ++p) {
      const auto& s = r.points[static_cast<std::size_t>(p)].strain;
      ASSERT_TRUE(s.has_value()) << "stage " << k << " point " << g.ids[static_cast<std::size_t>(p)];
      worst = std::max({worst, std::abs(s->lambda1 - (1 + 0.3 * t)), std::abs(s->lambda2 - (1 - 0.1 * t))});
    }
    EXPECT_LT(worst, kExactStrain) << "stage " << k;
  }
}

TEST(GsaSeries, EachStageEqualsTheOneStateAnalysisOfThatStage) {
  // The series reuses the undeformed stages; the result must be what analyse() gives on
  // the stage's own grid (same undeformed fit, same deformed stages).
  SyntheticSeriesOptions so;
  so.n = 17;
  so.stages = 3;
  so.bulge = 4.0;
  so.noise = 0.003;
  const SyntheticSeries syn = make_synthetic_series(so);
  const SeriesAnalysis a(syn.series, AnalyseOptions{}, SeriesSmoothing::kEachStage);
  EXPECT_FALSE(a.fixed_smoothing().has_value());
  for (std::size_t k = 0; k < a.n_stages(); ++k) {
    const GridData g = a.stage_grid(k);
    const AnalysisResult rs = a.analyse_stage(k, g);
    const AnalysisResult r1 = analyse(g, AnalyseOptions{});
    ASSERT_EQ(rs.points.size(), r1.points.size());
    EXPECT_EQ(rs.gauge_length, r1.gauge_length);
    for (std::size_t p = 0; p < rs.points.size(); ++p) {
      ASSERT_EQ(rs.points[p].status, r1.points[p].status);
      if (!rs.points[p].strain) continue;
      EXPECT_EQ(rs.points[p].strain->lambda1, r1.points[p].strain->lambda1) << "stage " << k << " point " << p;
      EXPECT_EQ(rs.points[p].strain->lambda2, r1.points[p].strain->lambda2) << "stage " << k << " point " << p;
    }
  }
}

TEST(GsaSeries, SmoothingChosenOnceOnTheLastStageServesEveryStage) {
  SyntheticSeriesOptions so;
  so.n = 17;
  so.stages = 3;
  so.bulge = 4.0;
  so.noise = 0.003;
  const SyntheticSeries syn = make_synthetic_series(so);
  const SeriesAnalysis a(syn.series, AnalyseOptions{});
  ASSERT_TRUE(a.fixed_smoothing().has_value());
  EXPECT_EQ(a.smoothing_stage(), 2u);
  const GridData last = a.stage_grid(2);
  const AnalysisResult full = analyse(last, AnalyseOptions{});
  for (std::size_t k = 0; k < a.n_stages(); ++k) {
    const GridData g = a.stage_grid(k);
    const AnalysisResult r = a.analyse_stage(k, g);
    EXPECT_EQ(r.gauge_length, full.gauge_length) << "stage " << k;
    EXPECT_EQ(r.smoothing_criterion, full.smoothing_criterion);
    if (k == 2)  // the stage it was chosen on is the one-state analysis of that stage
      for (std::size_t p = 0; p < r.points.size(); ++p)
        if (r.points[p].strain) {
          EXPECT_EQ(r.points[p].strain->lambda1, full.points[p].strain->lambda1);
        }
    EXPECT_LT(strain_error(g, r, syn.exact[k]).rms(), 1.5e-3) << "stage " << k;
  }
}

TEST(GsaSeries, BulgingSeriesFollowsTheExactStrainsStageByStage) {
  SyntheticSeriesOptions so;
  so.n = 21;
  so.stages = 4;
  so.stretch = 0.25;
  so.bulge = 6.0;
  so.noise = 0.002;
  const SyntheticSeries syn = make_synthetic_series(so);
  const SeriesAnalysis a(syn.series, AnalyseOptions{});
  for (std::size_t k = 0; k < a.n_stages(); ++k) {
    const GridData g = a.stage_grid(k);
    const AnalysisResult r = a.analyse_stage(k, g);
    const StrainError e = strain_error(g, r, syn.exact[k]);
    // Noise 0.002 mm on 2 mm spacing: a strain error of a few 1e-4 (measured 2-4e-4).
    EXPECT_LT(e.rms(), 1.5e-3) << "stage " << k;
    EXPECT_EQ(e.n_missing, 0);
  }
}

TEST(GsaSeries, MarkNotMeasuredInAStageIsFlaggedThereOnly) {
  SyntheticSeriesOptions so;
  so.n = 15;
  so.stages = 4;
  so.not_measured = 0.1;
  const SyntheticSeries syn = make_synthetic_series(so);
  const io::GridSeries& s = syn.series;
  const SeriesAnalysis a(s, AnalyseOptions{});
  std::vector<AnalysisResult> results;
  for (std::size_t k = 0; k < a.n_stages(); ++k) results.push_back(a.analyse_stage(k, a.stage_grid(k)));
  Index checked = 0;
  for (std::size_t k = 0; k < s.n_stages(); ++k) {
    ASSERT_FALSE(s.stages[k].not_measured.empty());
    for (std::size_t p = 0; p < s.ids.size(); ++p) {
      if (s.stages[k].not_measured[p]) {
        EXPECT_EQ(results[k].points[p].status, kStatusNotMeasured);
        EXPECT_FALSE(results[k].points[p].strain.has_value());
        ++checked;
        // Measured in another stage: a strain there.
        for (std::size_t o = 0; o < s.n_stages(); ++o)
          if (!s.stages[o].not_measured[p]) {
            EXPECT_TRUE(results[o].points[p].strain.has_value()) << p << " " << o;
          }
      } else {
        EXPECT_TRUE(results[k].points[p].strain.has_value()) << "stage " << k << " point " << p;
      }
    }
  }
  EXPECT_GT(checked, 10);
}

TEST(GsaSeries, StrainPathsFollowTheHighestStrainPointsThroughEveryStage) {
  SyntheticSeriesOptions so;
  so.n = 15;
  so.stages = 5;
  so.bulge = 5.0;
  const SyntheticSeries syn = make_synthetic_series(so);
  const SeriesAnalysis a(syn.series, AnalyseOptions{});
  StagePrincipalStrains principal(syn.series.n_points());
  for (std::size_t k = 0; k < a.n_stages(); ++k) principal.add(a.analyse_stage(k, a.stage_grid(k)));
  const GridData g = a.stage_grid(0);
  const std::vector<Index> pts = choose_path_points(principal, g, {}, 3, 4.0);
  ASSERT_EQ(pts.size(), 3u);
  // The first is the point of highest peak major stretch of all.
  double best = 0;
  for (Index p = 0; p < g.n_points(); ++p) best = std::max(best, principal.lambda1(4, p));
  EXPECT_EQ(principal.lambda1(4, pts[0]), best);
  // And they are spread out.
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j)
      EXPECT_GE((g.undeformed.row(pts[i]) - g.undeformed.row(pts[j])).norm(), 4.0);
  const std::vector<StrainPath> paths = strain_paths(principal, g, pts, StrainMeasure::kTrue);
  for (const StrainPath& path : paths) {
    ASSERT_EQ(path.major.size(), 5u);
    ASSERT_EQ(path.minor.size(), 5u);
    for (std::size_t k = 1; k < 5; ++k) EXPECT_GT(path.major[k], path.major[k - 1]) << path.id;  // growing stretch
    // Against the exact true strain of that point at the last stage.
    const ExactStrain& e = syn.exact[4][static_cast<std::size_t>(path.point)];
    EXPECT_NEAR(path.major[4], std::log(e.lambda1), 2e-3) << path.id;
    EXPECT_NEAR(path.minor[4], std::log(e.lambda2), 2e-3) << path.id;
  }
  // Chosen ids, in the order given; an unknown id names itself and the option.
  EXPECT_EQ(choose_path_points(principal, g, {"m3_4", "m0_0"}, 5, 1.0), (std::vector<Index>{3 * 15 + 4, 0}));
  EXPECT_THROW(
      {
        try {
          choose_path_points(principal, g, {"nope"}, 5, 1.0, "--path-ids");
        } catch (const UsageError& e) {
          EXPECT_THAT(e.what(), ::testing::HasSubstr("--path-ids: no point with id 'nope'"));
          throw;
        }
      },
      UsageError);
}

TEST(GsaSeries, WriterListsEveryStageInThePvdAndTheLongTable) {
  SyntheticSeriesOptions so;
  so.n = 11;
  so.stages = 4;
  const SyntheticSeries syn = make_synthetic_series(so);
  const SeriesAnalysis a(syn.series, AnalyseOptions{});
  const fs::path dir = fs::path(SF_BINARY_DIR) / "test_out" / "series_writer";
  fs::remove_all(dir);
  StagePrincipalStrains principal(syn.series.n_points());
  nlohmann::json j;
  {
    io::AtomicOutputDir out(dir);
    SeriesWriter w(out, syn.series, OutputOptions{}, true);
    for (std::size_t k = 0; k < a.n_stages(); ++k) {
      const GridData g = a.stage_grid(k);
      const AnalysisResult r = a.analyse_stage(k, g);
      w.add_stage(k, g, r);
      principal.add(r);
    }
    const GridData g0 = a.stage_grid(0);
    j = w.finish(strain_paths(principal, g0, choose_path_points(principal, g0, {}, 2, 2.0), StrainMeasure::kTrue),
                 a.undeformed_seconds());
    out.commit();
  }
  const std::string pvd = read_text((dir / "series.pvd").string());
  for (std::size_t k = 0; k < 4; ++k) {
    const std::string name = stage_surface_name(k, 4);
    EXPECT_EQ(name, "stages/stage_00" + std::to_string(k) + ".vtp");
    EXPECT_THAT(pvd, ::testing::HasSubstr("file=\"" + name + "\""));
    EXPECT_THAT(pvd, ::testing::HasSubstr("timestep=\"" + std::to_string(k + 1)));  // the stage times 1..4 s
    const io::PolyMesh m = io::read_vtp((dir / name).string());
    EXPECT_GT(m.n_points(), 0);
  }
  const std::regex data_set("<DataSet");
  EXPECT_EQ(std::distance(std::sregex_iterator(pvd.begin(), pvd.end(), data_set), std::sregex_iterator()), 4);
  // series_strains.csv: a comment, the header and a row per point and stage.
  std::ifstream csv(dir / "series_strains.csv");
  std::string line;
  int rows = 0;
  std::getline(csv, line);
  EXPECT_EQ(line[0], '#');
  std::getline(csv, line);
  EXPECT_THAT(line, ::testing::StartsWith("stage,stage_name,time,id,status,E1,E2"));
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 4 * 121);
  ASSERT_EQ(j["stages"].size(), 4u);
  EXPECT_EQ(j["stages"][2]["name"], "stage_3");
  EXPECT_EQ(j["stages"][2]["counts"]["ok"], 121);
  EXPECT_EQ(j["strain_paths"]["ids"].size(), 2u);
  EXPECT_TRUE(fs::exists(dir / "strain_paths.csv"));
}

TEST(GsaSeries, StageOfAnotherPartIsAClearError) {
  SyntheticSeriesOptions so;
  so.n = 9;
  so.stages = 3;
  SyntheticSeries syn = make_synthetic_series(so);
  io::GridSeries& s = syn.series;
  // As read without a reference file: sources are the stage files; stage 2 numbers
  // other points (its ids are new: their first rows are in it).
  s.sources.erase(s.sources.begin());
  const Index n = s.n_points();
  for (Index p = 0; p < n; ++p) {
    s.ids.push_back("other" + std::to_string(p));
    s.undeformed.conservativeResize(s.undeformed.rows() + 1, 3);
    s.undeformed.row(s.undeformed.rows() - 1) = s.undeformed.row(p);
  }
  for (std::size_t k = 0; k < s.n_stages(); ++k) {
    io::GridStage& st = s.stages[k];
    st.deformed.conservativeResize(2 * n, 3);
    st.where.resize(static_cast<std::size_t>(2 * n));
    if (k == 2)
      for (Index p = 0; p < n; ++p) {
        st.where[static_cast<std::size_t>(n + p)] = st.where[static_cast<std::size_t>(p)];
        st.where[static_cast<std::size_t>(p)].clear();
      }
  }
  try {
    check_series(s);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("synthetic stage_3: 81 of its 81 point ids are not in the first stage"));
  }
}

}  // namespace
}  // namespace sf::gsa

// Issue 20 for gsa: coordinates far from the origin are fitted centred (strains as without
// the offset, a warning where the input itself lost precision), and a results folder with
// one surface missing is refused by `gsa plot`.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "gsa/analysis.hpp"
#include "gsa/centring.hpp"
#include "gsa/command_options.hpp"
#include "gsa/gross_blunders.hpp"
#include "gsa/mesh_file.hpp"
#include "gsa/output.hpp"
#include "gsa/results_folder.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {
namespace {

namespace fs = std::filesystem;

GridData dome(int n = 9) {
  SyntheticGridOptions g;
  g.n = n;
  g.spacing = 5;
  return make_synthetic_grid(synthetic_case("dome"), g);
}

// What `gsa analyse` does: centre, analyse, move back.
AnalysisResult analyse_as_the_command(const GridData& grid, Centring* c = nullptr) {
  GridData centred = grid;
  const Centring centring = centre_grid(centred, false, "mm");
  AnalysisResult r = analyse(centred, AnalyseOptions{});
  uncentre(r, centring);
  if (c) *c = centring;
  return r;
}

double largest_strain_difference(const AnalysisResult& a, const AnalysisResult& b) {
  double d = 0.0;
  for (std::size_t p = 0; p < a.points.size(); ++p) {
    if (!a.points[p].strain || !b.points[p].strain) return INFINITY;
    d = std::max({d, std::abs(a.points[p].strain->lambda1 - b.points[p].strain->lambda1),
                  std::abs(a.points[p].strain->lambda2 - b.points[p].strain->lambda2)});
  }
  return d;
}

TEST(GsaReliability, OffsetCoordinatesGiveTheSameStrains) {
  const GridData g = dome();
  const AnalysisResult reference = analyse_as_the_command(g);
  for (const double offset : {1e6, 1e9}) {
    GridData shifted = g;
    shifted.undeformed.array().rowwise() += Eigen::Array3d(offset, -offset, 0.5 * offset).transpose();
    shifted.deformed.array().rowwise() += Eigen::Array3d(offset, offset, offset).transpose();
    Centring c;
    const AnalysisResult r = analyse_as_the_command(shifted, &c);
    EXPECT_TRUE(c.applied);
    EXPECT_TRUE(c.warning.empty()) << c.warning;
    EXPECT_LT(largest_strain_difference(r, reference), 1e-6) << "offset " << offset;
    // The outputs are in the coordinates given: the plane origin lies on the shifted part.
    EXPECT_NEAR(r.centroid.x(), reference.centroid.x() + offset, 1e-3 * offset * 1e-6 + 1e-3);
    EXPECT_NEAR(r.rigid.translation.y(), reference.rigid.translation.y() + 2 * offset, 1e-3);
  }
}

// Before: strain errors of order 100 with exit 0 and no warning at 1e14 mm.
TEST(GsaReliability, HugeOffsetIsWarnedAndStaysBounded) {
  const GridData g = dome();
  const AnalysisResult reference = analyse_as_the_command(g);
  GridData shifted = g;
  shifted.undeformed.array() += 1e14;
  shifted.deformed.array() += 1e14;
  Centring c;
  const AnalysisResult r = analyse_as_the_command(shifted, &c);
  EXPECT_THAT(c.warning, ::testing::HasSubstr("coordinates as large as 1e+14 mm keep only 0.02"));
  // What is left is the rounding of the input itself (0.016 mm on 5 mm spacing).
  EXPECT_LT(largest_strain_difference(r, reference), 0.05);
}

TEST(GsaReliability, PlotRefusesAFolderWithOneSurfaceMissing) {
  const fs::path dir = fs::temp_directory_path() / ("sf_gsa_rel_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const GridData g = dome(7);
  AnalysisResult r = analyse(g, AnalyseOptions{});
  OutputOptions o;
  o.keep_surfaces = true;
  {
    io::AtomicOutputDir out(dir);
    write_results(out, g, r, o, RunInfo{"test", {"dome/grid.csv"}});
    out.commit();
  }
  ASSERT_TRUE(fs::exists(dir / "deformed.vtp"));
  EXPECT_NO_THROW(read_results_folder(dir.string()));
  fs::remove(dir / "deformed.vtp");
  try {
    read_results_folder(dir.string());
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("deformed.vtp: missing beside"));
  }
  fs::remove_all(dir);
}

template <class E, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "(no exception)";
}

// Before: --beta nan was ignored, inf failed later without naming the option, a newline in
// --units corrupted strains.csv.
TEST(GsaReliability, NanAndInfiniteOptionsAreNamed) {
  const auto options = [](auto set) {
    AnalyseFlags f;
    f.out = "out";
    set(f);
    return message_of<UsageError>([&] { analyse_options(f); });
  };
  EXPECT_THAT(options([](AnalyseFlags& f) { f.beta = std::nan(""); }), ::testing::HasSubstr("--beta"));
  EXPECT_THAT(options([](AnalyseFlags& f) { f.gamma = INFINITY; }), ::testing::HasSubstr("--gamma"));
  EXPECT_THAT(options([](AnalyseFlags& f) { f.smoothing_scale = INFINITY; }),
              ::testing::HasSubstr("--smoothing-scale"));
  EXPECT_THAT(options([](AnalyseFlags& f) { f.fibres = "nan,90"; }), ::testing::HasSubstr("--fibres"));
  AnalyseFlags f;
  f.units = "mm\nx";
  EXPECT_THAT(message_of<UsageError>([&] { output_options(f); }), ::testing::HasSubstr("--units"));
  EXPECT_THAT(message_of<UsageError>([] { parse_delimiter("#"); }), ::testing::HasSubstr("--delimiter"));
}

// Before: "internal error, please report".
TEST(GsaReliability, MeshFileFolderAndHugeNumberAreInputErrors) {
  const fs::path dir = fs::temp_directory_path() / ("sf_gsa_mesh_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "huge.json") << R"({"nodes": [[0,0,1e400],[1,0,0],[0,1,0],[1,1,0]], "elements": [[0,1,2,3]]})";
  EXPECT_THAT(message_of<InputError>([&] { read_mesh_file((dir / "huge.json").string()); }),
              ::testing::HasSubstr("1e400"));
  EXPECT_THAT(message_of<InputError>([&] { read_mesh_file(dir.string()); }), ::testing::HasSubstr("is a folder"));
  fs::remove_all(dir);
}

// Before: undeformed X = 150 instead of 5 (or Z = 1000 on a flat blank) made the fit
// "singular" with a wrong hint; now the mark is flagged and the rest analysed.
TEST(GsaReliability, GrossBlunderIsFlaggedNotFatal) {
  for (const int column : {0, 2}) {
    GridData g = dome(11);
    const Index bad = 39;
    g.undeformed(bad, column) = column == 0 ? 150.0 : 1000.0;
    GridData work = g;
    const std::vector<GrossBlunder> blunders = screen_gross_blunders(work);
    ASSERT_EQ(blunders.size(), 1u);
    EXPECT_EQ(blunders[0].point, bad);
    EXPECT_TRUE(blunders[0].undeformed);
    AnalysisResult r = analyse(work, AnalyseOptions{});
    report_gross_blunders(r, g, blunders, "mm");
    EXPECT_EQ(r.points[bad].status, kStatusOutlierUndeformed);
    EXPECT_THAT(r.warnings.back(), ::testing::HasSubstr("gross blunder"));
    Index ok = 0;
    for (const auto& p : r.points) ok += p.strain ? 1 : 0;
    EXPECT_EQ(ok, g.n_points() - 1);
  }
  // A clean grid has none.
  GridData clean = dome(11);
  EXPECT_TRUE(screen_gross_blunders(clean).empty());
}

}  // namespace
}  // namespace sf::gsa

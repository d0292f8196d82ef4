// Tests of the gsa pictures (gsa/plots): arrow diagrams on a homogeneous stretch, the
// files `gsa analyse` and `gsa plot` write, the forming limit margin, fibre mode, the
// triangle method, option parsing and errors. Small grids and 400 x 300 pictures keep
// each test near a second.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/render/scene.hpp"
#include "gsa/analysis.hpp"
#include "gsa/output.hpp"
#include "gsa/command_options.hpp"
#include "gsa/flc.hpp"
#include "gsa/plots.hpp"
#include "gsa/results_folder.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {
namespace {

namespace fs = std::filesystem;

fs::path test_dir(const std::string& name) {
  const fs::path d = fs::path(SF_BINARY_DIR) / "test_output" / "gsa_plots" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

double distance(const render::Colour& a, const render::Colour& b) {
  return std::sqrt((a.r - b.r) * (a.r - b.r) + (a.g - b.g) * (a.g - b.g) + (a.b - b.b) * (a.b - b.b));
}

// Analyses a synthetic case into `dir` (results files only, no pictures).
void analyse_case(const std::string& name, const fs::path& dir, int n = 9, std::vector<double> fibres = {},
                  Method method = Method::kSurface) {
  SyntheticGridOptions g;
  g.n = n;
  g.spacing = 10;
  const GridData grid = make_synthetic_grid(synthetic_case(name), g);
  AnalyseOptions o;
  o.method = method;
  o.fibre_angles = std::move(fibres);
  AnalysisResult r = method == Method::kSurface ? analyse(grid, o) : analyse_triangles(grid, o);
  io::AtomicOutputDir out(dir);
  write_results(out, grid, r, OutputOptions{}, RunInfo{"test", {name}});
  out.commit();
}

PlotOptions small_pictures() {
  PlotOptions o;
  o.size = {400, 300};
  return o;
}

std::function<std::string(const std::string&)> into(const fs::path& dir) {
  return [dir](const std::string& name) { return (dir / name).string(); };
}

// `gsa plot DIR` without the command line: the pictures of a results folder, redrawn in place.
Redrawn redraw(const fs::path& dir, const PlotOptions& o, const std::string& flc = "") {
  std::optional<FormingLimitCurve> curve;
  if (!flc.empty()) curve = read_flc(flc);
  return redraw_results_folder(dir.string(), StrainMeasure::kTrue, curve, o, into(dir));
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ---------------------------------------------------------------------------------------

// Homogeneous stretch 1.2 x 0.9 along X and Y of the blank: on the undeformed blank every
// tension arrow lies along X with its head outside, every compression arrow along Y
// pointing in, all pairs alike; and in the image the arrows' middles are red and blue.
TEST(GsaPlots, ArrowsOnAHomogeneousStretchLandWhereExpected) {
  const fs::path dir = test_dir("stretch_arrows");
  analyse_case("stretch", dir);
  const PlotData r = plot_data(read_results_folder(dir.string()), StrainMeasure::kTrue);
  ASSERT_TRUE(r.has_surfaces);
  PlotOptions o = small_pictures();
  const render::Scene scene = arrow_diagram(r, false, o);
  ASSERT_EQ(scene.glyphs.size(), 2u);
  const render::GlyphSet& tension = scene.glyphs[0];
  const render::GlyphSet& compression = scene.glyphs[1];
  ASSERT_FALSE(tension.tails.empty());
  ASSERT_EQ(tension.tails.size(), compression.tails.size());  // one pair of each per point
  const double l_tension = (tension.heads[0] - tension.tails[0]).norm();
  const double l_compression = (compression.heads[0] - compression.tails[0]).norm();
  // Lengths proportional to the true strains ln 1.2 and |ln 0.9|.
  EXPECT_NEAR(l_compression / l_tension, std::abs(std::log(0.9)) / std::log(1.2), 2e-3);
  for (std::size_t i = 0; i < tension.tails.size(); ++i) {
    const Vec3 t = tension.heads[i] - tension.tails[i], c = compression.heads[i] - compression.tails[i];
    EXPECT_GT(std::abs(t.normalized().x()), 0.9999) << "tension arrow " << i << " not along X";
    EXPECT_GT(std::abs(c.normalized().y()), 0.9999) << "compression arrow " << i << " not along Y";
    EXPECT_NEAR(t.norm(), l_tension, 1e-3 * l_tension);
    // Heads out for tension: the head is farther from the pair's centre than the tail.
    const std::size_t pair = i ^ 1u;  // arrows come in pairs (-d, +d) about one point
    const Vec3 centre_t = 0.5 * (tension.tails[i] + tension.tails[pair]);
    EXPECT_GT((tension.heads[i] - centre_t).norm(), (tension.tails[i] - centre_t).norm());
    const Vec3 centre_c = 0.5 * (compression.heads[i] + compression.heads[pair]);
    EXPECT_LT((compression.heads[i] - centre_c).norm(), (compression.tails[i] - centre_c).norm());
  }
  const std::string png = (dir / "arrows.png").string();
  const render::Framing fr = render::write_png(scene, {800, 600}, png);  // shafts a few pixels wide
  const render::RgbImage img = render::read_png_rgb(png);
  int checked = 0;
  for (const auto* g : {&tension, &compression})
    for (std::size_t i = 0; i < g->tails.size(); ++i) {
      // Take the best of the 3 x 3 pixels around the middle (anti-aliased edges).
      const Vec2 p = fr.to_pixel(0.5 * (g->tails[i] + g->heads[i]));
      double best = 1e9;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          best = std::min(best, distance(img.at(int(std::floor(p.x())) + dx, int(std::floor(p.y())) + dy), g->colour));
      EXPECT_LT(best, 0.2) << (g == &tension ? "tension" : "compression") << " arrow " << i;
      ++checked;
    }
  EXPECT_GT(checked, 20);
}

TEST(GsaPlots, WritesEveryPictureAndTheReport) {
  const fs::path dir = test_dir("all_pictures");
  analyse_case("dome", dir);
  const PlotSummary s = redraw(dir, small_pictures()).pictures;
  const std::vector<std::string> expected = {"arrows_undeformed.png", "arrows_deformed.png", "thickness.png",
                                             "major_strain.png",      "minor_strain.png",    "principal_strains.png"};
  EXPECT_EQ(s.pictures, expected);
  const std::string report = read_text(dir / "report.html");
  for (const auto& name : expected) {
    SCOPED_TRACE(name);
    const render::RgbImage img = render::read_png_rgb((dir / name).string());
    EXPECT_EQ(img.width, 400);
    EXPECT_EQ(img.height, 300);
    EXPECT_NE(report.find("src=\"" + name + "\""), std::string::npos);
  }
  EXPECT_NE(report.find("Fit residuals"), std::string::npos);
  EXPECT_NE(report.find("</html>"), std::string::npos);
  EXPECT_EQ(s.n_marks, 81);
  // Nothing else left behind (no temporary files).
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
}

// The thickness picture of a homogeneous stretch is one colour: the middle of the part has
// the colour of the band holding 100 (1/(1.2 * 0.9) - 1) = -7.41 %.
TEST(GsaPlots, UniformThicknessIsOneBand) {
  const fs::path dir = test_dir("uniform_thickness");
  analyse_case("stretch", dir);
  redraw(dir, small_pictures());
  const render::RgbImage img = render::read_png_rgb((dir / "thickness.png").string());
  // The part fills the middle of the frame; sample a small patch around its centre.
  const render::Colour c = img.at(150, 160);
  for (int dx = -20; dx <= 20; dx += 10)
    for (int dy = -20; dy <= 20; dy += 10) EXPECT_LT(distance(img.at(150 + dx, 160 + dy), c), 0.03);
  EXPECT_GT(distance(c, {1, 1, 1}), 0.2);  // not background
}

TEST(GsaPlots, FormingLimitMarginIsWrittenPerMark) {
  const fs::path dir = test_dir("flc");
  analyse_case("stretch", dir);
  // True strains of the stretch: major ln 1.2 = 0.1823, minor ln 0.9 = -0.1054. A straight
  // curve through (-0.2, 0.3) and (0, 0.1) has major 0.2054 there: margin 0.0231.
  const fs::path flc = dir / "flc.csv";
  std::ofstream(flc) << "# test curve\nmajor,minor\n0.1,0\n0.3,-0.2\n";
  const PlotOptions o = small_pictures();
  const Redrawn s = redraw(dir, o, flc.string());
  ASSERT_TRUE(s.margins);
  EXPECT_EQ(s.margins->n_beyond, 0);
  EXPECT_EQ(s.margins->n_marks, 81);
  const double expected = 0.1 + 0.2 * (-std::log(0.9) / 0.2) - std::log(1.2);
  EXPECT_NEAR(s.margins->min_margin, expected, 1e-4);
  const io::CsvTable t = io::read_csv((dir / "strains.csv").string());
  const std::size_t c = t.column_index("flc_margin");
  EXPECT_EQ(c, t.n_columns() - 1);
  for (std::size_t row = 0; row < t.n_rows(); ++row) EXPECT_NEAR(t.number(row, c), expected, 1e-4);
  EXPECT_NE(read_text(dir / "strains.csv").find("# flc_margin"), std::string::npos);
  // Drawn again with a lower curve: every mark is beyond it; the column is replaced.
  std::ofstream(flc) << "minor,major\n-0.2,0.15\n0,0.05\n";
  const Redrawn s2 = redraw(dir, o, flc.string());
  EXPECT_EQ(s2.margins->n_beyond, 81);
  const io::CsvTable t2 = io::read_csv((dir / "strains.csv").string());
  EXPECT_EQ(t2.n_columns(), t.n_columns());
  EXPECT_LT(t2.number(0, t2.column_index("flc_margin")), 0);
}

// `gsa analyse` draws from the results in memory, `gsa plot` from the files: the same
// pictures, report and strains.csv (with the forming limit margin) byte for byte.
TEST(GsaPlots, PicturesFromMemoryEqualPicturesRedrawnFromTheFolder) {
  const fs::path dir = test_dir("memory"), again = test_dir("memory_again");
  std::ofstream(dir.parent_path() / "memory_flc.csv") << "minor,major\n-0.3,0.3\n0,0.1\n0.3,0.25\n";
  const FormingLimitCurve flc = read_flc((dir.parent_path() / "memory_flc.csv").string());
  SyntheticGridOptions g;
  g.n = 9;
  g.spacing = 10;
  const GridData grid = make_synthetic_grid(synthetic_case("dome"), g);
  AnalysisResult r = analyse(grid, {});
  OutputOptions out_options;
  out_options.flc = flc;
  out_options.keep_surfaces = true;
  PlotSummary drawn;
  {
    io::AtomicOutputDir out(dir);
    WrittenResults written = write_results(out, grid, r, out_options, RunInfo{"test", {"dome/grid.csv"}});
    ASSERT_TRUE(written.margins);
    EXPECT_EQ(written.margins->n_marks, 81);
    PlotData data = plot_data(r, written.summary, std::move(written.undeformed), std::move(written.deformed),
                              dir.string(), StrainMeasure::kTrue);
    data.flc = flc;
    data.margins = written.margins;
    drawn = write_pictures(data, small_pictures(), [&out](const std::string& n) { return out.path(n); });
    out.commit();
  }
  // Redrawn from the folder's files into another folder.
  const Redrawn redrawn = redraw_results_folder(dir.string(), StrainMeasure::kTrue, flc, small_pictures(), into(again));
  EXPECT_EQ(redrawn.pictures.pictures, drawn.pictures);
  EXPECT_EQ(redrawn.pictures.n_marks, drawn.n_marks);
  std::vector<std::string> files = drawn.pictures;
  files.insert(files.end(), {"report.html"});
  for (const std::string& name : files) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(fs::exists(again / name));
    EXPECT_TRUE(read_text(dir / name) == read_text(again / name)) << "differs";
  }
  // strains.csv: the same columns and margins; redrawn with the curve `gsa analyse` assessed
  // with, the zones (flc_radial_margin, zone) stay (docs/usage.md, "Redrawing").
  const io::CsvTable a = io::read_csv((dir / "strains.csv").string()),
                     b = io::read_csv((again / "strains.csv").string());
  ASSERT_EQ(a.n_rows(), b.n_rows());
  EXPECT_EQ(a.names(), b.names());
  EXPECT_TRUE(b.has_column("zone"));
  for (std::size_t row = 0; row < a.n_rows(); ++row)
    EXPECT_EQ(a.cell(row, a.column_index("flc_margin")), b.cell(row, b.column_index("flc_margin")));
  EXPECT_NE(read_text(dir / "report.html").find("marks beyond the curve"), std::string::npos);
  // Redrawn with another curve: the zones of the first go (strains.csv, the report's counts).
  const fs::path other = dir.parent_path() / "memory_other_flc.csv";
  std::ofstream(other) << "minor,major\n-0.3,0.35\n0,0.12\n0.3,0.3\n";
  const fs::path third = test_dir("memory_other");
  redraw_results_folder(dir.string(), StrainMeasure::kTrue, read_flc(other.string()), small_pictures(), into(third));
  const io::CsvTable c = io::read_csv((third / "strains.csv").string());
  EXPECT_FALSE(c.has_column("zone"));
  EXPECT_FALSE(c.has_column("flc_radial_margin"));
  EXPECT_EQ(c.names().back(), "flc_margin");
  EXPECT_EQ(read_text(third / "report.html").find("Forming-limit assessment"), std::string::npos);
}

TEST(GsaPlots, FibreModeDrawsShearAngleAndFibres) {
  const fs::path dir = test_dir("fibres");
  analyse_case("trellis", dir, 9, {0, 90});
  const PlotSummary s = redraw(dir, small_pictures()).pictures;
  EXPECT_NE(std::find(s.pictures.begin(), s.pictures.end(), "shear_angle.png"), s.pictures.end());
  EXPECT_NE(std::find(s.pictures.begin(), s.pictures.end(), "fibres.png"), s.pictures.end());
  EXPECT_TRUE(fs::exists(dir / "shear_angle.png"));
  EXPECT_TRUE(fs::exists(dir / "fibres.png"));
}

TEST(GsaPlots, TriangleMethodGetsTheStrainPlotOnly) {
  const fs::path dir = test_dir("triangles");
  analyse_case("stretch", dir, 9, {}, Method::kTriangles);
  const PlotSummary s = redraw(dir, small_pictures()).pictures;
  EXPECT_EQ(s.pictures, std::vector<std::string>{"principal_strains.png"});
  EXPECT_TRUE(fs::exists(dir / "report.html"));
  EXPECT_FALSE(fs::exists(dir / "thickness.png"));
}

TEST(GsaPlots, OptionsAndBadInputs) {
  EXPECT_EQ(parse_measure("true"), StrainMeasure::kTrue);
  EXPECT_EQ(parse_measure("Engineering"), StrainMeasure::kEngineering);
  EXPECT_EQ(parse_measure("lagrangian"), StrainMeasure::kLagrangian);
  EXPECT_THROW(parse_measure("log10"), UsageError);
  EXPECT_NEAR(strain_of_stretch(1.2, StrainMeasure::kLagrangian), 0.22, 1e-12);
  EXPECT_NEAR(strain_of_stretch(1.2, StrainMeasure::kEngineering), 0.2, 1e-12);

  const fs::path dir = test_dir("bad_inputs");
  std::ofstream(dir / "one_row.csv") << "minor,major\n0,0.2\n";
  std::ofstream(dir / "no_major.csv") << "minor,limit\n0,0.2\n0.1,0.3\n";
  std::ofstream(dir / "text.csv") << "minor,major\n0,0.2\n0.1,abc\n";
  EXPECT_THROW(read_flc((dir / "one_row.csv").string()), InputError);
  try {
    read_flc((dir / "no_major.csv").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("major"), std::string::npos) << e.what();
  }
  try {
    read_flc((dir / "text.csv").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":3:2:"), std::string::npos) << e.what();
  }
  FormingLimitCurve c;
  c.minor = {-0.1, 0.0, 0.2};
  c.major = {0.3, 0.1, 0.2};
  EXPECT_NEAR(c.major_at(-0.05), 0.2, 1e-12);
  EXPECT_NEAR(c.major_at(0.1), 0.15, 1e-12);
  EXPECT_TRUE(std::isnan(c.major_at(0.3)));
  EXPECT_THROW(read_results_folder((dir / "nowhere").string()), InputError);
}

// The command line: `gsa analyse --no-plots` draws nothing; `gsa plot` redraws with other
// options; bad options are usage errors (exit 2), a missing folder bad input (exit 1).
TEST(GsaPlots, PlotCommandRedrawsAResultsFolder) {
  const fs::path dir = test_dir("command");
  const std::string gsa = std::string(SF_BINARY_DIR) + "/bin/gsa";
  ASSERT_TRUE(fs::exists(gsa));
  const std::string grid = (dir / "grid.csv").string(), out = (dir / "results").string();
  auto run = [](const std::string& cmd) {
    const int st = std::system((cmd + " >/dev/null 2>&1").c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  };
  ASSERT_EQ(run(gsa + " synth stretch --n 7 --spacing 10 --out " + grid), 0);
  ASSERT_EQ(run(gsa + " analyse " + grid + " --out " + out + " --no-plots"), 0);
  EXPECT_FALSE(fs::exists(dir / "results" / "arrows_deformed.png"));
  EXPECT_FALSE(fs::exists(dir / "results" / "report.html"));
  EXPECT_EQ(run(gsa + " plot " + out + " --size 320x240 --measure engineering --view iso"), 0);
  const render::RgbImage img = render::read_png_rgb((dir / "results" / "thickness.png").string());
  EXPECT_EQ(img.width, 320);
  EXPECT_EQ(img.height, 240);
  EXPECT_TRUE(fs::exists(dir / "results" / "report.html"));
  EXPECT_EQ(run(gsa + " plot " + out + " --measure log10"), 2);
  EXPECT_EQ(run(gsa + " plot " + out + " --size big"), 2);
  EXPECT_EQ(run(gsa + " plot " + out + " --view sideways"), 2);
  EXPECT_EQ(run(gsa + " plot " + (dir / "nowhere").string()), 1);
  EXPECT_EQ(run(gsa + " plot " + out + " --flc " + (dir / "missing_flc.csv").string()), 1);
  // No temporary sibling folders left behind.
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// A two-file run's pictures name both files, not only the undeformed one.
TEST(GsaPlots, TwoFileRunsAreNamedByBothFiles) {
  nlohmann::json summary;
  summary["inputs"] = {"trial/blank.csv", "trial/formed.csv"};
  EXPECT_EQ(case_name_of(summary, "out"), "trial/blank.csv \xE2\x86\x92 trial/formed.csv");
  summary["inputs"] = {"dome/grid.csv"};
  EXPECT_EQ(case_name_of(summary, "out"), "dome/grid.csv");
}

}  // namespace
}  // namespace sf::gsa

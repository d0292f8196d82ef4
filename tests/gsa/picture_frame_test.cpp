// The pictures of a long part are cut to its proportions when the size is the default
// (PlotOptions::fit_height), and keep the size asked for otherwise.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/io/atomic_file.hpp"
#include "common/render/scene.hpp"
#include "gsa/analysis.hpp"
#include "gsa/command_options.hpp"
#include "gsa/output.hpp"
#include "gsa/plots.hpp"
#include "gsa/synthetic_measurement.hpp"

namespace sf::gsa {
namespace {

namespace fs = std::filesystem;

// A 60 x 6 mm strip of 61 x 7 marks in uniform tension, analysed into `dir`.
void analyse_strip(const fs::path& dir) {
  SyntheticMeasurementOptions o;
  o.layout.length_x = 60.0;
  o.layout.length_y = 6.0;
  o.layout.spacing = 1.0;
  const SyntheticMeasurement m = make_measurement(neck_deformation(0.1, 0.1, 1.0), o);
  AnalysisResult r = analyse(m.grid, AnalyseOptions{});
  io::AtomicOutputDir out(dir);
  write_results(out, m.grid, r, OutputOptions{}, RunInfo{"test", {"strip.csv"}});
  out.commit();
}

TEST(GsaPictureFrame, LongStripPicturesAreCutToItsProportions) {
  const fs::path dir = fs::path(SF_BINARY_DIR) / "test_output" / "gsa_picture_frame";
  fs::remove_all(dir);
  fs::create_directories(dir);
  analyse_strip(dir);
  auto into = [&](const std::string& name) { return (dir / name).string(); };
  PlotOptions o;
  o.size = {800, 600};
  o.fit_height = true;
  redraw_results_folder(dir.string(), StrainMeasure::kTrue, std::nullopt, o, into);
  // 0.72 x 800 x 6/60 + 133 px of titles is below the floor of 0.45 x 800.
  EXPECT_EQ(render::read_png_rgb((dir / "arrows_undeformed.png").string()).height, 360);
  EXPECT_EQ(render::read_png_rgb((dir / "major_strain.png").string()).height, 360);
  EXPECT_EQ(render::read_png_rgb((dir / "principal_strains.png").string()).height, 600);  // a chart
  o.fit_height = false;
  redraw_results_folder(dir.string(), StrainMeasure::kTrue, std::nullopt, o, into);
  EXPECT_EQ(render::read_png_rgb((dir / "arrows_undeformed.png").string()).height, 600);
}

TEST(GsaPictureFrame, OnlyTheDefaultSizeIsCutToThePart) {
  EXPECT_TRUE(plot_options("1200x900", "auto").fit_height);
  EXPECT_FALSE(plot_options("1200x800", "auto").fit_height);
}

}  // namespace
}  // namespace sf::gsa

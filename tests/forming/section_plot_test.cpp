// The section of a 3-D part in `simform plot` (issue 13 item 4; docs/forming.md
// "Pictures and report"): a small quarter dome (tests/forming/cases/dome_3d.yaml, two
// plies pressed by a sphere) is run, and plots/section.png must show both plies, each in
// its own colour, and the punch's profile, also for a plane along x (the symmetry edge
// of the quarter model, moved a hair into the part).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/render/scene.hpp"
#include "forming/case/reader.hpp"
#include "forming/plot/plots.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

// Pixels within 24 (of 255) per channel of colour (r, g, b).
int count_colour(const render::RgbImage& img, int r, int g, int b) {
  int n = 0;
  for (std::size_t p = 0; p + 2 < img.pixels.size(); p += 3)
    if (std::abs(img.pixels[p] - r) < 24 && std::abs(img.pixels[p + 1] - g) < 24 &&
        std::abs(img.pixels[p + 2] - b) < 24)
      ++n;
  return n;
}

TEST(SectionPlot, ADomeSectionShowsEveryPlyAndThePunch) {
  const CaseCheck c = check_case_file(std::string(SF_SOURCE_DIR) + "/tests/forming/cases/dome_3d.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  const std::filesystem::path dir = std::filesystem::path(SF_BINARY_DIR) / "forming_out" / "section_plot";
  const fixtures::RunOutput run = fixtures::run_into(c.spec, dir);
  ASSERT_TRUE(run.report.ok()) << run.report.message;
  for (const double angle : {0.0}) {  // along the quarter model's symmetry edge (the CLI test draws 45)
    PlotOptions o;
    o.frames = 0;
    o.animation = false;
    o.quiet = true;
    o.size = {800, 600};
    o.section_angle_deg = angle;
    const PlotReport report = plot_results(dir.string(), o);
    bool listed = false;
    for (const std::string& p : report.pictures) listed = listed || p == "plots/section.png";
    ASSERT_TRUE(listed) << "angle " << angle;
    const render::RgbImage img = render::read_png_rgb((dir / "plots" / "section.png").string());
    // The palette of plots.cpp: lam.1 #d95f02, lam.2 #1b9e77; the tool line (26, 51, 140).
    const int ply1 = count_colour(img, 0xd9, 0x5f, 0x02), ply2 = count_colour(img, 0x1b, 0x9e, 0x77);
    const int tool = count_colour(img, 26, 51, 140);
    std::printf("section at %g deg: %d, %d pixels of the plies, %d of the punch\n", angle, ply1, ply2, tool);
    EXPECT_GT(ply1, 2000) << "angle " << angle;  // the plies fill a band across the picture
    EXPECT_GT(ply2, 2000) << "angle " << angle;
    EXPECT_GT(tool, 100) << "angle " << angle;
  }
}

}  // namespace
}  // namespace sf::forming

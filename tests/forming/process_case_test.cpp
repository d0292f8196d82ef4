// Quick versions of the forming-process cases of data/forming/processes/ (coarse, few
// steps; the full cases and what they show are in that folder's README), asserting
// physics rather than numbers:
//  * matched-die bend (2-D plane strain, molten fibre plies, punch, die and holder): the
//    punch force is positive and grows with its stroke, the die carries it (its reaction
//    points down), the laminate sinks into the slot, and no contact point - ply on ply,
//    ply on tool - penetrates beyond the penalty's own tolerance (so the plies stay in
//    their order); the tool forces balance (nothing else holds the laminate vertically).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <string>

#include "common/io/vtk_xml.hpp"
#include "common/render/scene.hpp"
#include "forming/case/reader.hpp"
#include "forming/plot/plots.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

// Largest penetration accepted, mm: p / S_n at the highest contact pressure of the
// quick bend (~0.3 MPa over S_n = 50 N/mm^3 = 0.006 mm), with a margin.
constexpr double kPenetrationTol = 0.02;
// Vertical balance of the tool forces, relative to the die's: the residual tolerance
// (1e-6 of the force scale) with a margin.
constexpr double kBalanceRel = 1e-3;
// Newton iterations of the quick bend's three steps, cut-backs included (deterministic):
// 54 measured with the damped predictor and the viscous taper, 99 (1 cut-back) before
// both, 364 (9 cut-backs) with the taper alone.
constexpr int kQuickBendIterations = 90;

const char* kQuickBend = R"(units: "mm, N, MPa, s"
materials:
  gfpp_melt: {transversely_isotropic: {E_f: 25000, E_T: 1, G_L: 0.5, G_T: 0.4}}
laminates:
  - name: lam
    size: [24, 5]
    elements: [8, 1]
    layup: "[0_2]"
    ply_thickness: 0.5
    material: gfpp_melt
    plane_strain: true
    interface: {stiffness: 50, viscous: 0.02, band: 0.005}
tools:
  - name: die
    die: {centre: [0, 0, 0], normal: [0, 0, 1], slot_half_width: 8, along: [0, 1, 0], edge_radius: 3}
    motion: {fixed: true}
  - name: holder
    die: {centre: [0, 0, 1], normal: [0, 0, -1], slot_half_width: 8, along: [0, 1, 0], edge_radius: 3}
    motion: {fixed: true}
  - name: punch
    cylinder: {point: [0, 0, 7.0], axis: [0, 1, 0], radius: 6}
    motion: {displacement: [0, 0, -1.5], ramp: linear}
contact:
  - {ply: lam.1, face: bottom, tool: die, stiffness: 50, band: 0.005}
  - {ply: lam.2, face: top, tool: punch, stiffness: 50, band: 0.005}
  - {ply: lam.2, face: top, tool: holder, stiffness: 50, band: 0.005}
boundary_conditions:
  - symmetry: {ply: lam.1, plane: x0}
  - symmetry: {ply: lam.2, plane: x0}
solver: {steps: 3, process_time: 0.2, max_iterations: 40, tolerance: 1.0e-6}
)";

double cell(const io::CsvTable& h, std::size_t row, const char* name) {
  return std::stod(std::string(h.cell(row, h.column_index(name))));
}

TEST(ProcessCase, QuickMatchedDieBendPressesTheLaminateIntoTheDie) {
  const CaseCheck c = check_case_text(kQuickBend, "quick_bend.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_process_quick_bend";
  const fixtures::RunOutput out = fixtures::run_into(c.spec, dir);
  ASSERT_TRUE(out.report.ok()) << out.report.message;
  std::printf("[ measured ] Newton iterations: %d\n", out.report.total_iterations);
  EXPECT_LE(out.report.total_iterations, kQuickBendIterations);
  const io::CsvTable& h = out.history;
  ASSERT_EQ(h.n_rows(), 4u);
  double last = 0.0;
  for (std::size_t row = 1; row < h.n_rows(); ++row) {
    const double f = cell(h, row, "punch_fz");
    std::printf("[ measured ] step %zu: punch_uz %.3f mm, punch_fz %.4f N, die_fz %.4f N, holder_fz %.4f N\n", row,
                cell(h, row, "punch_uz"), f, cell(h, row, "die_fz"), cell(h, row, "holder_fz"));
    EXPECT_GT(f, last) << "step " << row;  // positive and growing with the stroke
    last = f;
    EXPECT_LT(cell(h, row, "die_fz"), 0.0) << "step " << row;  // the die is pushed down
    // Nothing else holds the laminate vertically (the symmetry plane holds x): the three
    // tools' vertical forces balance, to the Newton tolerance.
    const double sum = f + cell(h, row, "die_fz") + cell(h, row, "holder_fz");
    EXPECT_NEAR(sum, 0.0, kBalanceRel * std::abs(cell(h, row, "die_fz"))) << "step " << row;
  }
  EXPECT_LT(out.report.max_displacement.z(), -1.0);
  const io::VolumeMesh contact = io::read_vtu((dir / "steps/contact_0003.vtu").string());
  double min_gap = 1e30;
  for (const io::FieldArray& f : contact.point_data)
    if (f.name == "gap")
      for (double g : f.values)
        if (std::isfinite(g)) min_gap = std::min(min_gap, g);
  std::printf("[ measured ] largest penetration: %.3e mm\n", -min_gap);
  EXPECT_GT(min_gap, -kPenetrationTol);
  // The section picture is framed on the plies: the die wall and the holder reach far
  // beyond the laminate, and framed on them the plies were a sliver of the picture.
  PlotOptions po;
  po.frames = 0;
  po.animation = false;
  po.quiet = true;
  po.size = {800, 600};
  plot_results(dir.string(), po);
  const render::RgbImage img = render::read_png_rgb((dir / "plots" / "section.png").string());
  int ply_pixels = 0;  // lam.1 #d95f02 and lam.2 #1b9e77 of plots.cpp's palette, within 24 of 255
  for (std::size_t p = 0; p + 2 < img.pixels.size(); p += 3)
    for (const std::array<int, 3> rgb : {std::array<int, 3>{0xd9, 0x5f, 0x02}, std::array<int, 3>{0x1b, 0x9e, 0x77}})
      if (std::abs(img.pixels[p] - rgb[0]) < 24 && std::abs(img.pixels[p + 1] - rgb[1]) < 24 &&
          std::abs(img.pixels[p + 2] - rgb[2]) < 24)
        ++ply_pixels;
  std::printf("[ measured ] section.png: %d pixels of the plies of %zu\n", ply_pixels, img.pixels.size() / 3);
  EXPECT_GT(ply_pixels, 5000);  // 7401 framed on the plies, 2547 framed on the tools
  std::filesystem::remove_all(dir);
}

// Every process case of data/forming/processes/ passes `simform check` (the README's
// commands start from these files; the isotropic dome's gravity needs each material's
// density, which check demands).
TEST(ProcessCase, CaseFilesCheckClean) {
  int n = 0;
  const std::filesystem::path dir = std::filesystem::path(SF_SOURCE_DIR) / "data/forming/processes";
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    const CaseCheck c = check_case_file(entry.path().string());
    EXPECT_TRUE(c.ok()) << entry.path().filename() << ": " << (c.ok() ? "" : c.located(0));
    ++n;
  }
  EXPECT_GE(n, 9);
}

}  // namespace
}  // namespace sf::forming

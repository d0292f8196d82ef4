// Reading real exports of measuring systems (data/real/README.md: where each file comes
// from, its licence and how it was trimmed), as the systems wrote them: the neutral
// "nodemap" export of a ZEISS/GOM ARAMIS project in two versions of its exporter, and a
// DICe 2-D result on images of the DIC Challenge. Each test fails on the reader as it was
// before these files were tried: the nodemap's failed facets (0, 0, 0 with nan
// displacements) were read as measured undeformed points at the origin, and the older
// header "#ID,ID; x_undef [mm]; ..." was not read at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/io/grid_file.hpp"

namespace sf::io {
namespace {

std::string real_dir() { return std::string(SF_SOURCE_DIR) + "/data/real/"; }

Index index_of(const GridData& g, const std::string& id) {
  const auto it = std::find(g.ids.begin(), g.ids.end(), id);
  EXPECT_NE(it, g.ids.end()) << "no point '" << id << "'";
  return it == g.ids.end() ? 0 : static_cast<Index>(it - g.ids.begin());
}

bool any_note(const GridData& g, const std::string& text) {
  return std::any_of(g.notes.begin(), g.notes.end(),
                     [&](const std::string& n) { return n.find(text) != std::string::npos; });
}

// The nodemap of stage 52 of a fatigue-crack test (ARAMIS 12M), 168 facets ahead of and
// along the crack: a 50-line commented preamble with one latin-1 byte, a commented
// header with padded names, ';' with padded fields, undeformed positions with
// displacements. Facets 24015 and 24210 (at the specimen's centre notch) are written as
// 0, 0, 0 with nan displacements: not measured, and not an undeformed point at the origin.
TEST(IoRealExports, AramisNodemapWithFailedFacets) {
  const std::string path = real_dir() + "aramis_mt_crack/nodemap_stage52_crack_tip.txt";
  GridReadOptions o;
  o.format = MeasurementFormat::kAuto;
  const GridData g = read_grid_file(path, o);
  ASSERT_EQ(g.n_points(), 168);
  EXPECT_TRUE(any_note(g, "format found from the header: gom")) << g.notes.front();
  EXPECT_EQ(g.units, "mm");
  Index measured = 0;
  for (Index p = 0; p < g.n_points(); ++p) measured += g.has_undeformed(p) && g.has_deformed(p) ? 1 : 0;
  EXPECT_EQ(measured, 166);
  for (const char* id : {"24015", "24210"}) {
    const Index p = index_of(g, id);
    EXPECT_FALSE(g.has_undeformed(p)) << id << " read as an undeformed point at " << g.undeformed.row(p);
    EXPECT_FALSE(g.has_deformed(p)) << id;
    EXPECT_TRUE(g.not_measured_undeformed(p) && g.not_measured_deformed(p)) << id;
  }
  // First row: x = x_undef + u.
  const Index p = index_of(g, "23407");
  EXPECT_NEAR(g.undeformed(p, 0), -22.4248679691, 1e-10);
  EXPECT_NEAR(g.undeformed(p, 1), 2.3718538660, 1e-10);
  EXPECT_NEAR(g.deformed(p, 0), -22.4248679691 + 0.005399127956480, 1e-10);
  EXPECT_NEAR(g.deformed(p, 1), 2.3718538660 + 0.001288664177991, 1e-10);
  EXPECT_NEAR(g.deformed(p, 2), 0.0095133910 + 0.009348796680570, 1e-10);
}

// The older exporter (stage 407 of another test, 2019): "#ID,ID; x_undef [mm]; ..." as
// the header, '; ' between fields, ids from 0. The first 43 rows.
TEST(IoRealExports, AramisNodemapOfTheOlderExporter) {
  const std::string path = real_dir() + "aramis_mt_crack/alldatapoints_stage407_first43.txt";
  GridReadOptions o;
  o.format = MeasurementFormat::kAuto;
  const GridData g = read_grid_file(path, o);
  ASSERT_EQ(g.n_points(), 43);
  EXPECT_TRUE(any_note(g, "key ID,ID")) << g.notes.front();
  EXPECT_EQ(g.ids.front(), "0");
  EXPECT_EQ(g.ids.back(), "42");
  const Index p = index_of(g, "41");
  EXPECT_NEAR(g.undeformed(p, 0), 80.3937732704, 1e-10);
  EXPECT_NEAR(g.deformed(p, 1), 72.4788873563 + 0.3277158141, 1e-10);
}

// DICe on image 11 of the DIC Challenge's open-hole CFRP set: a 20-line "***" preamble,
// COORDINATE_X/Y and DISPLACEMENT_X/Y in pixels (2-D), no SUBSET_ID (the key is the
// subset centre), MATCH 0 everywhere, and no subsets inside the hole.
TEST(IoRealExports, DiceTwoDimensionalSolutionWithoutSubsetIds) {
  const std::string path = real_dir() + "dice_oht_cfrp/DICe_solution_11.txt";
  GridReadOptions o;
  o.format = MeasurementFormat::kAuto;
  o.units = "px";
  const GridData g = read_grid_file(path, o);
  ASSERT_EQ(g.n_points(), 230);
  EXPECT_TRUE(any_note(g, "format found from the header: dice")) << g.notes.front();
  EXPECT_TRUE(any_note(g, "planar"));
  for (Index p = 0; p < g.n_points(); ++p) {
    EXPECT_TRUE(g.has_undeformed(p) && g.has_deformed(p)) << g.ids[p];
    EXPECT_EQ(g.undeformed(p, 2), 0.0);
  }
  const Index p = index_of(g, "2.7100E+02_5.5100E+02");
  EXPECT_EQ(g.undeformed(p, 0), 271.0);
  EXPECT_EQ(g.undeformed(p, 1), 551.0);
  EXPECT_NEAR(g.deformed(p, 0), 271.0 - 1.2823, 1e-12);
  EXPECT_NEAR(g.deformed(p, 1), 551.0 - 8.1989, 1e-12);
  // A subset in the hole is absent.
  EXPECT_EQ(std::count(g.ids.begin(), g.ids.end(), "1.6600E+02_5.5100E+02"), 0);
  // In millimetres it needs the pixel size.
  GridReadOptions mm = o;
  mm.units = "mm";
  mm.pixel_size = 0.05;
  const GridData g_mm = read_grid_file(path, mm);
  EXPECT_NEAR(g_mm.undeformed(p, 0), 271.0 * 0.05, 1e-12);
}

}  // namespace
}  // namespace sf::io

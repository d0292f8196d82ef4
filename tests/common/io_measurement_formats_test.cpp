// Reading measuring-system exports (common/io/measurement_formats.hpp through
// read_grid_file): each preset reads its example file in data/formats/ (made-up
// numbers from one analytic deformation, tests/common/example_deformation.hpp) with its
// ids, positions, invalid points, units and uncertainties; and the general reading
// options (units in brackets, composite ids, current positions with displacements,
// positions from grid indices) with the messages of bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/core/error.hpp"
#include "common/io/grid_file.hpp"
#include "tests/common/example_deformation.hpp"
#include "tests/common/io_test_util.hpp"

namespace sf::io {
namespace {

using sf::test::example_current;
using sf::test::example_reference;
using sf::test::formats_dir;
using test::message_of;
using test::ScratchDir;
using test::write_text;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;

// Positions written with 6 decimals (mm): reading and X = x - u stay within this.
constexpr double kSixDecimals = 2e-6;
// MatchID's 6 significant digits on values up to 20 mm.
constexpr double kSixDigits = 1e-4;

Vec3 row(const Points3& m, Index p) { return m.row(p).transpose(); }
Index index_of(const GridData& g, const std::string& id) {
  const auto it = std::find(g.ids.begin(), g.ids.end(), id);
  EXPECT_NE(it, g.ids.end()) << "no point '" << id << "'";
  return it == g.ids.end() ? 0 : static_cast<Index>(it - g.ids.begin());
}

GridReadOptions preset(MeasurementFormat f) {
  GridReadOptions o;
  o.format = f;
  return o;
}

bool any_note(const GridData& g, const std::string& text) {
  return std::any_of(g.notes.begin(), g.notes.end(),
                     [&](const std::string& n) { return n.find(text) != std::string::npos; });
}

TEST(IoFormats, PresetNames) {
  EXPECT_EQ(format_by_name("gom"), MeasurementFormat::kGom);
  EXPECT_EQ(format_by_name("ARAMIS"), MeasurementFormat::kGom);
  EXPECT_EQ(format_by_name("MatchID"), MeasurementFormat::kMatchId);
  EXPECT_EQ(format_by_name("vic3d"), MeasurementFormat::kVic3d);
  EXPECT_EQ(format_by_name("dice"), MeasurementFormat::kDice);
  EXPECT_EQ(format_by_name("plain"), MeasurementFormat::kPlain);
  EXPECT_FALSE(format_by_name("ncorr").has_value());
  EXPECT_EQ(format_by_name("Auto"), MeasurementFormat::kAuto);
  EXPECT_EQ(format_names(), "auto, plain, gom, matchid, vic3d, dice");
}

// GOM: a comment and a second table before the header, ';', current positions with
// displacements (X = x - u), units in brackets, a comma inside a unit. Points 9 and 33
// are left out (absent), 17 and 41 have empty cells (not measured in either state).
TEST(IoFormats, GomStageExport) {
  const std::string path = formats_dir() + "gom_stage.csv";
  const GridData g = read_grid_file(path, preset(MeasurementFormat::kGom));
  ASSERT_EQ(g.n_points(), 47);
  EXPECT_EQ(std::count(g.ids.begin(), g.ids.end(), "9"), 0);
  EXPECT_EQ(std::count(g.ids.begin(), g.ids.end(), "33"), 0);
  for (Index p = 0; p < g.n_points(); ++p) {
    const int pid = std::stoi(g.ids[p]) - 1;
    const Vec3 X = example_reference(pid / 7, pid % 7);
    if (pid + 1 == 17 || pid + 1 == 41) {
      EXPECT_FALSE(g.has_undeformed(p) || g.has_deformed(p)) << g.ids[p];
      EXPECT_TRUE(g.not_measured_undeformed(p) && g.not_measured_deformed(p)) << g.ids[p];
      continue;
    }
    EXPECT_LT((row(g.undeformed, p) - X).norm(), kSixDecimals) << g.ids[p];
    EXPECT_LT((row(g.deformed, p) - example_current(X)).norm(), kSixDecimals) << g.ids[p];
    EXPECT_FALSE(g.not_measured_undeformed(p) || g.not_measured_deformed(p)) << g.ids[p];
  }
  EXPECT_EQ(g.where[0], path + ":7");  // the header is line 6
  EXPECT_TRUE(g.sigma_undeformed.empty() && g.sigma_deformed.empty());
  EXPECT_THAT(g.not_measured_rule, HasSubstr("empty or nan"));
  EXPECT_TRUE(any_note(g, "displacement_x, displacement_y, displacement_z = displacements")) << g.notes.front();
}

// The layout of a real GOM Correlate surface-component export (data/real/README.md):
// "# Units: length:mm angle:deg time:s", the stage as a comment and a one-row table
// "stage;index;relative_time;date" with quoted cells, "# Name : Flächenkomponente 1",
// names without units, ids from 0, 4 decimals. Points 8 and 32 are left out.
TEST(IoFormats, GomCorrelateStageExportAsWritten) {
  const std::string path = formats_dir() + "gom_correlate_stage.csv";
  GridReadOptions o;
  o.format = MeasurementFormat::kAuto;
  const GridData g = read_grid_file(path, o);
  ASSERT_EQ(g.n_points(), 47);
  EXPECT_TRUE(any_note(g, "format found from the header: gom")) << g.notes.front();
  EXPECT_EQ(std::count(g.ids.begin(), g.ids.end(), "8"), 0);
  EXPECT_EQ(std::count(g.ids.begin(), g.ids.end(), "32"), 0);
  constexpr double kFourDecimals = 2e-4;  // x and u rounded apart: X = x - u within 1e-4
  for (Index p = 0; p < g.n_points(); ++p) {
    const int pid = std::stoi(g.ids[p]);
    const Vec3 X = example_reference(pid / 7, pid % 7);
    EXPECT_LT((row(g.undeformed, p) - X).norm(), kFourDecimals) << g.ids[p];
    EXPECT_LT((row(g.deformed, p) - example_current(X)).norm(), kFourDecimals) << g.ids[p];
  }
  EXPECT_EQ(g.where[0], path + ":7");  // the header is line 6
}

// The length unit of GOM's units line converts the unit-less columns; its other
// entries (angle, time) say nothing about lengths. Without a length entry the line is
// not a unit at all.
TEST(IoFormats, GomUnitsLineGivesTheLengthUnit) {
  ScratchDir dir;
  const std::string head =
      "# Stage: Stufe 1\n"
      "stage;index;relative_time;date\n"
      "\"Stufe 1\";1;0.0000;\"2023-02-10T13:53:56.849\"\n"
      "# Name : Surface component 1\n"
      "id;x;y;z;displacement_x;displacement_y;displacement_z;epsilon_x\n"
      "0;1.5000;2.0000;0.0000;0.5000;0.0000;0.0000;0.0000\n"
      "1;2.5000;2.0000;0.0000;0.5000;0.0000;0.0000;0.0000\n";
  const std::string cm = dir.file("cm.csv");
  write_text(cm, "# Units: length:cm angle:deg time:s \n" + head);
  const GridData g = read_grid_file(cm, preset(MeasurementFormat::kGom));
  EXPECT_NEAR(g.undeformed(0, 0), 10.0, 1e-12);  // (1.5 - 0.5) cm
  EXPECT_NEAR(g.deformed(1, 0), 25.0, 1e-12);
  EXPECT_TRUE(any_note(g, "converted to mm")) << g.notes.back();
  const std::string no_length = dir.file("angles.csv");
  write_text(no_length, "# Units: angle:deg time:s\n" + head);
  EXPECT_NEAR(read_grid_file(no_length, preset(MeasurementFormat::kGom)).undeformed(0, 0), 1.0, 1e-12);
  const std::string degrees = dir.file("deg.csv");
  write_text(degrees, "# Units: length:deg\n" + head);
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(degrees, preset(MeasurementFormat::kGom)); }),
              HasSubstr("is in 'deg', which is not a length unit"));
}

// MatchID 2024.1: the key is the subset's image position, coor.* reference positions,
// 3-digit exponents, stats.Sigma in mm. Point 25 (image 875, 825) has nan displacements.
TEST(IoFormats, MatchIdImageExport) {
  const GridData g = read_grid_file(formats_dir() + "matchid_image.csv", preset(MeasurementFormat::kMatchId));
  ASSERT_EQ(g.n_points(), 47);
  ASSERT_EQ(g.sigma_deformed.size(), 47u);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) {
      const int pid = i * 7 + j + 1;
      if (pid == 2 || pid == 48) continue;
      const Index p = index_of(g, std::to_string(800 + 25 * j) + "_" + std::to_string(900 - 25 * i));
      const Vec3 X = example_reference(i, j);
      EXPECT_LT((row(g.undeformed, p) - X).norm(), kSixDigits) << pid;
      EXPECT_NEAR(g.sigma_deformed[p], 0.0010 + 0.0001 * (pid % 5), 1e-12) << pid;
      EXPECT_EQ(g.sigma_undeformed[p], g.sigma_deformed[p]);
      if (pid == 25) {
        EXPECT_FALSE(g.has_deformed(p));
        EXPECT_TRUE(g.not_measured_deformed(p));
        EXPECT_FALSE(g.not_measured_undeformed(p));
      } else {
        EXPECT_LT((row(g.deformed, p) - example_current(X)).norm(), kSixDigits) << pid;
      }
    }
  // The other reading of coor.*: current positions, so X = coor - disp.
  GridReadOptions current = preset(MeasurementFormat::kMatchId);
  current.positions = Positions::kCurrent;
  const GridData c = read_grid_file(formats_dir() + "matchid_image.csv", current);
  const Index p = index_of(c, "800_900");
  EXPECT_LT((row(c.deformed, p) - example_reference(0, 0)).norm(), kSixDigits);
  EXPECT_LT((row(c.undeformed, p) - (2 * example_reference(0, 0) - example_current(example_reference(0, 0)))).norm(),
            kSixDigits);
}

// VIC-3D: quoted, padded names; failed points are rows of zeros with sigma = -1; sigma
// is in pixels, used only with a pixel size.
TEST(IoFormats, Vic3dFrameExport) {
  const std::string path = formats_dir() + "vic3d_frame.csv";
  const GridData g = read_grid_file(path, preset(MeasurementFormat::kVic3d));
  ASSERT_EQ(g.n_points(), 49);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) {
      const int pid = i * 7 + j + 1;
      const Index p = index_of(g, std::to_string(300 + 21 * j) + "_" + std::to_string(420 + 21 * i));
      if (pid == 5 || pid == 23 || pid == 44) {
        EXPECT_FALSE(g.has_undeformed(p) || g.has_deformed(p)) << pid;  // the zeros are not read as data
        EXPECT_TRUE(g.not_measured_undeformed(p) && g.not_measured_deformed(p)) << pid;
        continue;
      }
      const Vec3 X = example_reference(i, j);
      EXPECT_LT((row(g.undeformed, p) - X).norm(), kSixDecimals) << pid;
      EXPECT_LT((row(g.deformed, p) - example_current(X)).norm(), kSixDecimals) << pid;
    }
  EXPECT_EQ(std::count(g.not_measured.begin(), g.not_measured.end(), kNotMeasuredUndeformed | kNotMeasuredDeformed), 3);
  EXPECT_TRUE(g.sigma_deformed.empty());
  EXPECT_TRUE(any_note(g, "'sigma' (uncertainty) is in image pixels and no pixel size was given"));

  GridReadOptions scaled = preset(MeasurementFormat::kVic3d);
  scaled.pixel_size = 0.02;  // mm per pixel
  const GridData s = read_grid_file(path, scaled);
  ASSERT_EQ(s.sigma_deformed.size(), 49u);
  EXPECT_NEAR(s.sigma_deformed[index_of(s, "300_420")], 0.02 * 0.005, 1e-15);  // point 1
  EXPECT_TRUE(std::isnan(s.sigma_deformed[index_of(s, "384_420")]));           // point 5: sigma = -1
  EXPECT_EQ(row(s.undeformed, 1), row(g.undeformed, 1));                       // positions are in mm already
}

TEST(IoFormats, Vic3dWithoutSigmaTakesARowOfZerosForAFailedPoint) {
  ScratchDir dir;
  const std::string path = dir.file("vic.csv");
  write_text(path,
             " \"X\", \"Y\", \"Z\", \"U\", \"V\", \"W\", \"x\", \"y\"\n1,2,3,0.1,0.2,0.3,10,20\n0,0,0,0,0,0,17,20\n");
  const GridData g = read_grid_file(path, preset(MeasurementFormat::kVic3d));
  ASSERT_EQ(g.n_points(), 2);
  EXPECT_TRUE(g.has_deformed(0));
  EXPECT_FALSE(g.has_undeformed(1) || g.has_deformed(1));
  EXPECT_TRUE(g.not_measured_deformed(1));
}

// DICe: a *** preamble; failed subsets (MATCH = -1) keep their reference position but
// their stale displacements are not read.
TEST(IoFormats, DiceSolutionFile) {
  const std::string path = formats_dir() + "dice_solution_10.txt";
  GridReadOptions o = preset(MeasurementFormat::kDice);
  o.pixel_size = 0.05;
  const GridData g = read_grid_file(path, o);
  ASSERT_EQ(g.n_points(), 49);
  for (Index p = 0; p < 49; ++p) {
    EXPECT_EQ(g.ids[p], std::to_string(p));
    const Vec3 X = example_reference(static_cast<int>(p) / 7, static_cast<int>(p) % 7);
    EXPECT_LT((row(g.undeformed, p) - X).norm(), 1e-5) << p;
    if (p == 6 || p == 30 || p == 40) {
      EXPECT_FALSE(g.has_deformed(p)) << p;
      EXPECT_TRUE(g.not_measured_deformed(p) && !g.not_measured_undeformed(p)) << p;
      EXPECT_TRUE(std::isnan(g.sigma_deformed[p]));
    } else {
      EXPECT_LT((row(g.deformed, p) - example_current(X)).norm(), 1e-5) << p;
      EXPECT_NEAR(g.sigma_deformed[p], 0.05 * (0.003 + 0.0005 * (p % 4)), 1e-15) << p;
    }
  }
  EXPECT_EQ(g.where[0], path + ":11");
  EXPECT_THAT(g.not_measured_rule, HasSubstr("MATCH"));
}

// DICe 2-D: coordinates and displacements in image pixels, blank-separated columns,
// no MATCH column (SIGMA = -1 marks the failure), no z.
TEST(IoFormats, Dice2dInPixelsNeedsAPixelSize) {
  ScratchDir dir;
  const std::string path = dir.file("DICe_solution_3.txt");
  write_text(path,
             "*** DICe-style 2-D output, made up\n***\n"
             "SUBSET_ID COORDINATE_X COORDINATE_Y DISPLACEMENT_X DISPLACEMENT_Y SIGMA\n"
             "0 100 200 1.5 -0.5 2.0E-03\n"
             "1 120 200 1.6 -0.5 -1\n");
  const std::string message = message_of<InputError>([&] { read_grid_file(path, preset(MeasurementFormat::kDice)); });
  EXPECT_THAT(message, AllOf(HasSubstr(path + ":3:2:"), HasSubstr("'COORDINATE_X' is in image pixels"),
                             HasSubstr("--pixel-size")));
  GridReadOptions o = preset(MeasurementFormat::kDice);
  o.pixel_size = 0.1;
  const GridData g = read_grid_file(path, o);
  ASSERT_EQ(g.n_points(), 2);
  EXPECT_LT((row(g.undeformed, 0) - Vec3(10, 20, 0)).norm(), 1e-12);
  EXPECT_LT((row(g.deformed, 0) - Vec3(10.15, 19.95, 0)).norm(), 1e-12);
  EXPECT_TRUE(g.has_undeformed(1));
  EXPECT_FALSE(g.has_deformed(1));
  EXPECT_TRUE(any_note(g, "planar"));
  // Read in pixels, nothing is converted.
  GridReadOptions px = preset(MeasurementFormat::kDice);
  px.units = "px";
  EXPECT_LT((row(read_grid_file(path, px).deformed, 0) - Vec3(101.5, 199.5, 0)).norm(), 1e-12);
}

// The --columns example of docs/usage.md on a file without an id column, in metres.
TEST(IoFormats, PlainTableWithoutIdInMetres) {
  GridReadOptions o;
  o.columns = {{"X", "X0"}, {"Y", "Y0"}, {"Z", "Z0"}, {"u", "ux"}, {"v", "uy"}, {"w", "uz"}};
  const GridData g = read_grid_file(formats_dir() + "plain_no_id_metres.csv", o);
  ASSERT_EQ(g.n_points(), 49);
  EXPECT_EQ(g.ids.front(), "1");
  EXPECT_EQ(g.ids.back(), "49");
  for (Index p = 0; p < 49; ++p) {
    const Vec3 X = example_reference(static_cast<int>(p) / 7, static_cast<int>(p) % 7);
    EXPECT_LT((row(g.undeformed, p) - X).norm(), kSixDecimals) << p;  // metres read in mm
    EXPECT_LT((row(g.deformed, p) - example_current(X)).norm(), kSixDecimals) << p;
  }
  EXPECT_TRUE(any_note(g, "converted to mm: X0 [m]"));
  EXPECT_TRUE(any_note(g, "numbered by row"));
  o.units = "in";
  const GridData in = read_grid_file(formats_dir() + "plain_no_id_metres.csv", o);
  EXPECT_NEAR(in.undeformed(0, 0), -15.0 / 25.4, 1e-12);
  EXPECT_EQ(in.units, "in");
}

TEST(IoFormats, UnitsInBracketsAndInAUnitsComment) {
  ScratchDir dir;
  const std::string path = dir.file("g.csv");
  write_text(path, "id,X [\xC2\xB5m],Y [\xCE\xBCm],Z [um],x [cm],y [in],z [mm]\np,1000,2000,3000,1,1,1\n");
  const GridData g = read_grid_file(path);
  EXPECT_LT((row(g.undeformed, 0) - Vec3(1, 2, 3)).norm(), 1e-12);
  EXPECT_LT((row(g.deformed, 0) - Vec3(10, 25.4, 1)).norm(), 1e-12);
  // "# units: m" before the header (as the grid writer puts it) applies to unmarked columns.
  write_text(path, "# units: m\nid,X,Y,Z,x,y,z [mm]\np,1,2,3,0.001,0.002,3\n");
  const GridData m = read_grid_file(path);
  EXPECT_LT((row(m.undeformed, 0) - Vec3(1000, 2000, 3000)).norm(), 1e-9);
  EXPECT_LT((row(m.deformed, 0) - Vec3(1, 2, 3)).norm(), 1e-12);
}

TEST(IoFormats, UnitThatCannotBeConvertedNamesTheColumn) {
  ScratchDir dir;
  const std::string path = dir.file("g.csv");
  write_text(path, "id,X,Y,Z,x [deg],y,z\np,1,2,3,1,1,1\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path); }),
              AllOf(HasSubstr(path + ":1:5:"), HasSubstr("column 'x [deg]' is in 'deg'"), HasSubstr("not a length")));
  write_text(path, "id,X,Y,Z,x [ ],y,z\np,1,2,3,1,1,1\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path); }), HasSubstr("'x [ ]' is dimensionless"));
  // A length the unit to read in cannot take.
  write_text(path, "id,X [m],Y,Z,x,y,z\np,1,2,3,1,1,1\n");
  GridReadOptions o;
  o.units = "furlong";
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, o); }),
              AllOf(HasSubstr(path + ":1:2:"), HasSubstr("'X [m]'"), HasSubstr("'furlong' (--units)")));
  // Without units in the file, any name only labels the numbers.
  write_text(path, "id,X,Y,Z,x,y,z\np,1,2,3,1,1,1\n");
  EXPECT_EQ(read_grid_file(path, o).undeformed(0, 0), 1.0);
}

TEST(IoFormats, CompositeIdAndItsDuplicates) {
  ScratchDir dir;
  const std::string path = dir.file("m.csv");
  write_text(path, "x_pic,y_pic,X,Y,Z,x,y,z\n10,20,0,0,0,0,0,0\n10,30,1,0,0,1,0,0\n20,10,2,0,0,2,0,0\n");
  GridReadOptions o;
  o.id_columns = {"x_pic", "y_pic"};
  const GridData g = read_grid_file(path, o);
  EXPECT_EQ(g.ids, (std::vector<std::string>{"10_20", "10_30", "20_10"}));
  write_text(path, "x_pic,y_pic,X,Y,Z,x,y,z\n10,20,0,0,0,0,0,0\n10,30,1,0,0,1,0,0\n10,20,2,0,0,2,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, o); }),
              AllOf(HasSubstr(path + ":4:1:"), HasSubstr("duplicate id '10_20' (from columns x_pic, y_pic)"),
                    HasSubstr("first at line 2")));
  o.id_columns = {"x_pic", "frame"};
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, o); }),
              AllOf(HasSubstr(path + ":1:"), HasSubstr("missing required column 'frame'")));
}

TEST(IoFormats, CurrentPositionsWithDisplacements) {
  ScratchDir dir;
  const std::string path = dir.file("c.csv");
  write_text(path, "id,xc,yc,zc,du,dv,dw\na,11,22,33,1,2,3\n");
  GridReadOptions o;
  o.columns = {{"x", "xc"}, {"y", "yc"}, {"z", "zc"}, {"u", "du"}, {"v", "dv"}, {"w", "dw"}};
  const GridData g = read_grid_file(path, o);
  EXPECT_LT((row(g.undeformed, 0) - Vec3(10, 20, 30)).norm(), 1e-12);  // X = x - u
  EXPECT_LT((row(g.deformed, 0) - Vec3(11, 22, 33)).norm(), 1e-12);
  o.columns["X"] = "xc";  // all three triples: over-determined
  EXPECT_THAT(message_of<UsageError>([&] { read_grid_file(path, o); }), HasSubstr("map two of them"));
}

TEST(IoFormats, NominalPositionsFromGridIndicesAndPitch) {
  GridReadOptions o;
  o.pitch = 5.0;
  const GridData g = read_grid_file(formats_dir() + "grid_indices.csv", o);
  ASSERT_EQ(g.n_points(), 49);
  ASSERT_TRUE(g.has_ij);
  for (Index p = 0; p < 49; ++p) {
    const int i = static_cast<int>(g.i[p]), j = static_cast<int>(g.j[p]);
    EXPECT_EQ(row(g.undeformed, p), Vec3(5.0 * j, 5.0 * i, 0.0));  // j along X, i along Y
    EXPECT_LT((row(g.deformed, p) - example_current(example_reference(i, j))).norm(), kSixDecimals);
  }
  // Without i, j the pitch cannot place the marks.
  ScratchDir dir;
  write_text(dir.file("n.csv"), "id,x,y,z\np,1,2,3\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(dir.file("n.csv"), o); }),
              AllOf(HasSubstr("missing required column 'i'"), HasSubstr("pitch")));
}

TEST(IoFormats, MissingColumnOfAPresetSaysWhatItReads) {
  ScratchDir dir;
  const std::string path = dir.file("vic.csv");
  write_text(path, "\"X\",\"Y\",\"Z\",\"U\",\"V\",\"x\",\"y\",\"sigma\"\n1,2,3,4,5,6,7,0.01\n");
  EXPECT_THAT(
      message_of<InputError>([&] { read_grid_file(path, preset(MeasurementFormat::kVic3d)); }),
      AllOf(HasSubstr(path + ":1: missing required column 'W'"), HasSubstr("--format vic3d reads X, Y, Z, U, V, W"),
            HasSubstr("found: X, Y, Z, U, V, x, y, sigma")));
}

// The neutral "nodemap" layout of the ARAMIS exporter: a commented header with ID and
// undeformed positions x_undef.. plus u, v, w; ';' and padded fields.
TEST(IoFormats, GomCommentedHeaderWithUndeformedPositions) {
  ScratchDir dir;
  const std::string path = dir.file("nodemap.txt");
  write_text(path,
             "# made-up nodemap-style file\n"
             "#        ID;   x_undef [mm];   y_undef [mm];   z_undef [mm];   u [mm];   v [mm];   w [mm]\n"
             "         1;   -8.0;   8.5;   0.1;   0.25;   0.5;   -0.125\n"
             "         2;   -7.0;   8.5;   0.1;   0.25;   0.5;   -0.125\n");
  const GridData g = read_grid_file(path, preset(MeasurementFormat::kGom));
  ASSERT_EQ(g.n_points(), 2);
  EXPECT_EQ(g.ids[0], "1");
  EXPECT_LT((row(g.deformed, 0) - Vec3(-7.75, 9.0, -0.025)).norm(), 1e-12);
}

TEST(IoFormats, DecimalCommaHeaderLineAndSkipLines) {
  ScratchDir dir;
  const std::string path = dir.file("de.csv");
  write_text(path, "Messung 3\nid;x;y;z;displacement_x;displacement_y;displacement_z\np;1,5;2;3;0,5;0;0\n");
  GridReadOptions o = preset(MeasurementFormat::kGom);
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, o); }), HasSubstr("a decimal comma?"));
  o.decimal = ',';
  EXPECT_LT((row(read_grid_file(path, o).undeformed, 0) - Vec3(1, 2, 3)).norm(), 1e-12);
  o.header_line = 2;
  EXPECT_EQ(read_grid_file(path, o).n_points(), 1);
  o.header_line = 0;
  o.skip_lines = 1;  // the header is searched after the skipped lines
  EXPECT_EQ(read_grid_file(path, o).n_points(), 1);
  o.skip_lines = 2;  // the header is skipped: the data line is taken for it
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, o); }), HasSubstr(path + ":3:"));
}

TEST(IoFormats, BadOptionsNameTheField) {
  GridReadOptions o;
  o.positions = Positions::kCurrent;
  EXPECT_THAT(message_of<UsageError>([&] { o.validate(); }), HasSubstr("positions"));
  o = {};
  o.pitch = -1;
  EXPECT_THAT(message_of<UsageError>([&] { o.validate(); }), HasSubstr("pitch: must be > 0"));
  o = {};
  o.id_from_row = true;
  o.id_columns = {"a"};
  EXPECT_THAT(message_of<UsageError>([&] { o.validate(); }), HasSubstr("id_from_row"));
  o = {};
  o.decimal = ',';
  o.delimiter = ',';
  EXPECT_THAT(message_of<UsageError>([&] { o.validate(); }), HasSubstr("decimal"));
}

}  // namespace
}  // namespace sf::io

namespace sf::io {
namespace {

// --format auto: each example export is recognised by its columns and key, and a note
// says so; the plain grid file stays plain without a note.
TEST(IoFormats, AutoFindsEachPresetFromItsHeader) {
  const std::vector<std::pair<std::string, std::string>> files = {{"gom_stage.csv", "gom"},
                                                                  {"matchid_image.csv", "matchid"},
                                                                  {"vic3d_frame.csv", "vic3d"},
                                                                  {"dice_solution_10.txt", "dice"},
                                                                  {"gom_stage_decimal_comma.csv", "gom"}};
  GridReadOptions o = preset(MeasurementFormat::kAuto);
  o.decimal = kDetectDecimal;
  for (const auto& [file, name] : files) {
    const GridData g = read_grid_file(formats_dir() + file, o);
    EXPECT_TRUE(any_note(g, "format found from the header: " + name + " (")) << file;
    // The same points as with the preset named.
    GridReadOptions named = o;
    named.format = *format_by_name(name);
    const GridData h = read_grid_file(formats_dir() + file, named);
    EXPECT_EQ(g.ids, h.ids) << file;
    EXPECT_EQ(g.not_measured, h.not_measured) << file;
  }
  ScratchDir dir;
  write_text(dir.file("plain.csv"), "id,X,Y,Z,x,y,z\np,0,0,0,1,0,0\n");
  const GridData plain = read_grid_file(dir.file("plain.csv"), o);
  EXPECT_FALSE(any_note(plain, "format found"));
  EXPECT_EQ(plain.n_points(), 1);
}

// Without a preset's key the header does not say which system wrote it: x, y, z, u, v, w
// fits both the plain file (x current) and MatchID 2023 (x reference); auto reads it as
// plain. With MatchID's key x_pic, y_pic it is MatchID.
TEST(IoFormats, AutoNeedsThePresetsKey) {
  ScratchDir dir;
  write_text(dir.file("a.csv"), "x,y,z,u,v,w\n1,2,3,0.5,0,0\n");
  const GridData a = read_grid_file(dir.file("a.csv"), preset(MeasurementFormat::kAuto));
  EXPECT_FALSE(any_note(a, "format found"));
  EXPECT_LT((row(a.undeformed, 0) - Vec3(0.5, 2, 3)).norm(), 1e-12);  // X = x - u
  write_text(dir.file("b.csv"), "x_pic,y_pic,x,y,z,u,v,w\n10,20,1,2,3,0.5,0,0\n");
  const GridData b = read_grid_file(dir.file("b.csv"), preset(MeasurementFormat::kAuto));
  EXPECT_TRUE(any_note(b, "format found from the header: matchid"));
  EXPECT_EQ(b.ids[0], "10_20");
  EXPECT_LT((row(b.undeformed, 0) - Vec3(1, 2, 3)).norm(), 1e-12);  // x is the reference
  // With --columns the user names the columns: plain.
  GridReadOptions o = preset(MeasurementFormat::kAuto);
  o.columns = {{"id", "x_pic"}};
  EXPECT_FALSE(any_note(read_grid_file(dir.file("b.csv"), o), "format found"));
}

TEST(IoFormats, AutoWithAHeaderOfTwoPresetsAsksForOne) {
  ScratchDir dir;
  const std::string path = dir.file("both.csv");
  write_text(path,
             "# two systems' columns\nid,x,y,z,displacement_x,displacement_y,displacement_z,X,Y,Z,U,V,W,sigma\n"
             "1,1,2,3,0,0,0,1,2,3,0,0,0,0.1\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, preset(MeasurementFormat::kAuto)); }),
              AllOf(HasSubstr(path + ":2: the header fits more than one measuring system's format (gom, vic3d)"),
                    HasSubstr("--format")));
  // A plain file that fits no preset keeps plain's message, and says no preset fits.
  write_text(path, "i,j,x,y,z\n0,0,1,2,3\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, preset(MeasurementFormat::kAuto)); }),
              AllOf(HasSubstr(path + ":1: missing required column 'X'"),
                    HasSubstr("nor does the header hold the columns and key of --format gom")));
}

TEST(IoFormats, DecimalSeparatorFoundFromTheData) {
  ScratchDir dir;
  GridReadOptions o = preset(MeasurementFormat::kGom);
  o.decimal = kDetectDecimal;
  const GridData g = read_grid_file(formats_dir() + "gom_stage_decimal_comma.csv", o);
  EXPECT_TRUE(any_note(g, "decimal comma"));
  o.decimal = '.';
  const GridData h = read_grid_file(formats_dir() + "gom_stage.csv", o);
  ASSERT_EQ(g.ids, h.ids);
  for (Index p = 0; p < g.n_points(); ++p) {
    if (!g.has_deformed(p)) continue;
    EXPECT_LT((row(g.deformed, p) - row(h.deformed, p)).norm(), 1e-12) << g.ids[p];
  }
  // A point anywhere in the first rows means a decimal point; a comma-separated file
  // always has one.
  o.decimal = kDetectDecimal;
  write_text(dir.file("p.csv"),
             "id;x;y;z;displacement_x;displacement_y;displacement_z\na;1;2;3;0;0;0\nb;1.5;2;3;0;0;0\n");
  EXPECT_FALSE(any_note(read_grid_file(dir.file("p.csv"), o), "decimal comma"));
  write_text(dir.file("c.csv"), "id,x,y,z,displacement_x,displacement_y,displacement_z\na,1,2,3,0,0,0\n");
  EXPECT_FALSE(any_note(read_grid_file(dir.file("c.csv"), o), "decimal comma"));
}

// Every preset: a bad cell is named by file, line, field number, column and what was
// expected; a key cell (empty, repeated) by file, line and character column, as the
// grid file's id always was.
TEST(IoFormats, BadCellsOfEachPresetNameFileLineColumn) {
  struct Case {
    MeasurementFormat format;
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {MeasurementFormat::kPlain, "id,X,Y,Z,x,y,z\np,0,0,0,1,zwei,0\n",
       ":2:6: expected a number in column 'y', found 'zwei'"},
      {MeasurementFormat::kGom,
       "Project;p\n\nid;x [mm];y [mm];z [mm];displacement_x [mm];displacement_y [mm];"
       "displacement_z [mm]\n7;1;2;3;0,5;0;0\n",
       ":4:5: expected a number in column 'displacement_x [mm]', found '0,5' (a decimal comma?"},
      {MeasurementFormat::kMatchId,
       "Coordinates.Image X [Pixel],Coordinates.Image Y [Pixel],coor.X [mm],coor.Y [mm],coor.Z [mm],"
       "disp.Horizontal Displacement U [mm],disp.Vertical Displacement V [mm],disp.Out-Of-Plane: W [mm]\n"
       "10,,1,2,3,0,0,0\n",
       ":2:4: empty id cell in column 'Coordinates.Image Y [Pixel]'"},
      {MeasurementFormat::kVic3d,
       " \"X\",  \"Y\",  \"Z\",  \"U\",  \"V\",  \"W\",  \"sigma\",  \"x\",  \"y\"\n"
       "1,2,3,0.1,0.2,0.3,0.004,100,200\n1,2,3,0.1,0.2,0.3,0.004,100,200\n",
       ":3:25: duplicate id '100_200' (from columns x, y) (first at line 2)"},
      {MeasurementFormat::kDice,
       "*** DICe-style\n***\nSUBSET_ID,MODEL_COORDINATES_X,MODEL_COORDINATES_Y,"
       "MODEL_COORDINATES_Z,MODEL_DISPLACEMENT_X,MODEL_DISPLACEMENT_Y,"
       "MODEL_DISPLACEMENT_Z,SIGMA,MATCH\n0,1,2,3,0.1,0.2,0.3,0.004,0\n"
       "1,1,2,3,0.1,0.2,0.3,0.004,-1x\n",
       ":5:9: expected a number in column 'MATCH', found '-1x'"},
  };
  ScratchDir dir;
  const std::string path = dir.file("bad.csv");
  for (const Case& c : cases) {
    write_text(path, c.text);
    EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, preset(c.format)); }), HasSubstr(path + c.expected))
        << format_spec(c.format).name;
  }
}

// Every preset: a file that lacks one of the columns it reads is named by file and
// header line, with the column, what the preset reads and what the header holds.
TEST(IoFormats, MissingColumnsOfEachPreset) {
  struct Case {
    MeasurementFormat format;
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {MeasurementFormat::kGom, "# export\nid;x;y;z;displacement_x;displacement_y\n1;1;2;3;0;0\n",
       ":2: missing required column 'displacement_z' (the other out-of-plane columns are there; --format gom reads"},
      {MeasurementFormat::kMatchId,
       "coor.X [mm],coor.Y [mm],coor.Z [mm],disp.Horizontal Displacement U [mm]\n1,2,3,4\n",
       ":1: missing required column 'disp.Vertical Displacement V' (--format matchid reads coor.X"},
      {MeasurementFormat::kDice, "***\nSUBSET_ID,COORDINATE_X,COORDINATE_Y,DISPLACEMENT_X\n0,1,2,3\n",
       ":2: missing required column 'DISPLACEMENT_Y' (--format dice reads COORDINATE_X, COORDINATE_Y, DISPLACEMENT_X, "
       "DISPLACEMENT_Y (or MODEL_COORDINATES_X"},
  };
  ScratchDir dir;
  const std::string path = dir.file("short.csv");
  for (const Case& c : cases) {
    write_text(path, c.text);
    EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, preset(c.format)); }), HasSubstr(path + c.expected))
        << format_spec(c.format).name;
  }
}

}  // namespace
}  // namespace sf::io

// Grid input as gsa takes it: the texts of --columns and --delimiter (the command layer,
// gsa/command_options.hpp) and the grids `gsa analyse` must refuse (too few points,
// collinear points). Reading and writing grid files: tests/common/io_grid_file_test.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "common/core/error.hpp"
#include "gsa/analysis.hpp"
#include "gsa/command_options.hpp"
#include "gsa/grid.hpp"
#include "tests/common/io_test_util.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::gsa {
namespace {

using io::test::message_of;
using io::test::ScratchDir;
using io::test::write_text;
using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Coordinates read from text are compared exactly up to the decimal conversion.
constexpr double kRead = sf::test::kRoundoff;

// Row p of a point array as a 3-vector.
Vec3 row(const Points3& m, Index p) { return m.row(p).transpose(); }

// Seven marks of a slightly curved 3 x 3 patch (minus two), deformed by x = 1.1 X,
// y = Y + 0.2, z = Z + 0.01 X Y, as CSV rows "id,X,Y,Z,x,y,z" (no header).
std::string seven_rows() {
  std::string s;
  int k = 0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      if (k++ >= 7) break;
      const double X = 10.0 * i, Y = 10.0 * j, Z = 0.01 * (X - 10) * (X - 10);
      s += "m" + std::to_string(j) + std::to_string(i) + "," + std::to_string(X) + "," + std::to_string(Y) + "," +
           std::to_string(Z) + "," + std::to_string(1.1 * X) + "," + std::to_string(Y + 0.2) + "," +
           std::to_string(Z + 0.01 * X * Y) + "\n";
    }
  return s;
}

TEST(GsaGrid, BadColumnMapTextIsRejectedNamingTheOption) {
  EXPECT_THAT(message_of<UsageError>([] { parse_column_map("X=x0,Y"); }),
              AllOf(HasSubstr("--columns"), HasSubstr("'Y'")));
  EXPECT_THAT(message_of<UsageError>([] { parse_column_map("Q=x0"); }),
              AllOf(HasSubstr("--columns"), HasSubstr("'Q'")));
  EXPECT_THAT(message_of<UsageError>([] { parse_column_map("X="); }), HasSubstr("--columns"));
  const auto map = parse_column_map("id=label,X=x0,u=du");
  EXPECT_EQ(map.size(), 3u);
  EXPECT_EQ(map.at("id"), "label");
  EXPECT_EQ(map.at("u"), "du");
}

TEST(GsaGrid, DelimiterNames) {
  EXPECT_EQ(parse_delimiter("tab"), '\t');
  EXPECT_EQ(parse_delimiter("semicolon"), ';');
  EXPECT_EQ(parse_delimiter("comma"), ',');
  EXPECT_EQ(parse_delimiter("space"), ' ');
  EXPECT_EQ(parse_delimiter("|"), '|');
  EXPECT_THAT(message_of<UsageError>([] { parse_delimiter("ab"); }), HasSubstr("--delimiter"));
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id;X;Y;Z;x;y;z\nk1;1,5;2;3;4;5;6\n");  // decimal commas are not numbers
  GridReadOptions o;
  o.delimiter = ';';
  EXPECT_THAT(message_of<InputError>([&] { read_grid(path, o); }), HasSubstr(path + ":2:2:"));
  write_text(path, "id;X;Y;Z;x;y;z\nk1;1.5;2;3;4;5;6\n");
  EXPECT_LT((row(read_grid(path, o).undeformed, 0) - Vec3(1.5, 2, 3)).norm(), kRead);
}

TEST(GsaGrid, FormatIdAndQuotedColumnNames) {
  EXPECT_EQ(parse_format("vic3d"), io::MeasurementFormat::kVic3d);
  EXPECT_EQ(parse_format("GOM"), io::MeasurementFormat::kGom);
  EXPECT_EQ(message_of<UsageError>([] { parse_format("ncorr"); }),
            "--format: unknown format 'ncorr' (expected one of auto, plain, gom, matchid, vic3d, dice)");
  EXPECT_THAT(parse_id_columns("x_pic,y_pic"), ElementsAre("x_pic", "y_pic"));
  EXPECT_THAT(message_of<UsageError>([] { parse_id_columns("a,,b"); }), HasSubstr("--id"));
  // A column name that holds a comma is quoted.
  const auto map = parse_column_map("x=\"eps [%, technical]\",u=du");
  EXPECT_EQ(map.at("x"), "eps [%, technical]");
  EXPECT_EQ(map.at("u"), "du");
  EXPECT_EQ(parse_column_map("sigma=s").at("sigma"), "s");
  EXPECT_EQ(parse_delimiter("auto"), io::kDetectDelimiter);
  EXPECT_THAT(message_of<UsageError>([] { parse_delimiter("#"); }), HasSubstr("--delimiter"));
}

// The reading flags become GridReadOptions; wrong values are usage errors naming the flag.
TEST(GsaGrid, ReadingFlagsAndTheirErrors) {
  AnalyseFlags a;
  a.format = "matchid";
  a.id = "x_pic,y_pic";
  a.positions = "current";
  a.decimal = "comma";
  a.delimiter = "semicolon";
  a.header_line = 3;
  a.units = "m";
  a.pixel_size = 1e-5;
  const GridReadOptions o = grid_read_options(a);
  EXPECT_EQ(o.format, io::MeasurementFormat::kMatchId);
  EXPECT_THAT(o.id_columns, ElementsAre("x_pic", "y_pic"));
  EXPECT_EQ(o.positions, io::Positions::kCurrent);
  EXPECT_EQ(o.decimal, ',');
  EXPECT_EQ(o.delimiter, ';');
  EXPECT_EQ(o.header_line, 3);
  EXPECT_EQ(o.units, "m");
  EXPECT_EQ(o.pixel_size, 1e-5);
  AnalyseFlags row;
  row.id = "row";
  EXPECT_TRUE(grid_read_options(row).id_from_row);
  EXPECT_EQ(grid_read_options(AnalyseFlags{}).delimiter, io::kDetectDelimiter);

  auto error = [](const std::function<void(AnalyseFlags&)>& set) {
    AnalyseFlags f;
    set(f);
    return message_of<UsageError>([&] { grid_read_options(f); });
  };
  EXPECT_THAT(error([](AnalyseFlags& f) { f.format = "excel"; }), HasSubstr("--format: unknown format 'excel'"));
  EXPECT_THAT(error([](AnalyseFlags& f) {
                f.format = "plain";
                f.positions = "current";
              }),
              HasSubstr("--positions: applies to --format"));
  EXPECT_THAT(error([](AnalyseFlags& f) {
                f.format = "gom";
                f.positions = "later";
              }),
              HasSubstr("--positions: expected 'reference' or 'current'"));
  EXPECT_THAT(error([](AnalyseFlags& f) {
                f.decimal = "comma";
                f.delimiter = ",";
              }),
              HasSubstr("--decimal comma"));
  EXPECT_THAT(error([](AnalyseFlags& f) { f.decimal = "dot"; }), HasSubstr("--decimal: expected 'auto'"));
  EXPECT_THAT(error([](AnalyseFlags& f) { f.pitch = 0; }), HasSubstr("--pitch: must be > 0"));
  EXPECT_THAT(error([](AnalyseFlags& f) { f.pixel_size = -1; }), HasSubstr("--pixel-size"));
  EXPECT_THAT(error([](AnalyseFlags& f) {
                f.skip_lines = 2;
                f.header_line = 4;
              }),
              HasSubstr("--skip-lines or --header-line"));
  EXPECT_THAT(error([](AnalyseFlags& f) {
                f.id = "a";
                f.columns = "id=b";
              }),
              HasSubstr("--id"));
  EXPECT_THAT(error([](AnalyseFlags& f) { f.columns = "X=a,x=b,u=c"; }), HasSubstr("--columns: reference positions"));
  EXPECT_THAT(error([](AnalyseFlags& f) {
                f.pitch = 5;
                f.columns = "X=a";
              }),
              HasSubstr("--pitch"));
}

// ---------------------------------------------------------------- grids analyse refuses

TEST(GsaGrid, FewerThanSixPointsIsAnError) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,x,y,z\n" + seven_rows());
  EXPECT_NO_THROW(analyse(read_grid(path), {}));  // seven is enough
  // Five points.
  write_text(path, "id,X,Y,Z,x,y,z\n" + seven_rows().substr(0, seven_rows().find("m12")));
  const GridData five = read_grid(path);
  ASSERT_EQ(five.n_points(), 5);
  EXPECT_THAT(message_of<InputError>([&] { analyse(five, {}); }), AllOf(HasSubstr(path), HasSubstr("6")));
  // Seven points, but only five with both positions.
  std::string rows = seven_rows();
  for (const std::string id : {"m00,", "m11,"}) {
    const auto at = rows.find(id);
    const auto end = rows.find('\n', at);
    rows.replace(at, end - at, id + "0,0,0,nan,nan,nan");
  }
  write_text(path, "id,X,Y,Z,x,y,z\n" + rows);
  EXPECT_THAT(message_of<InputError>([&] { analyse(read_grid(path), {}); }), AllOf(HasSubstr(path), HasSubstr("6")));
}

TEST(GsaGrid, TrianglesMethodNeedsThreePoints) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,x,y,z\na,0,0,0,0,0,0\nb,1,0,0,1,0,0\n");
  AnalyseOptions o;
  o.method = Method::kTriangles;
  EXPECT_THAT(message_of<InputError>([&] { analyse(read_grid(path), o); }), HasSubstr(path));
}

TEST(GsaGrid, CollinearPointsAreAnError) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  std::string text = "id,X,Y,Z,x,y,z\n";
  for (int k = 0; k < 10; ++k)
    text += "p" + std::to_string(k) + "," + std::to_string(k) + "," + std::to_string(2 * k) + "," +
            std::to_string(3 * k) + "," + std::to_string(1.1 * k) + ",0,0\n";
  write_text(path, text);
  EXPECT_THAT(message_of<InputError>([&] { analyse(read_grid(path), {}); }), AllOf(HasSubstr(path), HasSubstr("line")));
  // All points at one place.
  text = "id,X,Y,Z,x,y,z\n";
  for (int k = 0; k < 8; ++k) text += "p" + std::to_string(k) + ",1,2,3,1,2,3\n";
  write_text(path, text);
  EXPECT_THAT(message_of<InputError>([&] { analyse(read_grid(path), {}); }), HasSubstr(path));
}

}  // namespace
}  // namespace sf::gsa

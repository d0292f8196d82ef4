// Reading grid files (CONTRACT.md "Grid file"): the one-file and two-file forms,
// column mapping with displacements, missing cells, and the messages of bad input
// (file:line:column, both lines of a duplicate, the columns found), plus the
// grids `gsa analyse` must refuse (too few points, collinear points).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "common/core/error.hpp"
#include "gsa/analysis.hpp"
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

TEST(GsaGrid, ReadsOneFileWithColumnsInAnyOrderCommentsAndIJ) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path,
             "# a grid\n"
             "z,y,x,j,i,Z,Y,X,id\n"
             "3.5,2.5,1.5,0,1,0.5,0.25,0.125,a\n"
             "# comment in the middle\n"
             "-3,-2,-1,1,1,0,-0.5,1e-3,b\n");
  const GridData g = read_grid(path);
  ASSERT_EQ(g.n_points(), 2);
  EXPECT_THAT(g.ids, ElementsAre("a", "b"));
  EXPECT_LT((row(g.undeformed, 0) - Vec3(0.125, 0.25, 0.5)).norm(), kRead);
  EXPECT_LT((row(g.deformed, 0) - Vec3(1.5, 2.5, 3.5)).norm(), kRead);
  EXPECT_LT((row(g.undeformed, 1) - Vec3(1e-3, -0.5, 0)).norm(), kRead);
  EXPECT_LT((row(g.deformed, 1) - Vec3(-1, -2, -3)).norm(), kRead);
  ASSERT_TRUE(g.has_ij);
  EXPECT_THAT(g.i, ElementsAre(1, 1));
  EXPECT_THAT(g.j, ElementsAre(0, 1));
  // Each point knows where it came from, with the real line number (comments count).
  EXPECT_EQ(g.where[0], path + ":3");
  EXPECT_EQ(g.where[1], path + ":5");
  EXPECT_THAT(g.sources, ElementsAre(path));
}

TEST(GsaGrid, IJAreOptional) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,x,y,z,i\np,0,0,0,1,1,1,4\n");  // i without j: no grid indices
  const GridData g = read_grid(path);
  EXPECT_FALSE(g.has_ij);
  EXPECT_TRUE(g.i.empty());
  EXPECT_TRUE(g.j.empty());
}

TEST(GsaGrid, NanOrEmptyCellMeansNotDigitised) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path,
             "id,X,Y,Z,x,y,z\n"
             "full,1,2,3,4,5,6\n"
             "nodef,1,2,3,nan,5,6\n"
             "nodef2,1,2,3,4,NaN,6\n"
             "nodef3,1,2,3,4,5,\n"
             "noundef,,2,3,4,5,6\n");
  const GridData g = read_grid(path);
  ASSERT_EQ(g.n_points(), 5);
  EXPECT_TRUE(g.has_undeformed(0) && g.has_deformed(0));
  for (Index p : {1, 2, 3}) {
    EXPECT_TRUE(g.has_undeformed(p)) << g.ids[p];
    EXPECT_FALSE(g.has_deformed(p)) << g.ids[p];
    // A partly missing position is missing altogether (no half-known point).
    EXPECT_TRUE(g.deformed.row(p).array().isNaN().all()) << g.ids[p];
  }
  EXPECT_FALSE(g.has_undeformed(4));
  EXPECT_TRUE(g.has_deformed(4));
}

TEST(GsaGrid, PairOfFilesIsJoinedOnIdInAnyRowOrder) {
  ScratchDir dir;
  const std::string u = dir.file("u.csv"), d = dir.file("d.csv");
  write_text(u, "id,x,y,z,i,j\np1,0,0,0,0,0\np2,1,0,0,0,1\np3,0,1,0,1,0\np4,1,1,0,1,1\n");
  write_text(d, "# deformed, other order, p3 not digitised\nz,id,y,x\n0.4,p4,1.4,1.4\n0.2,p2,0.2,1.2\n0.1,p1,0.1,0.1\n");
  const GridData g = read_grid_pair(u, d);
  ASSERT_EQ(g.n_points(), 4);
  EXPECT_THAT(g.ids, ElementsAre("p1", "p2", "p3", "p4"));
  EXPECT_LT((row(g.undeformed, 3) - Vec3(1, 1, 0)).norm(), kRead);
  EXPECT_LT((row(g.deformed, 0) - Vec3(0.1, 0.1, 0.1)).norm(), kRead);
  EXPECT_LT((row(g.deformed, 1) - Vec3(1.2, 0.2, 0.2)).norm(), kRead);
  EXPECT_LT((row(g.deformed, 3) - Vec3(1.4, 1.4, 0.4)).norm(), kRead);
  EXPECT_TRUE(g.has_undeformed(2));
  EXPECT_FALSE(g.has_deformed(2));
  ASSERT_TRUE(g.has_ij);
  EXPECT_THAT(g.i, ElementsAre(0, 0, 1, 1));
  EXPECT_THAT(g.sources, ElementsAre(u, d));
}

TEST(GsaGrid, PairRejectsUnknownAndDuplicateIdsInTheDeformedFile) {
  ScratchDir dir;
  const std::string u = dir.file("u.csv"), d = dir.file("d.csv");
  write_text(u, "id,x,y,z\np1,0,0,0\np2,1,0,0\n");
  write_text(d, "id,x,y,z\np1,0,0,0\nq9,1,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_pair(u, d); }),
              AllOf(HasSubstr(d + ":3:"), HasSubstr("'q9'"), HasSubstr(u)));
  write_text(d, "id,x,y,z\np1,0,0,0\np2,1,0,0\np1,2,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_pair(u, d); }),
              AllOf(HasSubstr(d + ":4:"), HasSubstr("duplicate id 'p1'")));
}

TEST(GsaGrid, ColumnMapWithDisplacements) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "label,x0,y0,z0,du,dv,dw\nk1,1,2,3,0.5,-0.5,0.25\nk2,10,20,30,,1,1\n");
  GridReadOptions o;
  o.columns = parse_column_map("id=label,X=x0,Y=y0,Z=z0,u=du,v=dv,w=dw");
  EXPECT_EQ(o.columns.at("u"), "du");
  const GridData g = read_grid(path, o);
  ASSERT_EQ(g.n_points(), 2);
  EXPECT_THAT(g.ids, ElementsAre("k1", "k2"));
  EXPECT_LT((row(g.undeformed, 0) - Vec3(1, 2, 3)).norm(), kRead);
  EXPECT_LT((row(g.deformed, 0) - Vec3(1.5, 1.5, 3.25)).norm(), kRead);  // x = X + u
  EXPECT_TRUE(g.has_undeformed(1));
  EXPECT_FALSE(g.has_deformed(1));  // a missing displacement is a missing deformed position
}

TEST(GsaGrid, ColumnMapRenamesPositions) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,xd,yd,zd\nk1,1,2,3,4,5,6\n");
  GridReadOptions o;
  o.columns = parse_column_map("x=xd,y=yd,z=zd");
  const GridData g = read_grid(path, o);
  EXPECT_LT((row(g.deformed, 0) - Vec3(4, 5, 6)).norm(), kRead);
}

TEST(GsaGrid, BadColumnMapTextIsRejectedNamingTheOption) {
  EXPECT_THAT(message_of<UsageError>([] { parse_column_map("X=x0,Y"); }), AllOf(HasSubstr("--columns"), HasSubstr("'Y'")));
  EXPECT_THAT(message_of<UsageError>([] { parse_column_map("Q=x0"); }), AllOf(HasSubstr("--columns"), HasSubstr("'Q'")));
  EXPECT_THAT(message_of<UsageError>([] { parse_column_map("X="); }), HasSubstr("--columns"));
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

TEST(GsaGrid, MalformedNumberNamesFileLineAndColumn) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "# header follows\nid,X,Y,Z,x,y,z\np1,0,0,0,0,0,0\np2,1,2x,3,4,5,6\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid(path); }),
              AllOf(HasSubstr(path + ":4:3:"), HasSubstr("'Y'"), HasSubstr("2x")));
  write_text(path, "id,X,Y,Z,x,y,z,i,j\np1,0,0,0,0,0,0,1.5,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid(path); }), AllOf(HasSubstr(path + ":2:8:"), HasSubstr("'i'")));
}

TEST(GsaGrid, DuplicateIdNamesBothLines) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,x,y,z\np1,0,0,0,0,0,0\np2,1,0,0,1,0,0\n\np1,2,0,0,2,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid(path); }),
              AllOf(HasSubstr(path + ":5:"), HasSubstr("'p1'"), HasSubstr("line 2")));
}

TEST(GsaGrid, MissingColumnListsTheColumnsFound) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,x,y,z\np1,0,0,0,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid(path); }),
              AllOf(HasSubstr(path), HasSubstr("'Z'"), HasSubstr("id, X, Y, x, y, z")));
  // Displacement mapping: the displacement columns are the required ones.
  write_text(path, "id,X,Y,Z,u,v\np1,0,0,0,0,0\n");
  GridReadOptions o;
  o.columns = parse_column_map("u=u,v=v,w=w");
  EXPECT_THAT(message_of<InputError>([&] { read_grid(path, o); }), AllOf(HasSubstr("'w'"), HasSubstr("id, X, Y, Z, u, v")));
}

TEST(GsaGrid, MissingFileIsNamed) {
  EXPECT_THAT(message_of<InputError>([] { read_grid("/nonexistent/dir/grid.csv"); }),
              HasSubstr("/nonexistent/dir/grid.csv"));
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

// The grid file (common/io/grid_file.hpp, CONTRACT.md "Grid file"): reading the
// one-file and two-file forms, column mapping with displacements, missing cells, the
// messages of bad input (file:line:column, both lines of a duplicate, the columns found),
// and the writer: what it writes reads back exactly.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "common/core/error.hpp"
#include "common/io/grid_file.hpp"
#include "tests/common/io_test_util.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::io {
namespace {

using test::message_of;
using test::read_text;
using test::ScratchDir;
using test::write_text;
using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Coordinates read from text are compared exactly up to the decimal conversion.
constexpr double kRead = sf::test::kRoundoff;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Row p of a point array as a 3-vector.
Vec3 row(const Points3& m, Index p) { return m.row(p).transpose(); }

TEST(IoGridFile, ReadsOneFileWithColumnsInAnyOrderCommentsAndIJ) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path,
             "# a grid\n"
             "z,y,x,j,i,Z,Y,X,id\n"
             "3.5,2.5,1.5,0,1,0.5,0.25,0.125,a\n"
             "# comment in the middle\n"
             "-3,-2,-1,1,1,0,-0.5,1e-3,b\n");
  const GridData g = read_grid_file(path);
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

TEST(IoGridFile, IJAreOptional) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,x,y,z,i\np,0,0,0,1,1,1,4\n");  // i without j: no grid indices
  const GridData g = read_grid_file(path);
  EXPECT_FALSE(g.has_ij);
  EXPECT_TRUE(g.i.empty());
  EXPECT_TRUE(g.j.empty());
}

TEST(IoGridFile, NanOrEmptyCellMeansNotDigitised) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path,
             "id,X,Y,Z,x,y,z\n"
             "full,1,2,3,4,5,6\n"
             "nodef,1,2,3,nan,5,6\n"
             "nodef2,1,2,3,4,NaN,6\n"
             "nodef3,1,2,3,4,5,\n"
             "noundef,,2,3,4,5,6\n");
  const GridData g = read_grid_file(path);
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

TEST(IoGridFile, PairOfFilesIsJoinedOnIdInAnyRowOrder) {
  ScratchDir dir;
  const std::string u = dir.file("u.csv"), d = dir.file("d.csv");
  write_text(u, "id,x,y,z,i,j\np1,0,0,0,0,0\np2,1,0,0,0,1\np3,0,1,0,1,0\np4,1,1,0,1,1\n");
  write_text(d,
             "# deformed, other order, p3 not digitised\nz,id,y,x\n0.4,p4,1.4,1.4\n0.2,p2,0.2,1.2\n0.1,p1,0.1,0.1\n");
  const GridData g = read_grid_file_pair(u, d);
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

TEST(IoGridFile, PairRejectsUnknownAndDuplicateIdsInTheDeformedFile) {
  ScratchDir dir;
  const std::string u = dir.file("u.csv"), d = dir.file("d.csv");
  write_text(u, "id,x,y,z\np1,0,0,0\np2,1,0,0\n");
  write_text(d, "id,x,y,z\np1,0,0,0\nq9,1,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file_pair(u, d); }),
              AllOf(HasSubstr(d + ":3:"), HasSubstr("'q9'"), HasSubstr(u)));
  write_text(d, "id,x,y,z\np1,0,0,0\np2,1,0,0\np1,2,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file_pair(u, d); }),
              AllOf(HasSubstr(d + ":4:"), HasSubstr("duplicate id 'p1'")));
}

TEST(IoGridFile, ColumnMapWithDisplacements) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "label,x0,y0,z0,du,dv,dw\nk1,1,2,3,0.5,-0.5,0.25\nk2,10,20,30,,1,1\n");
  GridReadOptions o;
  o.columns = {{"id", "label"}, {"X", "x0"}, {"Y", "y0"}, {"Z", "z0"}, {"u", "du"}, {"v", "dv"}, {"w", "dw"}};
  const GridData g = read_grid_file(path, o);
  ASSERT_EQ(g.n_points(), 2);
  EXPECT_THAT(g.ids, ElementsAre("k1", "k2"));
  EXPECT_LT((row(g.undeformed, 0) - Vec3(1, 2, 3)).norm(), kRead);
  EXPECT_LT((row(g.deformed, 0) - Vec3(1.5, 1.5, 3.25)).norm(), kRead);  // x = X + u
  EXPECT_TRUE(g.has_undeformed(1));
  EXPECT_FALSE(g.has_deformed(1));  // a missing displacement is a missing deformed position
}

TEST(IoGridFile, ColumnMapRenamesPositions) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,xd,yd,zd\nk1,1,2,3,4,5,6\n");
  GridReadOptions o;
  o.columns = {{"x", "xd"}, {"y", "yd"}, {"z", "zd"}};
  const GridData g = read_grid_file(path, o);
  EXPECT_LT((row(g.deformed, 0) - Vec3(4, 5, 6)).norm(), kRead);
}

TEST(IoGridFile, MalformedNumberNamesFileLineAndColumn) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "# header follows\nid,X,Y,Z,x,y,z\np1,0,0,0,0,0,0\np2,1,2x,3,4,5,6\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path); }),
              AllOf(HasSubstr(path + ":4:3:"), HasSubstr("'Y'"), HasSubstr("2x")));
  write_text(path, "id,X,Y,Z,x,y,z,i,j\np1,0,0,0,0,0,0,1.5,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path); }),
              AllOf(HasSubstr(path + ":2:8:"), HasSubstr("'i'")));
}

TEST(IoGridFile, DuplicateIdNamesBothLines) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,Z,x,y,z\np1,0,0,0,0,0,0\np2,1,0,0,1,0,0\n\np1,2,0,0,2,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path); }),
              AllOf(HasSubstr(path + ":5:"), HasSubstr("'p1'"), HasSubstr("line 2")));
}

TEST(IoGridFile, MissingColumnListsTheColumnsFound) {
  ScratchDir dir;
  const std::string path = dir.file("grid.csv");
  write_text(path, "id,X,Y,x,y,z\np1,0,0,0,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path); }),
              AllOf(HasSubstr(path), HasSubstr("'Z'"), HasSubstr("id, X, Y, x, y, z")));
  // Displacement mapping: the displacement columns are the required ones.
  write_text(path, "id,X,Y,Z,u,v\np1,0,0,0,0,0\n");
  GridReadOptions o;
  o.columns = {{"u", "u"}, {"v", "v"}, {"w", "w"}};
  EXPECT_THAT(message_of<InputError>([&] { read_grid_file(path, o); }),
              AllOf(HasSubstr("'w'"), HasSubstr("id, X, Y, Z, u, v")));
}

TEST(IoGridFile, MissingFileIsNamed) {
  EXPECT_THAT(message_of<InputError>([] { read_grid_file("/nonexistent/dir/grid.csv"); }),
              HasSubstr("/nonexistent/dir/grid.csv"));
}

// ---------------------------------------------------------------- writing

// Awkward ids (a comma, a quote, a leading '#', blanks), missing positions and grid
// indices, comments and units: all read back exactly, in the writer's column order.
TEST(IoGridFile, WrittenGridReadsBackExactly) {
  ScratchDir dir;
  GridData g;
  g.ids = {"P0_0", "a,b", "say \"hi\"", "#3", " padded "};
  g.undeformed.resize(5, 3);
  g.deformed.resize(5, 3);
  g.undeformed << 0.1, -2.5e-7, 3, 1.0 / 3.0, 2, 0, 1e20, -0.0, 5, kNaN, kNaN, kNaN, 7, 8, 9;
  g.deformed << 0.2, 0.3, 3.1, kNaN, kNaN, kNaN, 4, 5, 6, 1, 2, 3, 7.5, 8.5, 9.5;
  g.has_ij = true;
  g.i = {0, 1, 2, kNoGridIndex, 4};
  g.j = {0, 0, 0, kNoGridIndex, 3};
  GridWriteOptions o;
  o.comments = {"from a test", "two\nlines"};
  o.units = "mm";
  const std::string path = dir.file("grid.csv");
  write_grid_file(path, g, o);
  const std::string text = read_text(path);
  EXPECT_EQ(text.substr(0, text.find("id,")), "# from a test\n# two\n# lines\n# units: mm\n");
  EXPECT_NE(text.find("id,X,Y,Z,x,y,z,i,j\n"), std::string::npos) << text;

  const GridData back = read_grid_file(path);
  EXPECT_EQ(back.ids, g.ids);
  ASSERT_TRUE(back.has_ij);
  EXPECT_EQ(back.i, g.i);
  EXPECT_EQ(back.j, g.j);
  for (Index p = 0; p < 5; ++p)
    for (int k = 0; k < 3; ++k) {
      for (const auto& [written, read] :
           {std::pair{&g.undeformed, &back.undeformed}, std::pair{&g.deformed, &back.deformed}}) {
        const double w = (*written)(p, k), r = (*read)(p, k);
        if (std::isnan(w)) {
          EXPECT_TRUE(std::isnan(r)) << "mark " << p << " coordinate " << k;
        } else {
          EXPECT_EQ(r, w) << "mark " << p << " coordinate " << k;  // shortest round-trip form: exact
        }
      }
    }
  EXPECT_FALSE(back.has_undeformed(3));
  EXPECT_FALSE(back.has_deformed(1));
}

// Without grid indices there are no i, j columns; a half-known position is written as
// not digitised at all, as the reader would take it.
TEST(IoGridFile, WriterWithoutGridIndices) {
  std::ostringstream out;
  {
    GridFileWriter w(out, {});
    w.add("m1", Vec3(1, 2, 3), Vec3(4, kNaN, 6));
    w.add("m2", Vec3(0.5, 0, -1), Vec3(0.5, 0, -2));
  }
  EXPECT_EQ(out.str(), "id,X,Y,Z,x,y,z\nm1,1,2,3,,,\nm2,0.5,0,-1,0.5,0,-2\n");
}

// The writer's programming errors: an empty id (unreadable), and a row form that does not
// match the columns.
TEST(IoGridFile, WriterRejectsEmptyIdsAndTheWrongRowForm) {
  std::ostringstream out;
  GridWriteOptions with_ij;
  with_ij.with_ij = true;
  GridFileWriter w(out, with_ij);
  EXPECT_THROW(w.add("", Vec3::Zero(), Vec3::Zero(), 0, 0), std::logic_error);
  EXPECT_THROW(w.add("m", Vec3::Zero(), Vec3::Zero()), std::logic_error);
  std::ostringstream out2;
  GridFileWriter plain(out2, {});
  EXPECT_THROW(plain.add("m", Vec3::Zero(), Vec3::Zero(), 1, 2), std::logic_error);
}

// A writer's own per-mark columns follow the contract's; NaN is an empty cell, and the
// reader ignores them.
TEST(IoGridFile, WriterExtraColumns) {
  std::ostringstream out;
  {
    GridWriteOptions o;
    o.with_ij = true;
    o.extra_columns = {"views", "reproj_px"};
    GridFileWriter w(out, o);
    w.add("a", Vec3(1, 2, 3), Vec3(4, 5, 6), 0, 1, {2, 0.125});
    w.add("b", Vec3(1, 2, 3), Vec3(kNaN, 5, 6), 1, 1, {kNaN, kNaN});
    EXPECT_THROW(w.add("c", Vec3::Zero(), Vec3::Zero(), 2, 1), std::logic_error);  // no extras given
  }
  EXPECT_EQ(out.str(), "id,X,Y,Z,x,y,z,i,j,views,reproj_px\na,1,2,3,4,5,6,0,1,2,0.125\nb,1,2,3,,,,1,1,,\n");
  GridWriteOptions clash;
  clash.extra_columns = {"X"};
  std::ostringstream out2;
  EXPECT_THROW(GridFileWriter(out2, clash), std::logic_error);
}

TEST(IoGridFile, ColumnKeys) {
  for (const char* key : {"id", "X", "Y", "Z", "x", "y", "z", "u", "v", "w", "i", "j"})
    EXPECT_TRUE(is_grid_column_key(key)) << key;
  for (const char* key : {"", "Q", "ID", "xyz", "k"}) EXPECT_FALSE(is_grid_column_key(key)) << key;
}

}  // namespace
}  // namespace sf::io

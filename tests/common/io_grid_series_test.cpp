// Stage series (common/io/grid_series.hpp): natural order of stage files, one file per
// stage joined on the id with the reference (or without one), a stage column in one
// file, what each stage knows of its marks (absent, not measured, sigma), the check of
// the position columns' meaning, and the messages of bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "common/core/error.hpp"
#include "common/io/grid_series.hpp"
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
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr double kSixDecimals = 2e-6;  // positions written with 6 decimals (mm)
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Vec3 row(const Points3& m, Index p) { return m.row(p).transpose(); }
std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

GridReadOptions gom() {
  GridReadOptions o;
  o.format = MeasurementFormat::kGom;
  return o;
}

TEST(IoGridSeries, NaturalOrder) {
  std::vector<std::string> names = {"s_10.000s", "s_2.000s", "s_0.000s", "b1", "a10", "a2", "a02", "a"};
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) { return natural_less(a, b); });
  EXPECT_THAT(names, ElementsAre("a", "a02", "a2", "a10", "b1", "s_0.000s", "s_2.000s", "s_10.000s"));
  EXPECT_FALSE(natural_less("x7", "x7"));
  EXPECT_TRUE(natural_less("frame-0009_0.csv", "frame-0010_0.csv"));
}

TEST(IoGridSeries, StageFilesOfAFolderInNaturalOrderWithoutTheReference) {
  const std::string dir = formats_dir() + "gom_series";
  const std::vector<std::string> files = stage_files({dir}, dir + "/surface-1_0.000s.csv");
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(file_name(files[0]), "surface-1_2.000s.csv");
  EXPECT_EQ(file_name(files[1]), "surface-1_10.000s.csv");
  // Files given one by one are ordered the same way, each once.
  const std::vector<std::string> listed = stage_files({files[1], files[0], files[1]});
  EXPECT_EQ(listed, files);
}

// The GOM series: reference stage 0 and stages 2 s and 10 s, joined on id. Stage 2 has
// point 17 with empty cells (not measured); stage 10 has lost points 9 and 33 (absent).
TEST(IoGridSeries, OneFilePerStageJoinedOnTheId) {
  const std::string dir = formats_dir() + "gom_series/";
  const GridSeries s = read_grid_series(dir + "surface-1_0.000s.csv", {dir}, gom());
  ASSERT_EQ(s.n_points(), 49);
  ASSERT_EQ(s.n_stages(), 2u);
  EXPECT_EQ(s.stages[0].name, "surface-1_2.000s");
  EXPECT_EQ(s.stages[0].time, 2.0);
  EXPECT_EQ(s.stages[1].time, 10.0);
  EXPECT_THAT(s.sources,
              ElementsAre(dir + "surface-1_0.000s.csv", dir + "surface-1_2.000s.csv", dir + "surface-1_10.000s.csv"));
  for (Index p = 0; p < 49; ++p) {
    const int pid = std::stoi(s.ids[p]);
    const Vec3 X = example_reference((pid - 1) / 7, (pid - 1) % 7);
    EXPECT_LT((row(s.undeformed, p) - X).norm(), kSixDecimals) << pid;
    for (std::size_t k = 0; k < 2; ++k) {
      const GridStage& st = s.stages[k];
      const bool lost = k == 1 && (pid == 9 || pid == 33);
      const bool empty = k == 0 && pid == 17;
      if (lost || empty) {
        EXPECT_FALSE(row(st.deformed, p).allFinite()) << pid;
      } else {
        EXPECT_LT((row(st.deformed, p) - example_current(X, st.time)).norm(), kSixDecimals) << pid << " " << st.name;
      }
      EXPECT_EQ(st.where[p].empty(), lost) << pid;
      EXPECT_EQ(!st.not_measured.empty() && st.not_measured[p], empty) << pid;
    }
  }
  EXPECT_TRUE(s.stages[1].not_measured.empty());  // lost rows are absent, not flagged
  // One stage as the grid the analysis takes.
  const GridData g = s.stage_grid(0);
  EXPECT_THAT(g.sources, ElementsAre(dir + "surface-1_0.000s.csv", dir + "surface-1_2.000s.csv"));
  const Index p17 = std::find(g.ids.begin(), g.ids.end(), "17") - g.ids.begin();
  EXPECT_TRUE(g.not_measured_deformed(p17));
  EXPECT_FALSE(g.not_measured_undeformed(p17));
  EXPECT_EQ(g.where[0], dir + "surface-1_0.000s.csv:7");
}

// --format auto on a series: every file is recognised, and the series is the one the
// preset reads.
TEST(IoGridSeries, AutoFindsThePresetOfEveryStageFile) {
  const std::string dir = formats_dir() + "gom_series/";
  GridReadOptions o;
  o.format = MeasurementFormat::kAuto;
  const GridSeries a = read_grid_series(dir + "surface-1_0.000s.csv", {dir}, o);
  const GridSeries b = read_grid_series(dir + "surface-1_0.000s.csv", {dir}, gom());
  ASSERT_EQ(a.ids, b.ids);
  ASSERT_EQ(a.n_stages(), b.n_stages());
  for (std::size_t k = 0; k < a.n_stages(); ++k) EXPECT_EQ(a.stages[k].not_measured, b.stages[k].not_measured);
  std::size_t found = 0;
  for (const std::string& n : a.notes) found += n.find("format found from the header: gom") != std::string::npos;
  EXPECT_EQ(found, 3u);  // the reference and two stage files
}

// Without a reference file the undeformed positions are the stages' reference positions
// (GOM: x - displacement), taken from the first stage that has the mark.
TEST(IoGridSeries, WithoutAReferenceFileTheStagesGiveTheUndeformedPositions) {
  const std::string dir = formats_dir() + "gom_series/";
  const GridSeries s = read_grid_series("", {dir + "surface-1_10.000s.csv", dir + "surface-1_2.000s.csv"}, gom());
  ASSERT_EQ(s.n_stages(), 2u);
  EXPECT_EQ(s.stages[0].time, 2.0);
  ASSERT_EQ(s.n_points(), 49);  // 17 (empty in stage 2) and 9, 33 (lost in stage 10) come from the other stage
  for (Index p = 0; p < 49; ++p) {
    const int pid = std::stoi(s.ids[p]);
    EXPECT_LT((row(s.undeformed, p) - example_reference((pid - 1) / 7, (pid - 1) % 7)).norm(), kSixDecimals) << pid;
  }
  EXPECT_TRUE(s.not_measured_undeformed.empty());
}

TEST(IoGridSeries, StageColumnInOneFile) {
  GridReadOptions o;
  const GridSeries s = read_grid_series_column(formats_dir() + "stage_column.csv", "stage", o, "0");
  ASSERT_EQ(s.n_points(), 49);
  ASSERT_EQ(s.n_stages(), 2u);
  EXPECT_EQ(s.stages[0].name, "5");
  EXPECT_EQ(s.stages[1].name, "10");
  EXPECT_EQ(s.stages[1].time, 10.0);
  EXPECT_EQ(s.ids[8], "m1_1");
  const Vec3 X = example_reference(1, 1);
  EXPECT_LT((row(s.undeformed, 8) - X).norm(), kSixDecimals);
  EXPECT_LT((row(s.stages[0].deformed, 8) - example_current(X, 5.0)).norm(), kSixDecimals);
  EXPECT_LT((row(s.stages[1].deformed, 8) - example_current(X, 10.0)).norm(), kSixDecimals);
  EXPECT_THAT(
      message_of<InputError>([&] { read_grid_series_column(formats_dir() + "stage_column.csv", "stage", o, "1"); }),
      HasSubstr("no rows of the reference stage '1' (stages: 0, 5, 10)"));
}

TEST(IoGridSeries, StageColumnWithReferencePositionsInEveryRow) {
  ScratchDir dir;
  const std::string path = dir.file("s.csv");
  write_text(path, "id,frame,X,Y,Z,u,v,w,sigma\na,2,0,0,0,0.2,0,0,0.01\na,1,0,0,0,0.1,0,0,0.02\nb,1,1,0,0,0.1,0,0,\n");
  const GridSeries s = read_grid_series_column(path, "frame");
  ASSERT_EQ(s.n_stages(), 2u);
  EXPECT_EQ(s.stages[0].name, "1");
  EXPECT_THAT(s.ids, ElementsAre("a", "b"));
  EXPECT_EQ(row(s.undeformed, 1), Vec3(1, 0, 0));
  EXPECT_EQ(row(s.stages[1].deformed, 0), Vec3(0.2, 0, 0));
  EXPECT_FALSE(row(s.stages[1].deformed, 1).allFinite());  // b is not in frame 2
  ASSERT_EQ(s.stages[0].sigma.size(), 2u);
  EXPECT_EQ(s.stages[0].sigma[0], 0.02);
  EXPECT_TRUE(std::isnan(s.stages[0].sigma[1]));
  write_text(path, "id,frame,X,Y,Z,u,v,w\na,1,0,0,0,0.1,0,0\na,1,0,0,0,0.1,0,0\n");
  EXPECT_THAT(
      message_of<InputError>([&] { read_grid_series_column(path, "frame"); }),
      AllOf(HasSubstr(path + ":3:1:"), HasSubstr("duplicate id 'a' in stage '1'"), HasSubstr("first at line 2")));
}

TEST(IoGridSeries, StageFileWithAnIdTheReferenceLacksIsAnError) {
  ScratchDir dir;
  write_text(dir.file("ref.csv"), "id,x,y,z\np1,0,0,0\np2,1,0,0\n");
  write_text(dir.file("s1.csv"), "id,x,y,z\np1,0,0,0\n");
  write_text(dir.file("s2.csv"), "# stage 2\nid,x,y,z\np2,1,0,0\nq7,5,5,5\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_series(dir.file("ref.csv"), {dir.path().string()}); }),
              AllOf(HasSubstr(dir.file("s2.csv") + ":4:1:"), HasSubstr("id 'q7' (id) is not in the reference"),
                    HasSubstr(dir.file("ref.csv"))));
}

TEST(IoGridSeries, JoiningByRowOrderNeedsTheSameRows) {
  ScratchDir dir;
  write_text(dir.file("ref.csv"), "x,y,z\n0,0,0\n1,0,0\n");
  write_text(dir.file("s1.csv"), "x,y,z\n0,0,1\n1,0,1\n");
  write_text(dir.file("s2.csv"), "x,y,z\n0,0,2\n");
  GridReadOptions o;
  EXPECT_THAT(message_of<InputError>([&] { read_grid_series(dir.file("ref.csv"), {dir.file("s1.csv")}, o); }),
              AllOf(HasSubstr("missing required column 'id'"), HasSubstr("joins the files")));
  o.id_from_row = true;
  const GridSeries s = read_grid_series(dir.file("ref.csv"), {dir.file("s1.csv")}, o);
  EXPECT_EQ(row(s.stages[0].deformed, 1), Vec3(1, 0, 1));
  EXPECT_THAT(message_of<InputError>([&] { read_grid_series(dir.file("ref.csv"), {dir.file("s2.csv")}, o); }),
              AllOf(HasSubstr(dir.file("s2.csv")), HasSubstr("1 rows, but the reference file")));
}

// Read with the wrong meaning of the position columns, the stages' reference positions
// move with the displacement; the series says so.
TEST(IoGridSeries, PositionColumnsOfTheOtherStateAreNoticed) {
  const std::string dir = formats_dir() + "gom_series/";
  GridReadOptions o = gom();
  const GridSeries right = read_grid_series(dir + "surface-1_0.000s.csv", {dir}, o);
  for (const std::string& n : right.notes) EXPECT_THAT(n, ::testing::Not(HasSubstr("other state"))) << n;
  o.positions = Positions::kReference;
  const GridSeries wrong = read_grid_series(dir + "surface-1_0.000s.csv", {dir}, o);
  EXPECT_TRUE(std::any_of(wrong.notes.begin(), wrong.notes.end(), [&](const std::string& n) {
    return n.find("surface-1_10.000s.csv: its reference positions") != std::string::npos &&
           n.find("other state") != std::string::npos;
  }));
}

TEST(IoGridSeries, MissingFoldersAndEmptyFoldersAreNamed) {
  ScratchDir dir;
  EXPECT_THAT(message_of<InputError>([&] { stage_files({dir.file("absent")}); }),
              HasSubstr(dir.file("absent") + ": no such file or folder"));
  write_text(dir.file("notes.md"), "not a stage\n");
  EXPECT_THAT(message_of<InputError>([&] { stage_files({dir.path().string()}); }),
              HasSubstr("no stage files (csv, txt, tsv or dat) in this folder"));
  write_text(dir.file("ref.csv"), "id,x,y,z\np,0,0,0\n");
  EXPECT_THAT(message_of<InputError>([&] { read_grid_series(dir.file("ref.csv"), {dir.path().string()}); }),
              HasSubstr("no stage files besides the reference file"));
  (void)kNaN;
}

}  // namespace
}  // namespace sf::io

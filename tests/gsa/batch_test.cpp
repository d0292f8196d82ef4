// `gsa batch` pieces (gsa/batch.hpp): finding the parts, splitting --options, reading a
// part's results folder into a row, the table. The runs themselves: tests/batch/check_batch.sh.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "gsa/batch.hpp"

namespace sf::gsa {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

class BatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(SF_BINARY_DIR) / "test_scratch" /
           ("batch_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void write(const fs::path& p, const std::string& text) {
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
  }
  fs::path dir_;
};

TEST_F(BatchTest, FolderOfFilesAndPartFolders) {
  write(dir_ / "b.csv", "x");
  write(dir_ / "a.TXT", "x");
  write(dir_ / ".hidden.csv", "x");
  write(dir_ / "notes.md", "x");
  write(dir_ / "c" / "grid.csv", "x");
  write(dir_ / "c" / "options", "# fibre mode\n--fibres 0,90  --view \"1,2,3\"\n");
  write(dir_ / "empty" / "other.csv", "x");
  const auto parts = batch_parts(dir_.string());
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].name, "a");
  EXPECT_EQ(parts[1].name, "b");
  EXPECT_EQ(parts[2].name, "c");
  EXPECT_EQ(parts[2].input, (dir_ / "c" / "grid.csv").string());
  EXPECT_THAT(parts[2].extra_options, ElementsAre("--fibres", "0,90", "--view", "1,2,3"));
}

TEST_F(BatchTest, ListFileRelativeToItsFolder) {
  write(dir_ / "parts" / "p1.csv", "x");
  write(dir_ / "dome" / "grid.csv", "x");
  write(dir_ / "list.txt", "# trial 7\nparts/p1.csv\n\n  dome/grid.csv  \n");
  const auto parts = batch_parts((dir_ / "list.txt").string());
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].name, "p1");
  EXPECT_EQ(parts[1].name, "dome");  // grid.csv is named by its folder
  EXPECT_EQ(parts[1].input, (dir_ / "dome" / "grid.csv").string());
}

TEST_F(BatchTest, ListErrorsNameTheLine) {
  write(dir_ / "p1.csv", "x");
  write(dir_ / "sub" / "p1.csv", "x");
  write(dir_ / "list.txt", "p1.csv\nmissing.csv\n");
  try {
    batch_parts((dir_ / "list.txt").string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("list.txt:2"));
    EXPECT_THAT(e.what(), HasSubstr("missing.csv"));
  }
  write(dir_ / "list2.txt", "p1.csv\nsub/p1.csv\n");
  try {
    batch_parts((dir_ / "list2.txt").string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("part name 'p1'"));
    EXPECT_THAT(e.what(), HasSubstr("list2.txt:1"));
  }
  // A grid file given where a list is expected.
  write(dir_ / "grid_by_mistake.csv", "id,X,Y,Z,x,y,z\nP1,0,0,0,0,0,0\n");
  try {
    batch_parts((dir_ / "grid_by_mistake.csv").string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("a list of them, one path a line"));
  }
  EXPECT_THROW(batch_parts((dir_ / "nothing-here").string()), InputError);
  fs::create_directories(dir_ / "void");
  EXPECT_THROW(batch_parts((dir_ / "void").string()), InputError);
}

TEST(BatchOptions, SplitsWordsWithQuotes) {
  EXPECT_THAT(split_options("  --fibres 0,90 --view '1, 2, 3'  --flc \"my curve.csv\""),
              ElementsAre("--fibres", "0,90", "--view", "1, 2, 3", "--flc", "my curve.csv"));
  EXPECT_TRUE(split_options("").empty());
  EXPECT_THROW(split_options("--flc \"open"), UsageError);
}

TEST_F(BatchTest, CollectsAPartFolderAndAFailedLog) {
  write(dir_ / "p1" / "summary.json", R"({"inputs": ["parts/p1.csv"], "timings_s": {"read": 0.25, "fit": 0.5}})");
  write(dir_ / "p1" / "strains.csv",
        "# comment\nid,status,true1,eng1,E1,thickness_change_pct,flc_margin\n"
        "a,ok,0.1,0.2,0.3,-5,0.05\nb,ok,0.15,0.2,0.3,-7.5,-0.01\nc,missing_deformed,,,,,\n");
  write(dir_ / "logs" / "p2.log",
        "# gsa batch input: parts/p2.csv\ngsa: reading parts/p2.csv\ngsa: error: parts/p2.csv:3:2: bad number\n");
  write(dir_ / "p3.tmp-123-1" / "strains.csv", "x");  // a run killed half-way: not a part
  EXPECT_THAT(parts_in_results(dir_.string()), ElementsAre("p1", "p2"));

  const BatchRow ok = collect_part(dir_.string(), "p1", "true");
  EXPECT_EQ(ok.status, "ok");
  EXPECT_EQ(ok.input, "parts/p1.csv");
  EXPECT_EQ(ok.points, 3);
  EXPECT_EQ(ok.analysed, 2);
  EXPECT_DOUBLE_EQ(ok.max_major, 0.15);
  EXPECT_DOUBLE_EQ(ok.min_thickness_change_pct, -7.5);
  EXPECT_DOUBLE_EQ(ok.worst_flc_margin, -0.01);
  EXPECT_DOUBLE_EQ(ok.run_time_s, 0.75);
  EXPECT_DOUBLE_EQ(collect_part(dir_.string(), "p1", "engineering").max_major, 0.2);

  const BatchRow failed = collect_part(dir_.string(), "p2", "true");
  EXPECT_EQ(failed.status, "failed");
  EXPECT_EQ(failed.error, "parts/p2.csv:3:2: bad number");
  EXPECT_EQ(failed.input, "parts/p2.csv");
  const BatchRow missing = collect_part(dir_.string(), "p9", "true");
  EXPECT_EQ(missing.status, "missing");

  const std::string table = write_batch_table(dir_.string(), {ok, failed, missing}, "true");
  const io::CsvTable t = io::read_csv(table);
  ASSERT_EQ(t.n_rows(), 3u);
  EXPECT_EQ(t.cell(0, t.column_index("max_major_true")), "0.15");
  EXPECT_EQ(t.cell(1, t.column_index("status")), "failed");
  EXPECT_EQ(t.cell(1, t.column_index("error")), "parts/p2.csv:3:2: bad number");
}

}  // namespace
}  // namespace sf::gsa

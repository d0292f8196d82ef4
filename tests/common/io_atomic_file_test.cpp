#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "tests/common/io_test_util.hpp"

namespace sf::io {
namespace {

namespace fs = std::filesystem;

// Number of entries in `dir` whose name starts with `prefix`.
int count_entries(const fs::path& dir, const std::string& prefix) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) ++n;
  }
  return n;
}

TEST(IoAtomicFile, CommitCreatesTheDirectoryWithAllFiles) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  {
    AtomicOutputDir dir(out);
    EXPECT_EQ(dir.final_dir(), out);
    test::write_text(dir.path("strains.csv"), "id\n");
    test::write_text(dir.path("steps/step_1.vtu"), "<x/>");
    EXPECT_FALSE(fs::exists(out));
    EXPECT_TRUE(fs::is_directory(dir.temp_dir()));
    EXPECT_EQ(dir.temp_dir().parent_path(), scratch.path());  // a sibling
    dir.commit();
    EXPECT_TRUE(dir.committed());
  }
  EXPECT_EQ(test::read_text(out / "strains.csv"), "id\n");
  EXPECT_EQ(test::read_text(out / "steps" / "step_1.vtu"), "<x/>");
  EXPECT_EQ(count_entries(scratch.path(), "results"), 1);  // no temporary left
}

TEST(IoAtomicFile, AbandonedRunLeavesExistingOutputUntouched) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  fs::create_directories(out);
  test::write_text(out / "strains.csv", "old\n");
  try {
    AtomicOutputDir dir(out.string() + "/");  // a trailing slash names the same directory
    EXPECT_EQ(dir.final_dir(), out);
    test::write_text(dir.path("strains.csv"), "half-writ");
    throw std::runtime_error("the run failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(test::read_text(out / "strains.csv"), "old\n");
  EXPECT_EQ(count_entries(scratch.path(), "results"), 1);
}

TEST(IoAtomicFile, CommitReplacesSameNamesAndKeepsOthers) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  fs::create_directories(out);
  test::write_text(out / "strains.csv", "old\n");
  test::write_text(out / "notes.txt", "mine\n");
  AtomicOutputDir dir(out);
  test::write_text(dir.path("strains.csv"), "new\n");
  test::write_text(dir.path("summary.json"), "{}\n");
  EXPECT_EQ(test::read_text(out / "strains.csv"), "old\n");  // not before commit
  dir.commit();
  EXPECT_EQ(test::read_text(out / "strains.csv"), "new\n");
  EXPECT_EQ(test::read_text(out / "summary.json"), "{}\n");
  EXPECT_EQ(test::read_text(out / "notes.txt"), "mine\n");
  EXPECT_FALSE(fs::exists(dir.temp_dir()));
  EXPECT_THROW(dir.commit(), std::logic_error);
  EXPECT_THROW(dir.path("late.csv"), std::logic_error);
}

TEST(IoAtomicFile, RejectsNamesOutsideTheDirectory) {
  test::ScratchDir scratch;
  AtomicOutputDir dir(scratch.path() / "out");
  EXPECT_THROW(dir.path("/etc/passwd"), std::logic_error);
  EXPECT_THROW(dir.path("../x.csv"), std::logic_error);
  EXPECT_THROW(dir.path("a/../../x.csv"), std::logic_error);
  EXPECT_THROW(dir.path(""), std::logic_error);
  EXPECT_NO_THROW(dir.path("a/../x.csv"));
}

TEST(IoAtomicFile, WriteFileAtomicReplacesWholeFile) {
  test::ScratchDir scratch;
  const std::string path = scratch.file("a.txt");
  write_file_atomic(path, std::string("first"));
  write_file_atomic(path, std::string("second"));
  EXPECT_EQ(test::read_text(path), "second");
  // A writer that fails leaves the old content and no temporary file.
  EXPECT_THROW(write_file_atomic(path,
                                 [](std::ostream& out) {
                                   out << "par";
                                   throw std::runtime_error("boom");
                                 }),
               std::runtime_error);
  EXPECT_EQ(test::read_text(path), "second");
  EXPECT_EQ(count_entries(scratch.path(), "a.txt"), 1);
  EXPECT_THROW(write_file_atomic(scratch.file("missing/dir/a.txt"), std::string("x")), Error);
}

}  // namespace
}  // namespace sf::io

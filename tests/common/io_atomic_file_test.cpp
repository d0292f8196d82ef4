#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <stdexcept>
#include <vector>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "tests/common/io_test_util.hpp"
#include "tests/common/kill_replace.hpp"

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

// A pid that ran and is gone (a child that exited).
long dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return static_cast<long>(child);
}

TEST(IoAtomicFile, CommitReplacesTheWholeFolderKeepingTheUsersFiles) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  fs::create_directories(out / "steps");
  test::write_text(out / "strains.csv", "old\n");
  test::write_text(out / "major_strain.png", "old picture\n");  // an output the new run does not write
  test::write_text(out / "steps" / "step_9.vtu", "old frame\n");
  test::write_text(out / "notes.txt", "mine\n");
  OutputDirOptions o;
  o.owned = {"strains.csv", "*.png", "steps"};
  AtomicOutputDir dir(out, o);
  test::write_text(dir.path("strains.csv"), "new\n");
  test::write_text(dir.path("steps/step_1.vtu"), "new frame\n");
  dir.commit();
  EXPECT_EQ(test::read_text(out / "strains.csv"), "new\n");
  EXPECT_EQ(test::read_text(out / "steps" / "step_1.vtu"), "new frame\n");
  EXPECT_FALSE(fs::exists(out / "major_strain.png"));       // the old run's: gone
  EXPECT_FALSE(fs::exists(out / "steps" / "step_9.vtu"));   // the old run's: gone
  EXPECT_EQ(test::read_text(out / "notes.txt"), "mine\n");  // the user's: kept
  EXPECT_EQ(count_entries(scratch.path(), "results"), 1);
}

TEST(IoAtomicFile, SecondWriterOfTheSameFolderStopsWithAClearMessage) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  AtomicOutputDir first(out);
  const std::string msg = test::message_of<Error>([&] { AtomicOutputDir second(out); });
  EXPECT_THAT(msg, ::testing::HasSubstr("another run (process " + std::to_string(::getpid()) + ")"));
  EXPECT_THAT(msg, ::testing::HasSubstr(out.string()));
  // Another folder beside it is free.
  EXPECT_NO_THROW(AtomicOutputDir other(scratch.path() / "results2"));
}

TEST(IoAtomicFile, TheLockFileIsRemovedWhenTheRunEnds) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  const fs::path lock = scratch.path() / ".results.lock";
  {
    AtomicOutputDir dir(out);
    EXPECT_EQ(test::read_text(lock), std::to_string(::getpid()) + "\n");  // the holder, for the message
    test::write_text(dir.path("strains.csv"), "id\n");
    dir.commit();
  }
  EXPECT_FALSE(fs::exists(lock));
  { AtomicOutputDir abandoned(out); }  // a failed run (no commit) removes it too
  EXPECT_FALSE(fs::exists(lock));
  EXPECT_EQ(count_entries(scratch.path(), ""), 1);  // results/ alone
}

// A run killed with SIGKILL while it holds the lock leaves the lock file (nothing runs at
// a SIGKILL); the kernel dropped its lock, so the next run is not blocked, and removes it.
TEST(IoAtomicFile, TheLockFileOfAKilledRunDoesNotBlockTheNext) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  const fs::path lock = scratch.path() / ".results.lock";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    AtomicOutputDir dir(out);
    const char c = 'x';
    [[maybe_unused]] const ssize_t w = ::write(ready[1], &c, 1);
    ::pause();
    ::_exit(0);
  }
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);  // the child holds the lock
  EXPECT_THAT(test::message_of<Error>([&] { AtomicOutputDir second(out); }),
              ::testing::HasSubstr("another run (process " + std::to_string(child) + ")"));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(ready[0]);
  ::close(ready[1]);
  ASSERT_TRUE(fs::exists(lock));  // left by the killed run, naming it
  EXPECT_EQ(test::read_text(lock), std::to_string(child) + "\n");
  {
    AtomicOutputDir next(out);  // not blocked
    test::write_text(next.path("strains.csv"), "id\n");
    next.commit();
  }
  EXPECT_TRUE(fs::exists(out / "strains.csv"));
  EXPECT_FALSE(fs::exists(lock));
  EXPECT_EQ(count_entries(scratch.path(), "results."), 0);  // the killed run's temporary: cleaned
}

// Runs that take the lock of one folder again and again, at the same time: never two
// holders at once, even though each removes the lock file when it ends (a run that opened
// the file just before its removal must not count as holding the lock).
TEST(IoAtomicFile, RemovingTheLockFileNeverLetsTwoRunsHoldTheLock) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  const std::string busy = (scratch.path() / "busy").string();
  std::vector<pid_t> children;
  for (int k = 0; k < 3; ++k) {
    const pid_t child = ::fork();
    if (child == 0) {
      int held = 0;
      for (int i = 0; i < 400; ++i) {
        try {
          AtomicOutputDir dir(out);
          const int fd = ::open(busy.c_str(), O_CREAT | O_EXCL | O_WRONLY, 0644);
          if (fd < 0) ::_exit(2);  // another run holds the lock at the same time
          ::close(fd);
          ++held;
          ::unlink(busy.c_str());
        } catch (const Error&) {
          // another run holds it: that is the expected refusal
        }
      }
      ::_exit(held > 0 ? 0 : 3);
    }
    children.push_back(child);
  }
  for (const pid_t child : children) {
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 2) << "two runs held the lock of one folder at once";
  }
  EXPECT_FALSE(fs::exists(scratch.path() / ".results.lock"));
}

TEST(IoAtomicFile, StaleTemporariesOfDeadRunsAreRemoved) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  const long dead = dead_pid();
  const fs::path stale = scratch.path() / ("results.tmp-" + std::to_string(dead) + "-3");
  const fs::path live = scratch.path() / ("results.tmp-" + std::to_string(::getppid()) + "-0");
  const fs::path other = scratch.path() / ("resultsX.tmp-" + std::to_string(dead) + "-0");
  for (const auto& d : {stale, live, other}) fs::create_directories(d / "steps");
  test::write_text(stale / "steps" / "a.vtu", "x");
  { AtomicOutputDir dir(out); }
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));   // its process runs
  EXPECT_TRUE(fs::exists(other));  // another folder's
}

TEST(IoAtomicFile, FolderLostBetweenTheFallbackRenamesIsPutBack) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "results";
  const fs::path aside = scratch.path() / ("results.old-" + std::to_string(dead_pid()) + "-0");
  fs::create_directories(aside);
  test::write_text(aside / "strains.csv", "complete\n");
  { AtomicOutputDir dir(out); }
  EXPECT_EQ(test::read_text(out / "strains.csv"), "complete\n");
  EXPECT_FALSE(fs::exists(aside));
}

TEST(IoAtomicFile, EmptyOrCurrentFolderIsRefused) {
  EXPECT_THROW(AtomicOutputDir(""), Error);
  EXPECT_THROW(AtomicOutputDir("."), Error);
  EXPECT_THROW(AtomicOutputDir(fs::current_path().parent_path()), Error);
}

TEST(IoAtomicFile, WorkingFolderSurvivesAFailureAndIsResumed) {
  test::ScratchDir scratch;
  const fs::path out = scratch.path() / "run";
  OutputDirOptions o;
  o.work_suffix = ".partial";
  {
    AtomicOutputDir dir(out, o);
    test::write_text(dir.path("steps/step_1.vtu"), "1");
  }  // abandoned (a failure): kept
  EXPECT_TRUE(fs::exists(scratch.path() / "run.partial" / "steps" / "step_1.vtu"));
  o.resume = true;
  {
    AtomicOutputDir dir(out, o);
    EXPECT_TRUE(fs::exists(dir.path("steps/step_1.vtu")));
    test::write_text(dir.path("steps/step_2.vtu"), "2");
    dir.commit();
  }
  EXPECT_TRUE(fs::exists(out / "steps" / "step_1.vtu"));
  EXPECT_TRUE(fs::exists(out / "steps" / "step_2.vtu"));
  EXPECT_FALSE(fs::exists(scratch.path() / "run.partial"));
  // Seeding from the committed folder links its files in.
  o.resume = false;
  AtomicOutputDir dir(out, o);
  EXPECT_TRUE(dir.seed_from_final());
  EXPECT_EQ(test::read_text(dir.temp_dir() / "steps" / "step_2.vtu"), "2");
}

// The fast version of the kill-during-replace study (100 kills: ctest -L long).
TEST(IoAtomicFile, KillsDuringReplaceAlwaysLeaveOneCompleteSet) {
  test::ScratchDir scratch;
  const test::KillStudy s = test::kill_during_replace(scratch.path() / "results", 12, 12, 7);
  EXPECT_EQ(s.complete, s.kills) << s.first_problem;
  EXPECT_EQ(s.left_after_cleaning, 0);
}

}  // namespace
}  // namespace sf::io

// 100 kills (SIGKILL) at random moments of a writer re-writing a results folder: the folder
// always holds one complete result set (tests/common/kill_replace.hpp). ctest -L long.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "tests/common/kill_replace.hpp"

namespace sf::io {
namespace {

TEST(KillDuringReplace, HundredKillsAlwaysLeaveOneCompleteSet) {
  const auto scratch = std::filesystem::temp_directory_path() / ("sf_kill_long_" + std::to_string(::getpid()));
  std::filesystem::remove_all(scratch);
  std::filesystem::create_directories(scratch);
  const test::KillStudy s = test::kill_during_replace(scratch / "results", 100, 30, 2026);
  std::printf(
      "kill-during-replace: %d kills, %d complete sets (%d of a re-run, %d still the first), %d without a "
      "folder, %d temporaries seen after kills, %d left after the next run cleaned\n",
      s.kills, s.complete, s.replaced, s.complete - s.replaced, s.no_folder, s.temporaries, s.left_after_cleaning);
  EXPECT_EQ(s.complete, s.kills) << s.first_problem;
  EXPECT_EQ(s.left_after_cleaning, 0);
  std::filesystem::remove_all(scratch);
}

}  // namespace
}  // namespace sf::io

// 100 kills (SIGKILL) at random moments of re-runs into a results folder: the folder always
// holds one complete result set. First the writer of tests/common/kill_replace.hpp (30
// files, the mechanism alone), then `gsa analyse` itself (tests/reliability/gsa_kill.hpp).
// ctest -L long.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "tests/common/kill_replace.hpp"
#include "tests/reliability/gsa_kill.hpp"

namespace sf::io {
namespace {

std::filesystem::path fresh_scratch(const char* name) {
  const auto scratch = std::filesystem::temp_directory_path() / (name + std::to_string(::getpid()));
  std::filesystem::remove_all(scratch);
  std::filesystem::create_directories(scratch);
  return scratch;
}

TEST(KillDuringReplace, HundredKillsAlwaysLeaveOneCompleteSet) {
  const auto scratch = fresh_scratch("sf_kill_long_");
  const test::KillStudy s = test::kill_during_replace(scratch / "results", 100, 30, 2026);
  std::printf(
      "kill-during-replace: %d kills, %d complete sets (%d of a re-run, %d still the first), %d without a "
      "folder, %d temporaries seen after kills, %d left after the next run cleaned\n",
      s.kills, s.complete, s.replaced, s.complete - s.replaced, s.no_folder, s.temporaries, s.left_after_cleaning);
  EXPECT_EQ(s.complete, s.kills) << s.first_problem;
  EXPECT_EQ(s.left_after_cleaning, 0);
  std::filesystem::remove_all(scratch);
}

TEST(GsaKillDuringReplace, HundredKilledRerunsOfGsaAnalyseLeaveOneCompleteResultSet) {
  const auto scratch = fresh_scratch("sf_gsa_kill_long_");
  const sf::test::GsaKillStudy s = sf::test::kill_gsa_analyse(scratch, 100, 2026);
  std::printf(
      "gsa analyse kill study: %d killed, %d ended before the kill, after the kills %d old and %d new complete "
      "result sets, %d runs refused or failed, %d temporaries or lock files left after a last run\n",
      s.kills, s.finished, s.old_results, s.new_results, s.refused, s.left_after);
  EXPECT_EQ(s.first_problem, "");
  EXPECT_EQ(s.refused, 0);
  EXPECT_EQ(s.old_results + s.new_results, s.kills);
  EXPECT_GE(s.kills, 50);  // most runs were killed (the kills spread over 1.1 runs' time)
  EXPECT_EQ(s.left_after, 0);
  std::filesystem::remove_all(scratch);
}

}  // namespace
}  // namespace sf::io

// Issue 20: `gsa analyse` killed (SIGKILL) at random moments of a re-run into a results
// folder leaves the old complete results or the new complete results, never a mix, and
// nothing that blocks the next run (tests/reliability/gsa_kill.hpp). The study with 100
// kills: reliability_long.GsaKillDuringReplace.* (ctest -L long).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "tests/reliability/gsa_kill.hpp"

namespace sf {
namespace {

TEST(GsaKill, KilledRerunsLeaveOneCompleteResultSetAndNoLitter) {
  const auto scratch = std::filesystem::temp_directory_path() / ("sf_gsa_kill_" + std::to_string(::getpid()));
  std::filesystem::remove_all(scratch);
  std::filesystem::create_directories(scratch);
  const test::GsaKillStudy s = test::kill_gsa_analyse(scratch, 5, 20);
  std::printf("gsa analyse kill study: %d killed (%d old, %d new result sets after), %d ended before the kill\n",
              s.kills, s.old_results, s.new_results, s.finished);
  EXPECT_EQ(s.kills + s.finished + s.refused, 5);
  EXPECT_EQ(s.first_problem, "");
  EXPECT_EQ(s.refused, 0);  // a killed run's lock file and temporary never block the next
  EXPECT_EQ(s.old_results + s.new_results, s.kills);
  EXPECT_EQ(s.left_after, 0);
  std::filesystem::remove_all(scratch);
}

}  // namespace
}  // namespace sf

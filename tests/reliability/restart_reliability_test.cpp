// Issue 20, simform run --restart: after a kill the series lists every frame (tool and
// contact parts too) and nothing of another run that used the folder before; a restart
// with any case value changed is refused, naming it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/core/error.hpp"
#include "forming/case/reader.hpp"
#include "forming/run/run.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

namespace fs = std::filesystem;

// The cantilever with `steps` steps, a frame every step, written to `dir`/case.yaml.
std::string cantilever_case(const fs::path& dir, int steps, const std::string& E_T = "1", int elements = 10) {
  std::string t = fixtures::read_text(std::string(SF_SOURCE_DIR) + "/data/forming/cantilever.yaml");
  t = std::regex_replace(t, std::regex("steps: 10"), "steps: " + std::to_string(steps));
  t = std::regex_replace(t, std::regex("every: 2"), "every: 1");
  t = std::regex_replace(t, std::regex("E_T: 1,"), "E_T: " + E_T + ",");
  t = std::regex_replace(t, std::regex("elements: \\[10, 1\\]"), "elements: [" + std::to_string(elements) + ", 1]");
  fs::create_directories(dir);
  const fs::path path =
      dir / ("cantilever_" + std::to_string(steps) + "_" + E_T + "_" + std::to_string(elements) + ".yaml");
  std::ofstream(path) << t;
  return path.string();
}

// Runs bin/simform run CASE --out OUT and kills it (SIGKILL) once the run in progress has
// written the frame of step `at` (OUT.partial/restart.json). False if the run ended first.
bool run_and_kill(const std::string& case_file, const fs::path& out, int at) {
  const std::string simform = std::string(SF_BINARY_DIR) + "/bin/simform";
  std::vector<std::string> args = {simform, "run", case_file, "--out", out.string(), "-q"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (::posix_spawn(&pid, simform.c_str(), nullptr, nullptr, argv.data(), environ) != 0) return false;
  const fs::path restart = fs::path(out.string() + ".partial") / "restart.json";
  const auto t0 = std::chrono::steady_clock::now();
  bool killed = false;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return false;  // finished before the kill
    const std::string text = fixtures::read_text(restart);
    const auto at_step = text.find("\"step\":");
    if (at_step != std::string::npos && std::atoi(text.c_str() + at_step + 7) >= at) {
      ::kill(pid, SIGKILL);
      killed = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return killed;
}

std::vector<std::string> data_sets(const fs::path& pvd) {
  std::vector<std::string> out;
  std::istringstream in(fixtures::read_text(pvd));
  for (std::string line; std::getline(in, line);)
    if (line.find("<DataSet") != std::string::npos) out.push_back(line);
  return out;
}

TEST(Restart, AfterAKillTheSeriesListsEveryFrameAndNothingForeign) {
  const fs::path tmp = fs::temp_directory_path() / ("sf_restart_kill_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  const std::string long_case = cantilever_case(tmp, 40);
  // The reference: one uninterrupted run.
  RunOptions whole;
  whole.out_dir = (tmp / "whole").string();
  whole.quiet = true;
  ASSERT_TRUE(run_case(load_case(long_case), whole).ok());

  // The folder first holds a complete run of another case (50 steps, 12 elements): its
  // frames must never enter the restarted series.
  const fs::path out = tmp / "out";
  RunOptions other = whole;
  other.out_dir = out.string();
  ASSERT_TRUE(run_case(load_case(cantilever_case(tmp, 50, "1", 12)), other).ok());
  ASSERT_TRUE(fs::exists(out / "steps" / "step_0050.vtu"));

  if (!run_and_kill(long_case, out, 5)) GTEST_SKIP() << "the run finished before it could be killed";
  // The killed run left its frames in out.partial; out still holds the complete older run.
  EXPECT_TRUE(fs::exists(out / "steps" / "step_0050.vtu"));
  RunOptions again = whole;
  again.out_dir = out.string();
  again.restart = true;
  const RunReport r = run_case(load_case(long_case), again);
  ASSERT_EQ(r.status, RunReport::Status::kConverged) << r.message;
  const auto expected = data_sets(tmp / "whole" / "result.pvd");
  const auto got = data_sets(out / "result.pvd");
  EXPECT_EQ(got.size(), expected.size());  // 41 frames: 0 .. 40, before and after the kill
  for (const std::string& line : expected) EXPECT_THAT(got, ::testing::Contains(line));
  EXPECT_FALSE(fs::exists(out / "steps" / "step_0050.vtu"));  // the older run's: gone
  // Frames before the kill are this case's (10 elements), not the older run's (12).
  const auto points = [](const fs::path& vtu) {
    const std::string t = fixtures::read_text(vtu);
    const auto at = t.find("NumberOfPoints=\"");
    return at == std::string::npos ? std::string() : t.substr(at, 30);
  };
  for (const char* frame : {"steps/step_0000.vtu", "steps/step_0003.vtu", "steps/step_0040.vtu"})
    EXPECT_EQ(points(out / frame), points(tmp / "whole" / frame)) << frame;
  EXPECT_FALSE(fs::exists(out.string() + ".partial"));
  fs::remove_all(tmp);
}

TEST(Restart, ChangedMaterialConstantIsRefusedNamingIt) {
  const fs::path tmp = fs::temp_directory_path() / ("sf_restart_fp_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  RunOptions o;
  o.out_dir = (tmp / "out").string();
  o.quiet = true;
  o.stop_after = 2;
  ASSERT_TRUE(run_case(load_case(cantilever_case(tmp, 6)), o).ok());
  o.stop_after = 0;
  o.restart = true;
  try {
    run_case(load_case(cantilever_case(tmp, 6, "1.5")), o);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("transversely_isotropic.E_T: 1 -> 1.5"));
  }
  // Solver settings are part of the case too.
  try {
    run_case(load_case(cantilever_case(tmp, 7)), o);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("solver.steps: 6 -> 7"));
  }
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace sf::forming

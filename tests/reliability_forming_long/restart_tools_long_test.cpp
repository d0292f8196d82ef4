// Issue 20: tool and contact parts written before a restart stay in the series (the
// laminate punch sample, several contact steps: ctest -L long).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "forming/case/reader.hpp"
#include "forming/run/run.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> data_sets(const fs::path& pvd) {
  std::vector<std::string> out;
  std::istringstream in(fixtures::read_text(pvd));
  for (std::string line; std::getline(in, line);)
    if (line.find("<DataSet") != std::string::npos) out.push_back(line);
  return out;
}

TEST(Restart, ToolAndContactFramesBeforeTheRestartStayInTheSeries) {
  const std::string file = std::string(SF_SOURCE_DIR) + "/data/forming/contact/laminate_punch.yaml";
  const FormingCase spec = load_case(file);
  const fs::path tmp = fs::temp_directory_path() / ("sf_restart_tools_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  RunOptions o;
  o.out_dir = (tmp / "out").string();
  o.quiet = true;
  o.stop_after = 1;
  ASSERT_TRUE(run_case(spec, o).ok());
  const auto parts_before = data_sets(tmp / "out" / "result.pvd");
  o.stop_after = 1;
  o.restart = true;
  ASSERT_TRUE(run_case(spec, o).ok());
  const auto parts_after = data_sets(tmp / "out" / "result.pvd");
  // Every data set (plies, tools, contact points) of steps 0..1 is still listed.
  for (const std::string& line : parts_before) EXPECT_THAT(parts_after, ::testing::Contains(line));
  EXPECT_GT(parts_after.size(), parts_before.size());
  int tools = 0;
  for (const std::string& line : parts_after) tools += line.find("steps/tool_") != std::string::npos ? 1 : 0;
  EXPECT_GE(tools, 3);  // steps 0, 1 (before the restart) and 2
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace sf::forming

// simform run --stop-after / --restart: a run split in two gives the same final state,
// history and frames as one uninterrupted run.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "common/core/error.hpp"
#include "forming/case/reader.hpp"
#include "forming/run/run.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

namespace fs = std::filesystem;

TEST(Restart, SplitRunMatchesUninterruptedRun) {
  const FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/cantilever.yaml");
  const fs::path tmp = fs::temp_directory_path() / "sf_restart_test";
  fs::remove_all(tmp);
  RunOptions whole;
  whole.out_dir = (tmp / "whole").string();
  whole.quiet = true;
  ASSERT_TRUE(run_case(spec, whole).ok());

  RunOptions first = whole;
  first.out_dir = (tmp / "split").string();
  first.stop_after = 3;
  const RunReport a = run_case(spec, first);
  EXPECT_EQ(a.status, RunReport::Status::kStopped);
  EXPECT_EQ(nlohmann::json::parse(fixtures::read_text(tmp / "split" / "summary.json"))["status"], "stopped");
  RunOptions second = first;
  second.stop_after = 0;
  second.restart = true;
  const RunReport b = run_case(spec, second);
  ASSERT_EQ(b.status, RunReport::Status::kConverged) << b.message;

  const nlohmann::json rw = nlohmann::json::parse(fixtures::read_text(tmp / "whole" / "restart.json"));
  const nlohmann::json rs = nlohmann::json::parse(fixtures::read_text(tmp / "split" / "restart.json"));
  const std::vector<double> xw = rw["positions"], xs = rs["positions"];
  ASSERT_EQ(xw.size(), xs.size());
  double diff = 0.0;
  for (std::size_t i = 0; i < xw.size(); ++i) diff = std::max(diff, std::abs(xw[i] - xs[i]));
  EXPECT_LT(diff, 1e-9) << "final positions of the split run differ by " << diff << " mm";
  // History: same number of rows; the collection lists every frame once.
  auto rows = [](const std::string& t) { return std::count(t.begin(), t.end(), '\n'); };
  EXPECT_EQ(rows(fixtures::read_text(tmp / "whole" / "history.csv")),
            rows(fixtures::read_text(tmp / "split" / "history.csv")));
  // Every frame of the whole run is in the split run's collection (which also has the
  // frame written where it stopped).
  const std::string pvd_split = fixtures::read_text(tmp / "split" / "result.pvd");
  std::istringstream pvd_whole(fixtures::read_text(tmp / "whole" / "result.pvd"));
  for (std::string line; std::getline(pvd_whole, line);)
    if (line.find("<DataSet") != std::string::npos) {
      EXPECT_NE(pvd_split.find(line), std::string::npos) << line;
    }
  fs::remove_all(tmp);
}

TEST(Restart, MissingOrForeignRestartFileIsAnInputError) {
  const FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/uniaxial_0.yaml");
  const fs::path tmp = fs::temp_directory_path() / "sf_restart_test_bad";
  fs::remove_all(tmp);
  RunOptions o;
  o.out_dir = tmp.string();
  o.quiet = true;
  o.restart = true;
  EXPECT_THROW(run_case(spec, o), InputError);
  // A restart file of another model.
  o.restart = false;
  ASSERT_TRUE(run_case(load_case(std::string(SF_SOURCE_DIR) + "/data/forming/cantilever.yaml"), o).ok());
  o.restart = true;
  try {
    run_case(spec, o);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("written for a different case"), std::string::npos) << e.what();
  }
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace sf::forming

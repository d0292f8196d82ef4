// simform run --stop-after / --restart: a run split in two gives the same final state,
// history and frames as one uninterrupted run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

// `spec` run whole into tmp/whole and split (stopped after `stop_after` steps, then
// restarted) into tmp/split; both must converge. Returns the largest difference of the
// final positions (mm).
double run_whole_and_split(const FormingCase& spec, const fs::path& tmp, int stop_after) {
  fs::remove_all(tmp);
  RunOptions whole;
  whole.out_dir = (tmp / "whole").string();
  whole.quiet = true;
  const RunReport w = run_case(spec, whole);
  EXPECT_TRUE(w.ok()) << w.message;

  RunOptions first = whole;
  first.out_dir = (tmp / "split").string();
  first.stop_after = stop_after;
  const RunReport a = run_case(spec, first);
  EXPECT_EQ(a.status, RunReport::Status::kStopped);
  EXPECT_EQ(nlohmann::json::parse(fixtures::read_text(tmp / "split" / "summary.json"))["status"], "stopped");
  RunOptions second = first;
  second.stop_after = 0;
  second.restart = true;
  const RunReport b = run_case(spec, second);
  EXPECT_EQ(b.status, RunReport::Status::kConverged) << b.message;

  const nlohmann::json rw = nlohmann::json::parse(fixtures::read_text(tmp / "whole" / "restart.json"));
  const nlohmann::json rs = nlohmann::json::parse(fixtures::read_text(tmp / "split" / "restart.json"));
  const std::vector<double> xw = rw["positions"], xs = rs["positions"];
  EXPECT_EQ(xw.size(), xs.size());
  double diff = 0.0;
  for (std::size_t i = 0; i < std::min(xw.size(), xs.size()); ++i) diff = std::max(diff, std::abs(xw[i] - xs[i]));
  return diff;
}

TEST(Restart, SplitRunMatchesUninterruptedRun) {
  const FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/cantilever.yaml");
  const fs::path tmp = fs::temp_directory_path() / "sf_restart_test";
  const double diff = run_whole_and_split(spec, tmp, 3);
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

// A stabilised run (forming/solve/stabilisation.hpp) restarted after its first steps goes
// on with the c calibrated in step 1 and the energy dissipated so far (restart.json's
// "stabilisation"): it ends where the uninterrupted run ends, with the same c and energy.
// Without them restored, the second part would calibrate c again from its own first step
// and restart its energy sum at 0.
TEST(Restart, StabilisedSplitRunKeepsItsDampingAndEnergy) {
  FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/cantilever.yaml");
  spec.solver.stabilise_fraction = 1e-2;
  const fs::path tmp = fs::temp_directory_path() / "sf_restart_test_stabilised";
  const double diff = run_whole_and_split(spec, tmp, 3);
  EXPECT_LT(diff, 1e-9) << "final positions of the split run differ by " << diff << " mm";
  const nlohmann::json sw = nlohmann::json::parse(fixtures::read_text(tmp / "whole" / "summary.json"));
  const nlohmann::json ss = nlohmann::json::parse(fixtures::read_text(tmp / "split" / "summary.json"));
  ASSERT_TRUE(sw.contains("stabilisation"));
  ASSERT_TRUE(ss.contains("stabilisation"));
  const double cw = sw["stabilisation"]["damping"].get<double>(), cs = ss["stabilisation"]["damping"].get<double>();
  const double ew = sw["stabilisation"]["energy"].get<double>(), es = ss["stabilisation"]["energy"].get<double>();
  EXPECT_GT(cw, 0.0);
  EXPECT_GT(ew, 0.0);
  EXPECT_NEAR(cs, cw, 1e-12 * cw);
  EXPECT_NEAR(es, ew, 1e-9 * ew);
  std::printf("stabilised cantilever split 3 + rest: c %.6g / %.6g N s/mm^4, energy %.9g / %.9g N mm, positions %.2g mm\n",
              cw, cs, ew, es, diff);
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

// A restart file whose history rows do not have this run's columns (edited by hand, or
// written for other tools) is refused naming the file, the row and both column counts,
// before anything is written; earlier it failed later with a bare CSV field count.
TEST(Restart, HistoryRowsOfAnotherShapeAreRefusedNamingTheFile) {
  const FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/uniaxial_0.yaml");
  const fs::path tmp = fs::temp_directory_path() / "sf_restart_test_history";
  fs::remove_all(tmp);
  RunOptions o;
  o.out_dir = tmp.string();
  o.quiet = true;
  o.stop_after = 2;
  ASSERT_EQ(run_case(spec, o).status, RunReport::Status::kStopped);
  const fs::path restart = tmp / "restart.json";
  nlohmann::json j = nlohmann::json::parse(fixtures::read_text(restart));
  std::string rows = j["history_rows"];
  const std::size_t second = rows.find('\n') + 1;  // row 1 loses its last column
  const std::size_t end = rows.find('\n', second);
  rows.erase(rows.rfind(',', end), end - rows.rfind(',', end));
  j["history_rows"] = rows;
  std::ofstream(restart) << j.dump();
  o.stop_after = 0;
  o.restart = true;
  try {
    run_case(spec, o);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("restart.json"), std::string::npos) << m;
    EXPECT_NE(m.find("history row 2 has 11 columns where this run's history.csv has 12"), std::string::npos) << m;
  }
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace sf::forming

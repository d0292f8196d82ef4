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

// The Newton iterations of each step (history.csv's newton_iterations column).
std::vector<int> step_iterations(const fs::path& history) {
  std::istringstream in(fixtures::read_text(history));
  std::string line;
  std::getline(in, line);
  int column = 0;
  for (std::size_t at = 0; at < line.find("newton_iterations"); ++at) column += line[at] == ',';
  std::vector<int> out;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string cell;
    for (int c = 0; c <= column; ++c) std::getline(row, cell, ',');
    out.push_back(std::stoi(cell));
  }
  return out;
}

// With `predictor: extrapolate` each step's first iterate starts from the last step's
// increment, and each solve with the sub-step the last one ended with. A restart keeps
// both (restart.json `predictor_rate`, `next_increment`), so the restarted steps take the
// iterations they take in the uninterrupted run and end at its state. Measured on the
// cantilever split after 3 steps: without either, step 4 took 40 iterations against 34;
// with the sub-step kept but not the rate, 13 (the tangent predictor) and the later steps
// differ too.
TEST(Restart, ExtrapolatingPredictorKeepsItsRateAcrossARestart) {
  FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/cantilever.yaml");
  spec.solver.extrapolate = true;
  const fs::path tmp = fs::temp_directory_path() / "sf_restart_test_extrapolate";
  const double diff = run_whole_and_split(spec, tmp, 3);
  EXPECT_LT(diff, 1e-9) << "final positions of the split run differ by " << diff << " mm";
  const std::vector<int> whole = step_iterations(tmp / "whole" / "history.csv");
  const std::vector<int> split = step_iterations(tmp / "split" / "history.csv");
  EXPECT_EQ(whole, split);
  const nlohmann::json r = nlohmann::json::parse(fixtures::read_text(tmp / "split" / "restart.json"));
  ASSERT_TRUE(r.contains("predictor_rate"));
  EXPECT_EQ(r["predictor_rate"].size(), r["positions"].size());
  std::string w, s;
  for (int i : whole) w += " " + std::to_string(i);
  for (int i : split) s += " " + std::to_string(i);
  std::printf("extrapolating cantilever, iterations a step: whole%s; split after 3%s\n", w.c_str(), s.c_str());
  fs::remove_all(tmp);
}

// The solver keys that steer how a step is solved (max_iterations, tolerance,
// min_increment, line_search, predictor, linear, branch_switch) may change at a restart
// and take effect from its first step; the others (here the number of steps) are still
// refused, naming the key.
TEST(Restart, SolverKeysThatSteerTheSolveMayChange) {
  const std::string text = fixtures::read_text(std::string(SF_SOURCE_DIR) + "/data/forming/cantilever.yaml");
  const std::string solver = "solver: {steps: 10, max_iterations: 30, tolerance: 1.0e-8}";
  ASSERT_NE(text.find(solver), std::string::npos);
  const fs::path tmp = fs::temp_directory_path() / "sf_restart_test_solver_keys";
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  auto with_solver = [&](const std::string& name, const std::string& line) {
    std::string t = text;
    t.replace(t.find(solver), solver.size(), line);
    std::ofstream(tmp / name) << t;
    return load_case((tmp / name).string());
  };
  RunOptions o;
  o.out_dir = (tmp / "out").string();
  o.quiet = true;
  o.stop_after = 3;
  ASSERT_EQ(run_case(with_solver("a.yaml", solver), o).status, RunReport::Status::kStopped);
  o.stop_after = 0;
  o.restart = true;
  // Two iterations a step and no cut-back below half a step: step 4 (7 to 14
  // iterations in the file's run) cannot converge, so the restart fails there, with the
  // new values in its message.
  const RunReport r = run_case(
      with_solver("b.yaml", "solver: {steps: 10, max_iterations: 2, tolerance: 1.0e-7, min_increment: 0.5, "
                            "line_search: false, predictor: extrapolate, linear: direct}"),
      o);
  EXPECT_EQ(r.status, RunReport::Status::kNotConverged);
  EXPECT_NE(r.message.find("step 4 of 10"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("in 2 iterations"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("min_increment 0.5"), std::string::npos) << r.message;
  try {
    run_case(with_solver("c.yaml", "solver: {steps: 20, max_iterations: 30, tolerance: 1.0e-8}"), o);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("solver.steps: 10 -> 20"), std::string::npos) << e.what();
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

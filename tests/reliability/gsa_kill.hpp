#pragma once
// The kill-during-replace study of `gsa analyse` itself (issue 20): bin/gsa re-analyses
// into one results folder, alternating two inputs (A: the dome grid, B: the cylinder grid),
// and is killed with SIGKILL at random moments. After every kill the folder must hold one
// complete result set, the one of A or the one of B, file for file as a run to the end
// writes it (never files of both, never a file cut short), and the next run must not be
// blocked by what the killed one left (its lock file, its temporary folder). The last run
// cleans up: no temporary folder and no lock file are left.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace sf::test {

struct GsaKillStudy {
  int kills = 0;        // runs killed before they ended
  int finished = 0;     // runs that ended before the kill (exit 0)
  int old_results = 0;  // kills after which the folder held the previous run's results
  int new_results = 0;  // kills after which it held the killed run's own (killed after the swap)
  int refused = 0;      // runs that did not start or failed (e.g. blocked by a stale lock)
  int left_after = 0;   // temporaries and lock files beside the folder after a last full run
  std::string first_problem;
};

namespace gsa_kill {

namespace fs = std::filesystem;

inline std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Every file of a folder (relative name -> content).
inline std::map<std::string, std::string> files_of(const fs::path& dir) {
  std::map<std::string, std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec))
    if (it->is_regular_file()) out[fs::relative(it->path(), dir).string()] = read_all(it->path());
  return out;
}

// The results of one run as a signature: the set of files and the content of each, except
// summary.json's stage timings and command line (they differ between two runs of one
// input); summary.json must be whole (it ends with its closing brace).
inline std::map<std::string, std::string> signature(const fs::path& dir, std::string* problem) {
  std::map<std::string, std::string> f = files_of(dir);
  auto it = f.find("summary.json");
  if (it == f.end()) {
    *problem = "no summary.json";
    return f;
  }
  std::string& s = it->second;
  if (s.find_last_not_of(" \n") == std::string::npos || s[s.find_last_not_of(" \n")] != '}')
    *problem = "summary.json cut short";
  // Keep the lines that do not vary between runs of one input: all but the command line
  // (it names the output folder) and the block of stage timings.
  std::string kept;
  std::size_t pos = 0;
  bool timings = false;
  while (pos < s.size()) {
    std::size_t nl = s.find('\n', pos);
    if (nl == std::string::npos) nl = s.size();
    const std::string line = s.substr(pos, nl - pos);
    if (line.find("\"timings_s\"") != std::string::npos) timings = true;
    if (!timings && line.find("\"command_line\"") == std::string::npos) kept += line + "\n";
    if (timings && line.find('}') != std::string::npos) timings = false;
    pos = nl + 1;
  }
  s = kept;
  return f;
}

// Starts `gsa --quiet analyse INPUT --out OUT --no-plots` (output to /dev/null).
inline pid_t start(const std::string& gsa, const std::string& input, const fs::path& out) {
  std::vector<std::string> args = {gsa, "--quiet", "analyse", input, "--out", out.string(), "--no-plots"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, gsa.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

inline int run_to_end(const std::string& gsa, const std::string& input, const fs::path& out) {
  const pid_t pid = start(gsa, input, out);
  if (pid < 0) return -1;
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace gsa_kill

// `scratch`: an empty folder for the runs; `kills`: how many runs to kill.
inline GsaKillStudy kill_gsa_analyse(const std::filesystem::path& scratch, int kills, unsigned seed) {
  namespace fs = std::filesystem;
  using namespace gsa_kill;
  GsaKillStudy s;
  const std::string gsa = std::string(SF_BINARY_DIR) + "/bin/gsa";
  const std::string inputs[2] = {std::string(SF_SOURCE_DIR) + "/data/gsa/dome/grid.csv",
                                 std::string(SF_SOURCE_DIR) + "/data/gsa/cylinder/grid.csv"};
  // The two complete result sets, each from a run to the end (timed: the kills spread
  // over 1.1 runs' time, so they land in every phase of one, the swap included).
  std::map<std::string, std::string> expected[2];
  double run_seconds = 0.0;
  for (int k = 0; k < 2; ++k) {
    const fs::path ref = scratch / ("reference_" + std::to_string(k));
    const auto t0 = std::chrono::steady_clock::now();
    if (run_to_end(gsa, inputs[k], ref) != 0) {
      s.first_problem = "the reference run of " + inputs[k] + " failed";
      return s;
    }
    run_seconds = std::max(run_seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    std::string problem;
    expected[k] = signature(ref, &problem);
    if (!problem.empty()) {
      s.first_problem = ref.string() + ": " + problem;
      return s;
    }
  }
  const fs::path out = scratch / "results";
  if (run_to_end(gsa, inputs[0], out) != 0) {
    s.first_problem = "the first run into " + out.string() + " failed";
    return s;
  }
  int current = 0;  // which input's results the folder holds
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> fraction(0.0, 1.1);
  for (int k = 0; k < kills; ++k) {
    const int next = 1 - current;
    const auto t0 = std::chrono::steady_clock::now();
    const pid_t pid = start(gsa, inputs[next], out);
    if (pid < 0) {
      ++s.refused;
      continue;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(fraction(rng) * run_seconds));
    // Waited for the run's end? Then runs got faster (a machine less loaded than when the
    // references ran): the kills spread over the time of the last run to the end.
    int ended = 0;
    if (::waitpid(pid, &ended, WNOHANG) == pid) {
      if (!WIFEXITED(ended) || WEXITSTATUS(ended) != 0) {
        ++s.refused;
        if (s.first_problem.empty()) s.first_problem = "run " + std::to_string(k) + " failed (exit code)";
        continue;
      }
      run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ++s.finished;
      std::string problem;
      const auto got = signature(out, &problem);
      if ((got != expected[next] || !problem.empty()) && s.first_problem.empty())
        s.first_problem = "run " + std::to_string(k) + " ended but the folder does not hold its results";
      current = next;
      continue;
    }
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (WIFEXITED(status)) {
      if (WEXITSTATUS(status) == 0) {
        ++s.finished;
      } else {
        ++s.refused;
        if (s.first_problem.empty()) s.first_problem = "run " + std::to_string(k) + " failed (exit code)";
      }
    } else {
      ++s.kills;
    }
    std::string problem;
    const auto got = signature(out, &problem);
    const int holds = got == expected[0] ? 0 : got == expected[1] ? 1 : -1;
    if (holds < 0 || !problem.empty()) {
      if (s.first_problem.empty())
        s.first_problem = "after run " + std::to_string(k) + " the folder holds no complete result set" +
                          (problem.empty() ? "" : " (" + problem + ")");
      continue;
    }
    if (WIFSIGNALED(status)) ++(holds == next ? s.new_results : s.old_results);
    current = holds;
  }
  // A last run to the end cleans what the killed ones left.
  if (run_to_end(gsa, inputs[1 - current], out) != 0 && s.first_problem.empty())
    s.first_problem = "the last run failed";
  for (const auto& e : fs::directory_iterator(scratch)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("results.", 0) == 0 || name.rfind(".results", 0) == 0) ++s.left_after;
  }
  return s;
}

}  // namespace sf::test

#pragma once
// The kill-during-replace study of io::AtomicOutputDir (issue 20): a child process
// re-writes a results folder of `n_files` files again and again (each file carries the
// run's number), the parent kills it with SIGKILL at random moments; after every kill the
// folder must hold one complete result set (every file, all of one run), and the next
// writer removes the dead run's temporaries.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <thread>

#include "common/io/atomic_file.hpp"

namespace sf::io::test {

struct KillStudy {
  int kills = 0;
  int complete = 0;     // kills after which the folder held one complete set
  int no_folder = 0;    // kills after which there was no folder (never expected)
  int replaced = 0;     // complete sets of a re-run (generation > 0), the others the first
  int temporaries = 0;  // temporaries left by the killed runs (then cleaned)
  int left_after_cleaning = 0;
  std::string first_problem;
};

inline std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Writes generation `gen` of the folder: `n_files` files (some in a subfolder), then commits.
inline void write_generation(const std::filesystem::path& dir, int n_files, long gen) {
  AtomicOutputDir out(dir, OutputDirOptions{{"*.csv", "summary.json", "steps"}, "", false});
  for (int f = 0; f < n_files; ++f) {
    std::ofstream os(
        out.path(f % 3 == 0 ? "steps/part_" + std::to_string(f) + ".csv" : "f" + std::to_string(f) + ".csv"));
    for (int line = 0; line < 200; ++line) os << gen << "," << f << "," << line << "\n";
  }
  std::ofstream(out.path("summary.json")) << "{\"generation\": " << gen << "}\n";
  out.commit();
}

// Writes generation after generation into `dir` until killed (runs in the child).
[[noreturn]] inline void rewrite_forever(const std::filesystem::path& dir, int n_files) {
  for (long gen = 1;; ++gen) {
    try {
      write_generation(dir, n_files, gen);
    } catch (...) {
    }
  }
}

inline KillStudy kill_during_replace(const std::filesystem::path& dir, int kills, int n_files, unsigned seed) {
  namespace fs = std::filesystem;
  KillStudy s;
  std::mt19937 rng(seed);
  // A complete folder first (generation 0); every kill then interrupts a re-run. The kill
  // moments spread over three re-runs' time, so they land in every phase of one.
  const auto t0 = std::chrono::steady_clock::now();
  write_generation(dir, n_files, 0);
  const auto one = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0);
  std::uniform_int_distribution<long> wait_us(0, std::max<long>(1000, 3 * one.count()));
  for (int k = 0; k < kills; ++k) {
    const pid_t child = ::fork();
    if (child == 0) rewrite_forever(dir, n_files);
    std::this_thread::sleep_for(std::chrono::microseconds(wait_us(rng)));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    ++s.kills;
    for (const auto& e : fs::directory_iterator(dir.parent_path())) {
      const std::string name = e.path().filename().string();
      if (name.rfind(dir.filename().string() + ".", 0) == 0) ++s.temporaries;
    }
    if (!fs::exists(dir)) {
      ++s.no_folder;
      continue;
    }
    // One complete set: summary.json names the generation, every file holds it.
    const std::string summary = read_all(dir / "summary.json");
    const auto colon = summary.find(':');
    const std::string gen = colon == std::string::npos ? "" : std::to_string(std::atol(summary.c_str() + colon + 1));
    bool ok = !gen.empty();
    int files = 0;
    for (int f = 0; f < n_files && ok; ++f) {
      const fs::path p =
          dir / (f % 3 == 0 ? "steps/part_" + std::to_string(f) + ".csv" : "f" + std::to_string(f) + ".csv");
      const std::string text = read_all(p);
      const std::string expect_first = gen + "," + std::to_string(f) + ",0\n";
      const std::string expect_last = gen + "," + std::to_string(f) + ",199\n";
      ok = text.rfind(expect_first, 0) == 0 && text.size() >= expect_last.size() &&
           text.compare(text.size() - expect_last.size(), expect_last.size(), expect_last) == 0;
      if (ok) ++files;
      if (!ok && s.first_problem.empty())
        s.first_problem = "kill " + std::to_string(k) + ": " + p.string() + " is not of generation " + gen;
    }
    if (ok && files == n_files) ++s.complete;
    if (ok && files == n_files && gen != "0") ++s.replaced;
  }
  // The next writer cleans every temporary of the dead runs.
  { AtomicOutputDir out(dir); }
  for (const auto& e : fs::directory_iterator(dir.parent_path())) {
    const std::string name = e.path().filename().string();
    if (name.rfind(dir.filename().string() + ".", 0) == 0) ++s.left_after_cleaning;
  }
  return s;
}

}  // namespace sf::io::test

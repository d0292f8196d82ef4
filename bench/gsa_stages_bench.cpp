// Times each stage of `gsa analyse` (read, mesh, blunder check, project, fits, noise
// estimates, smoothing choice, strain, write) on a synthetic case (default the dome)
// with 1e4, 1e5 and (with argument "1e6") 1e6 marks over 100 mm, and prints the peak
// resident memory, and the RMS Green-strain error against the exact strains at
// interior marks (digitisation noise 0.002 mm per coordinate unless given).
// A program that prints figures, not a timed test. Wall seconds; the threads used are
// stated (the fits of the smoothing choice and the probe fields use two). The stage times
// overlap (the blank's noise estimate runs beside the deformed blunder check and first
// fit). A second table gives processor seconds between the progress messages (the
// analysis's stages as the progress bar shows them) for the whole process and for the
// main thread: on a loaded machine wall seconds say little, and the larger of the main
// thread's time and half the process's is what the stage would take on two idle cores.
//   build/bin/gsa_stages_bench [max_marks=1e5] [elements_per_side=automatic] [case=dome] [noise_mm=0.002]
//   [noise_blank_mm=noise_mm] (0: an exact blank, the displacement's noise estimate)
#include <sys/resource.h>
#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "common/core/memory.hpp"
#include "common/core/parallel.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/grid_file.hpp"
#include "gsa/accuracy.hpp"
#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"
#include "gsa/output.hpp"
#include "gsa/synthetic.hpp"

using namespace sf;
using namespace sf::gsa;

static double clock_s(clockid_t id) {
  timespec t{};
  clock_gettime(id, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Processor seconds (process, main thread) and wall seconds at a moment.
struct Reading {
  double process = 0, thread = 0, wall = 0;
  static Reading now() {
    return {clock_s(CLOCK_PROCESS_CPUTIME_ID), clock_s(CLOCK_THREAD_CPUTIME_ID), clock_s(CLOCK_MONOTONIC)};
  }
};

static double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

// One row of the processor-time table: process/main-thread seconds per progress stage.
static std::string fmt_cpu(Index marks, const double* process, const double* thread, double write_p, double write_t,
                           double total_p, double total_t) {
  char buf[512];
  int at = std::snprintf(buf, sizeof buf, "%9ld", static_cast<long>(marks));
  auto pair = [&](double p, double t) { at += std::snprintf(buf + at, sizeof buf - at, " %6.2f/%-6.2f", p, t); };
  pair(process[0] + process[1], thread[0] + thread[1]);  // frame, mesh, undeformed blunder check
  for (int s = 2; s < 6; ++s) pair(process[s], thread[s]);
  pair(write_p, write_t);
  pair(total_p, total_t);
  return buf;
}

int main(int argc, char** argv) {
  keep_freed_memory();  // as gsa does (common/core/memory.hpp)
  const double max_marks = argc > 1 ? std::atof(argv[1]) : 1e5;
  const int elements = argc > 2 ? std::atoi(argv[2]) : 0;
  const std::string name = argc > 3 ? argv[3] : "dome";
  const double noise = argc > 4 ? std::atof(argv[4]) : 0.002;
  const double noise_blank = argc > 5 ? std::atof(argv[5]) : noise;
  const auto tmp = std::filesystem::temp_directory_path() / "gsa_stages_bench";
  std::filesystem::create_directories(tmp);
  std::printf("# case %s, noise %g mm per coordinate (blank %g mm), %u hardware threads, %d used\n", name.c_str(),
              noise, noise_blank, std::thread::hardware_concurrency(), default_threads());
  std::printf("%9s %6s %7s %7s %7s %7s %7s %7s %7s %7s %7s %8s %8s %9s\n", "marks", "mesh", "read_s", "mesh_s",
              "outl_s", "proj_s", "fit_s", "noise_s", "choice_s", "strain_s", "write_s", "total_s", "peak_MB",
              "rms_err");
  std::vector<std::string> cpu_rows;
  for (int n : {100, 316, 1000}) {
    if (static_cast<double>(n) * n > max_marks * 1.01) break;
    SyntheticGridOptions go;
    go.n = n;
    go.spacing = 100.0 / (n - 1);
    go.noise = noise;
    std::vector<ExactStrain> exact;
    GridData g0 = make_synthetic_grid(synthetic_case(name), go, &exact);
    if (noise_blank != noise) {  // the blank's own noise: its positions from a grid with that noise
      SyntheticGridOptions gb = go;
      gb.noise = noise_blank;
      g0.undeformed = make_synthetic_grid(synthetic_case(name), gb).undeformed;
    }
    // Write the grid so the read stage is measured on a real file.
    const std::string path = (tmp / "grid.csv").string();
    io::write_grid_file(path, g0);
    const auto t0 = std::chrono::steady_clock::now();
    const GridData g = read_grid(path);
    const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    AnalyseOptions o;
    o.mesh.elements1 = o.mesh.elements2 = elements;  // 0: the automatic mesh
    // Readings at each progress message: (stage, reading); the stages may repeat (mesh refinement).
    std::vector<std::pair<int, Reading>> marks_at;
    const Reading r0 = Reading::now();
    const auto ta = std::chrono::steady_clock::now();
    AnalysisResult r = analyse(g, o, [&](const StageStart& s) {
      marks_at.emplace_back(static_cast<int>(s.stage), Reading::now());
    });
    const double analyse_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - ta).count();
    marks_at.emplace_back(-1, Reading::now());
    const Reading rw = Reading::now();
    r.times.read = read_s;
    {
      io::AtomicOutputDir out((tmp / "out").string());
      write_results(out, g, r, OutputOptions{}, RunInfo{});
      out.commit();
    }
    const Reading rend = Reading::now();
    double process[6] = {}, thread[6] = {};
    for (std::size_t k = 0; k + 1 < marks_at.size(); ++k) {
      const int st = marks_at[k].first;
      process[st] += marks_at[k + 1].second.process - marks_at[k].second.process;
      thread[st] += marks_at[k + 1].second.thread - marks_at[k].second.thread;
    }
    cpu_rows.push_back(fmt_cpu(g.n_points(), process, thread, rend.process - rw.process, rend.thread - rw.thread,
                               rend.process - r0.process, rend.thread - r0.thread));
    const auto& t = r.times;
    // Marks are read back in file order, so the exact strains still line up.
    const StrainError err = strain_error(g, r, exact);
    const double total = t.read + analyse_s + t.write;  // the stages and what lies between them
    std::printf("%9ld %3dx%-3d %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %8.3f %8.1f %9.2e\n",
                static_cast<long>(g.n_points()), r.elements1, r.elements2, t.read, t.mesh, t.outliers, t.project, t.fit,
                t.noise, t.choice, t.strain, t.write, total, peak_mb(), err.rms());
    std::fflush(stdout);
  }
  // Processor seconds, process/main thread, between the progress messages: mesh (frame,
  // mesh, undeformed blunders), undeformed fit (projection, fit; then the deformed blunder
  // check, and the blank's noise estimate beside it), deformed fit (the first one),
  // choice (the deformed noise estimates, smoothing choice, local relaxation, refit),
  // strains; write; total (analyse and write).
  std::printf("# processor seconds, process/main thread\n%9s %13s %13s %13s %13s %13s %13s %13s\n", "marks", "mesh",
              "undef_fit", "def_fit", "noise+choice", "strain", "write", "total");
  for (const std::string& row : cpu_rows) std::printf("%s\n", row.c_str());
  std::filesystem::remove_all(tmp);
  return 0;
}

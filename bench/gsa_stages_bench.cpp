// Times each stage of `gsa analyse` (read, mesh, blunder check, project, fits, noise
// estimates, smoothing choice, strain, write) on a synthetic case (default the dome)
// with 1e4, 1e5 and (with argument "1e6") 1e6 marks over 100 mm, and prints the peak
// resident memory, and the RMS Green-strain error against the exact strains at
// interior marks (digitisation noise 0.002 mm per coordinate unless given).
// A program that prints figures, not a timed test. Wall seconds; the threads used are
// stated (the fits of the smoothing choice and the probe fields use two).
//   build/bin/gsa_stages_bench [max_marks=1e5] [elements_per_side=automatic] [case=dome] [noise_mm=0.002]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "common/core/memory.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/grid_file.hpp"
#include "gsa/accuracy.hpp"
#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"
#include "gsa/output.hpp"
#include "gsa/synthetic.hpp"

using namespace sf;
using namespace sf::gsa;

static double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

int main(int argc, char** argv) {
  keep_freed_memory();  // as gsa does (common/core/memory.hpp)
  const double max_marks = argc > 1 ? std::atof(argv[1]) : 1e5;
  const int elements = argc > 2 ? std::atoi(argv[2]) : 0;
  const std::string name = argc > 3 ? argv[3] : "dome";
  const double noise = argc > 4 ? std::atof(argv[4]) : 0.002;
  const auto tmp = std::filesystem::temp_directory_path() / "gsa_stages_bench";
  std::filesystem::create_directories(tmp);
  std::printf("# case %s, noise %g mm per coordinate, %u hardware threads\n", name.c_str(), noise,
              std::thread::hardware_concurrency());
  std::printf("%9s %6s %7s %7s %7s %7s %7s %7s %7s %7s %7s %8s %8s %9s\n", "marks", "mesh", "read_s", "mesh_s",
              "outl_s", "proj_s", "fit_s", "noise_s", "choice_s", "strain_s", "write_s", "total_s", "peak_MB",
              "rms_err");
  for (int n : {100, 316, 1000}) {
    if (static_cast<double>(n) * n > max_marks * 1.01) break;
    SyntheticGridOptions go;
    go.n = n;
    go.spacing = 100.0 / (n - 1);
    go.noise = noise;
    std::vector<ExactStrain> exact;
    const GridData g0 = make_synthetic_grid(synthetic_case(name), go, &exact);
    // Write the grid so the read stage is measured on a real file.
    const std::string path = (tmp / "grid.csv").string();
    io::write_grid_file(path, g0);
    const auto t0 = std::chrono::steady_clock::now();
    const GridData g = read_grid(path);
    const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    AnalyseOptions o;
    o.mesh.elements1 = o.mesh.elements2 = elements;  // 0: the automatic mesh
    const auto ta = std::chrono::steady_clock::now();
    AnalysisResult r = analyse(g, o);
    const double analyse_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - ta).count();
    r.times.read = read_s;
    {
      io::AtomicOutputDir out((tmp / "out").string());
      write_results(out, g, r, OutputOptions{}, RunInfo{});
      out.commit();
    }
    const auto& t = r.times;
    // Marks are read back in file order, so the exact strains still line up.
    const StrainError err = strain_error(g, r, exact);
    const double total = t.read + analyse_s + t.write;  // the stages and what lies between them
    std::printf("%9ld %3dx%-3d %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %8.3f %8.1f %9.2e\n",
                static_cast<long>(g.n_points()), r.elements1, r.elements2, t.read, t.mesh, t.outliers, t.project, t.fit,
                t.noise, t.choice, t.strain, t.write, total, peak_mb(), err.rms());
    std::fflush(stdout);
  }
  std::filesystem::remove_all(tmp);
  return 0;
}

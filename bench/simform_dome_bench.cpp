// The [0,90]s matched-die dome (data/forming/processes/dome_0_90s.yaml: four molten
// GF/PP plies of 20 x 20 bricks each, quarter model, hemispherical punch 18 mm deep into
// a die) run from flat towards full depth with the case's own solver settings, and where
// the time goes. Prints, per converged step, the punch depth, its force and the Newton
// iterations (from history.csv), then for the whole run:
//   steps / Newton iterations / assemblies / factorisations / solves
//   time per Newton iteration split into
//     elements   brick kernels and their scatter into the tangent pattern
//     contact    contact search, laws, consistent contact tangent and its merge
//     factorise  numeric (and symbolic, when the pattern grows) factorisation
//     solve      triangular solves
//     other      the rest (line search bookkeeping, outputs, set-up)
//   peak resident memory (getrusage high-water mark).
// A program that prints figures, not a timed test.
//   build/bin/simform_dome_bench [--quick] [--elements N] [--max-steps N] [--case FILE]
//   --quick       4 x 4 bricks a ply, 2 of the 36 steps (a smoke test)
//   --elements N  N x N bricks a ply (the mid size: 10)
//   --max-steps N stop cleanly after N steps (the full run can take long)
//   --case FILE   another case (default: the [0,90]s dome)
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "forming/case/reader.hpp"
#include "forming/model/solve_profile.hpp"
#include "forming/run/run.hpp"

using namespace sf;
using namespace sf::forming;

// Processor seconds of the process (user + system, all threads): on a loaded machine
// a steadier measure than the wall clock.
static double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

static double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

int main(int argc, char** argv) {
  std::string file = std::string(SF_SOURCE_DIR) + "/data/forming/processes/dome_0_90s.yaml";
  bool quick = false;
  int max_steps = 0;
  int n_elements = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--max-steps" && i + 1 < argc) {
      max_steps = std::atoi(argv[++i]);
    } else if (a == "--elements" && i + 1 < argc) {
      n_elements = std::atoi(argv[++i]);
      if (n_elements < 1) {
        std::fprintf(stderr, "simform_dome_bench: --elements: expected a count >= 1, found '%s'\n", argv[i]);
        return 2;
      }
    } else if (a == "--case" && i + 1 < argc) {
      file = argv[++i];
    } else {
      std::fprintf(stderr, "usage: simform_dome_bench [--quick] [--elements N] [--max-steps N] [--case FILE]\n");
      return 2;
    }
  }
  try {
    FormingCase spec = load_case(file);
    if (quick) {
      for (CasePly& p : spec.plies) {
        p.n1 = std::min(p.n1, 4);
        p.n2 = std::min(p.n2, 4);
      }
      if (max_steps == 0) max_steps = 2;
    }
    if (n_elements > 0)
      for (CasePly& p : spec.plies) {
        p.n1 = n_elements;
        p.n2 = n_elements;
      }
    int elements = 0;
    for (const CasePly& p : spec.plies) elements += p.n1 * p.n2;
    std::printf("case %s%s: %zu plies, %d bricks, %zu contact pairs, %d steps requested%s\n", file.c_str(),
                quick ? " (--quick: at most 4 x 4 bricks a ply)" : "", spec.plies.size(), elements,
                spec.contacts.size(), spec.solver.steps,
                max_steps > 0 ? (", stopping after " + std::to_string(max_steps)).c_str() : "");
    std::fflush(stdout);
    // One folder per process: runs side by side (sizes, orderings) do not collide.
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("sf_simform_dome_bench_" + std::to_string(getpid()));
    std::filesystem::remove_all(dir);
    RunOptions o;
    o.out_dir = dir.string();
    o.quiet = false;  // simform's step lines on stderr: progress on a long run
    o.stop_after = max_steps;
    solve_profile().reset();
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    const RunReport r = run_case(spec, o);
    const double cpu = cpu_seconds() - cpu0;
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const SolveProfile p = solve_profile();

    const io::CsvTable h = io::read_csv((dir / "history.csv").string());
    const auto col = [&](const char* name) { return h.column_index(name); };
    std::printf("%5s %10s %18s %7s %9s\n", "step", "punch_uz", "punch_fz", "newton", "cutbacks");
    for (std::size_t row = 1; row < h.n_rows(); ++row)
      std::printf("%5zu %10.4f %18.12g %7s %9s\n", row, std::stod(std::string(h.cell(row, col("punch_uz")))),
                  std::stod(std::string(h.cell(row, col("punch_fz")))),
                  std::string(h.cell(row, col("newton_iterations"))).c_str(),
                  std::string(h.cell(row, col("cutbacks"))).c_str());
    const double n_it = std::max(1, r.total_iterations);
    const double other = total - p.elements_s - p.contact_s - p.factorize_s - p.solve_s;
    std::printf("status %s: %d steps, %d Newton iterations, %ld assemblies, %ld factorisations, %ld solves\n",
                r.ok() ? "ok" : "not converged", r.steps_converged, r.total_iterations, p.assemblies, p.factorizations,
                p.solves);
    if (!r.ok()) std::printf("message: %s\n", r.message.c_str());
    std::printf("largest displacement (x, y, z) %.12g %.12g %.12g mm\n", r.max_displacement.x(), r.max_displacement.y(),
                r.max_displacement.z());
    std::printf(
        "total %.2f s; per Newton iteration: elements %.4f s, contact %.4f s, factorise %.4f s, solve %.4f s, "
        "other %.4f s\n",
        total, p.elements_s / n_it, p.contact_s / n_it, p.factorize_s / n_it, p.solve_s / n_it, other / n_it);
    std::printf("processor time %.2f s (user + system, all threads; wall %.2f s)\n", cpu, total);
    std::printf("shares: elements %.0f %%, contact %.0f %%, factorise %.0f %%, solve %.0f %%, other %.0f %%\n",
                100 * p.elements_s / total, 100 * p.contact_s / total, 100 * p.factorize_s / total,
                100 * p.solve_s / total, 100 * other / total);
    std::printf(
        "contact: evaluation (search, laws, local tangents) %.4f s, merge into the pattern %.4f s per "
        "iteration; %.0f entries merged per assembly\n",
        p.contact_eval_s / n_it, p.contact_merge_s / n_it,
        static_cast<double>(p.contact_entries) / std::max(1L, p.assemblies));
    std::printf("linear: %s\n", solve_profile_linear_summary(p).c_str());
    std::printf("peak memory %.0f MB\n", peak_mb());
    std::filesystem::remove_all(dir);
    return r.ok() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simform_dome_bench: %s\n", e.what());
    return 1;
  }
}

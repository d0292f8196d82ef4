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
//   peak resident memory (getrusage high-water mark), the threads (element loop, BLAS),
//   pattern growths (each a new symbolic analysis) and, for the iterative solver, the
//   GMRES iterations and residuals; and, per ply, the forming results at the last
//   converged step (summary.json: trellis shear angle to the partner ply, in-ply shear,
//   fibre stretch: min .. max).
// A program that prints figures, not a timed test.
//   build/bin/simform_dome_bench [--quick] [--elements N] [--max-steps N] [--case FILE]
//                                [--ordering amd|metis|nesdis|default] [--factor-only] [--time-limit S]
//   --quick       4 x 4 bricks a ply, 2 of the 36 steps (a smoke test)
//   --elements N  N x N bricks a ply (the mid size: 10)
//   --max-steps N stop cleanly after N steps (the full run can take long)
//   --keep DIR    write the run's results into DIR and keep them (frames, history.csv,
//                 summary.json: `simform plot DIR` draws the pictures); default: a
//                 temporary folder, removed at the end
//   --case FILE   another case (default: the [0,90]s dome)
//   --stabilise F solver: {stabilise: {fraction: F}} (viscous stabilisation, calibrated from step 1)
//   --damping C   solver: {stabilise: {damping: C}} (the damping factor given, N s/mm^4, from
//                 step 1 on, as in dome_isotropic.yaml); the step table then shows the
//                 dissipated fraction of the strain energy
//   --ordering O  fill-reducing ordering of the Newton tangent's solver (default: the
//                 solvers' own choice; forming/solve/tangent_solver.hpp)
//   --time-limit S  after S seconds print the figures so far (a snapshot taken while the
//                 solve runs) and stop with status 3: a size that does not finish a step
//                 still reports where its time went
//   --linear M    the Newton tangent's linear solver: direct, iterative, iterative-ply or
//                 auto (the case key solver: {linear: M}; forming/solve/tangent_solver.hpp)
//   --iterative   no run: the start tangent solved by the direct path and by GMRES with
//                 the per-ply preconditioner (iterations, residuals, times)
//   --no-band-pattern  a growing tangent pattern takes only the contact entries present
//                 (the old behaviour), not every pair within the search band
//   --factor-only no run: the tangent of the flat start (contact pattern included: the
//                 plies touch and the die and holder touch the stack) factorised by each
//                 direct solver and ordering, printing nnz, fill, flops and seconds (the
//                 numeric factorisation is repeated with the analysis kept, timed in processor
//                 seconds of all threads) and one solve of a random right-hand side
//                 (|Kx-b|/|b|; neg: negative pivots of MUMPS's LDL^T, the tangent's inertia)
//   --solvers K,K with --factor-only: only these kinds (umfpack, cholmod, cholmod-ldlt, mumps,
//                 mumps-ldlt); --ordering O: only that ordering
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>

#include "common/core/error.hpp"
#include "common/core/parallel.hpp"
#include "common/io/csv.hpp"
#include "common/core/memory.hpp"
#include "common/io/json.hpp"
#include "common/linalg/krylov.hpp"
#include "common/linalg/solver.hpp"
#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/contact/surface_contact.hpp"
#include "forming/solve/tangent_solver.hpp"
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

// Processor seconds of the calling thread.
static double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The per-iteration split and the linear-algebra line from a profile.
static void print_split(const SolveProfile& p, double total, double cpu, long iterations) {
  const double n_it = static_cast<double>(std::max(1L, iterations));
  const double other = total - p.elements_s - p.contact_s - p.factorize_s - p.solve_s;
  std::printf(
      "total %.2f s; per Newton iteration: elements %.4f s, contact %.4f s, factorise %.4f s, solve %.4f s, "
      "other %.4f s\n",
      total, p.elements_s / n_it, p.contact_s / n_it, p.factorize_s / n_it, p.solve_s / n_it, other / n_it);
  std::printf("processor time %.2f s (user + system, all threads; wall %.2f s)\n", cpu, total);
  std::printf("shares: elements %.0f %%, contact %.0f %%, factorise %.0f %%, solve %.0f %%, other %.0f %%\n",
              100 * p.elements_s / total, 100 * p.contact_s / total, 100 * p.factorize_s / total,
              100 * p.solve_s / total, 100 * other / total);
  std::printf(
      "contact: evaluation (search, laws, local tangents, their entries into the kept pattern) %.4f s, merge of "
      "triplets and pattern growth %.4f s per iteration; %.0f stiffness entries per assembly\n",
      p.contact_eval_s / n_it, p.contact_merge_s / n_it,
      static_cast<double>(p.contact_entries) / static_cast<double>(std::max(1L, p.assemblies)));
  std::printf("linear: %s\n", solve_profile_linear_summary(p).c_str());
  std::printf("pattern: %ld growths (each a new symbolic analysis), %.3f s laying out the search band (%s)\n",
              p.pattern_growths, p.band_layout_s, Model::band_pattern() ? "band pattern on" : "--no-band-pattern");
  std::printf("peak memory %.0f MB\n", peak_mb());
}

// Per ply, the forming results of the last converged step from summary.json (docs/forming.md
// "Forming results"): trellis shear angle against the partner ply, in-ply shear angle and
// fibre stretch, each min .. max. Nothing when the run wrote no summary.
static void print_forming_results(const std::filesystem::path& summary) {
  if (!std::filesystem::exists(summary)) return;
  try {
    const nlohmann::json j = io::read_json(summary.string());
    if (!j.contains("forming") || !j["forming"].contains("plies")) return;
    // Angles to 1e-3 degrees, the stretch to 1e-5 (near-inextensible fibres: 0.999 .. 1.001).
    const auto range = [](const nlohmann::json& ply, const char* key, char* out, std::size_t size) {
      const bool stretch = std::string(key) == "fibre_stretch";
      if (ply.contains(key) && ply[key].contains("min") && ply[key]["min"].is_number())
        std::snprintf(out, size, stretch ? "%8.5f .. %-8.5f" : "%8.3f .. %-8.3f", ply[key]["min"].get<double>(),
                      ply[key]["max"].get<double>());
      else
        std::snprintf(out, size, "%20s", "-");
    };
    std::printf("forming results at the last converged step (min .. max):\n%-8s %-8s %-20s %-20s %-20s\n", "ply",
                "partner", "trellis_shear_deg", "ply_shear_deg", "fibre_stretch");
    for (const nlohmann::json& ply : j["forming"]["plies"]) {
      char trellis[64], shear[64], stretch[64];
      range(ply, "trellis_shear_angle_deg", trellis, sizeof trellis);
      range(ply, "ply_shear_angle_deg", shear, sizeof shear);
      range(ply, "fibre_stretch", stretch, sizeof stretch);
      const std::string partner =
          ply.contains("trellis_partner") && ply["trellis_partner"].is_string() ? ply["trellis_partner"].get<std::string>()
                                                                                 : "-";
      std::printf("%-8s %-8s %s %s %s\n", ply.value("ply", std::string("?")).c_str(), partner.c_str(), trellis, shear,
                  stretch);
    }
  } catch (const std::exception& e) {
    std::printf("forming results: %s unreadable (%s)\n", summary.string().c_str(), e.what());
  }
}

// Random numbers in [-1, 1], the same on every run.
static Eigen::VectorXd fixed_random(Index n) {
  Eigen::VectorXd v(n);
  std::uint64_t state = 0x9e3779b97f4a7c15ULL;
  for (Index i = 0; i < n; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    v(i) = static_cast<double>(state >> 11) / static_cast<double>(1ULL << 52) - 1.0;
  }
  return v;
}

// --iterative: the start tangent solved by the direct path and by GMRES with the per-ply
// preconditioner (forming/solve/tangent_solver.hpp), both storages, for a random
// right-hand side and for K times a smooth field; prints times, iterations, residuals and
// the difference of the solutions.
static void compare_iterative(const Model& model, linalg::PatternAssembler& pa, bool unsymmetric) {
  const linalg::SparseMatrix& k = pa.matrix();
  const Index n = k.rows();
  const std::vector<int> group = ply_groups(model, pa.active_dofs());
  const linalg::Storage storage = pa.storage();
  Eigen::MatrixXd b(n, 2);
  b.col(0) = fixed_random(n);
  {
    // K u for u a smooth field: each unknown's value a slow sine of its index.
    Eigen::VectorXd u(n), ku(n);
    for (Index i = 0; i < n; ++i) u(i) = std::sin(6.0 * static_cast<double>(i) / static_cast<double>(n));
    linalg::multiply(k, storage, u, ku);
    b.col(1) = ku;
  }
  const char* label = storage == linalg::Storage::kLower ? "lower (symmetric)" : "full (unsymmetric)";
  std::vector<Eigen::MatrixXd> solutions;
  for (LinearMode mode : {LinearMode::kDirect, LinearMode::kIterativePly}) {
    solve_profile().reset();
    TangentSolver solver(linalg::SolverKind::kAuto, unsymmetric, mode, group);
    const double w0 = thread_cpu_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    const linalg::SolveReport r = solver.factorize(k);
    const double f_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double f_cpu = thread_cpu_seconds() - w0;
    const double factor_nnz = solve_profile().factor_nnz, factor_flops = solve_profile().factor_flops;
    if (!r.ok()) {
      std::printf("%-20s %-10s factorisation failed: %s\n", label, to_string(mode).c_str(), r.brief().c_str());
      return;
    }
    // The numeric factorisation again with the analysis kept (a Newton iteration's cost).
    const auto t1 = std::chrono::steady_clock::now();
    const double w1 = thread_cpu_seconds();
    if (mode == LinearMode::kDirect) solver.factorize(k);
    const double f2_wall = mode == LinearMode::kDirect
                               ? std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count()
                               : f_wall;
    const double f2_cpu = mode == LinearMode::kDirect ? thread_cpu_seconds() - w1 : f_cpu;
    const auto t2 = std::chrono::steady_clock::now();
    const double w2 = thread_cpu_seconds();
    const Eigen::MatrixXd x = solver.solve(b);
    const double s_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count();
    const double s_cpu = thread_cpu_seconds() - w2;
    double worst = 0.0;
    for (Index c = 0; c < b.cols(); ++c) {
      Eigen::VectorXd kx(n);
      linalg::multiply(k, storage, x.col(c), kx);
      worst = std::max(worst, (kx - b.col(c)).norm() / b.col(c).norm());
    }
    const SolveProfile& p = solve_profile();
    std::printf(
        "%-20s %-10s first factorise %.3f s (%.3f cpu), again %.3f s (%.3f cpu), 2 solves %.3f s (%.3f cpu), "
        "|Kx-b|/|b| %.2g",
        label, to_string(mode).c_str(), f_wall, f_cpu, f2_wall, f2_cpu, s_wall, s_cpu, worst);
    if (mode == LinearMode::kIterativePly)
      std::printf(", GMRES iterations %ld (%ld solves), fallbacks %ld, preconditioner nnz(factor) %.4g (%.3g Gflop)",
                  p.krylov_iterations, p.krylov_solves, p.direct_fallbacks, factor_nnz, factor_flops * 1e-9);
    else
      std::printf(", nnz(factor) %.4g (%.3g Gflop, %s)", factor_nnz, factor_flops * 1e-9, p.solver.c_str());
    solutions.push_back(x);
    if (solutions.size() == 2)
      std::printf(", |x_it - x_direct|/|x_direct| %.2g",
                  (solutions[1] - solutions[0]).norm() / std::max(1e-300, solutions[0].norm()));
    std::printf("\n");
    std::fflush(stdout);
  }
}

// --factor-only: the start tangent through each solver and ordering.
static int factor_only(const FormingCase& spec, bool iterative, const std::string& solvers) {
  const Problem problem = build_problem(spec);
  const Model& model = problem.model;
  const VecX x = model.reference_positions();
  std::vector<bool> is_free = model.used_dofs();
  for (const PrescribedDof& p : problem.prescriptions.at(1.0 / std::max(1, spec.solver.steps)))
    is_free[static_cast<std::size_t>(p.dof)] = false;
  InteractionContext context;
  context.previous = &x;  // quasi-static rates over the first step (zero here: the pattern counts)
  context.time = spec.solver.process_time / std::max(1, spec.solver.steps);
  linalg::PatternAssembler full = model.make_pattern(is_free, false);
  linalg::PatternAssembler lower = model.make_pattern(is_free, true);
  for (linalg::PatternAssembler* pa : {&full, &lower}) {
    const Assembly a = model.assemble_into(x, context, pa);
    if (!a.ok) {
      std::fprintf(stderr, "simform_dome_bench: start tangent: %s\n", a.message.c_str());
      return 1;
    }
  }
  std::printf("start tangent: n %ld, nnz %ld (both triangles), %ld (lower); %s\n", static_cast<long>(full.n_active()),
              static_cast<long>(full.matrix().nonZeros()), static_cast<long>(lower.matrix().nonZeros()),
              linalg::blas_description().c_str());
  if (iterative) {
    // How unsymmetric the tangent is (viscous slip, two-pass contact): |K - K^T| / |K|.
    const linalg::SparseMatrix kt = full.matrix().transpose();
    std::printf("asymmetry |K - K^T|_F / |K|_F = %.3g\n",
                linalg::SparseMatrix(full.matrix() - kt).norm() / full.matrix().norm());
    compare_iterative(model, full, true);
    compare_iterative(model, lower, false);
    return 0;
  }
  std::printf("%-12s %-8s %-30s %12s %7s %9s %10s %10s %10s %10s %9s %6s %s\n", "solver", "ordering", "ordering used",
              "nnz(factor)", "fill", "Gflop", "analyse_s", "factor_s", "factor_cpu", "solve_cpu", "|Kx-b|/|b|", "neg",
              "status");
  using linalg::Ordering;
  using linalg::SolverKind;
  struct Trial {
    SolverKind kind;
    linalg::MatrixProperty property;
    bool use_lower;
  };
  const Trial trials[] = {
      {SolverKind::kUmfpack, linalg::MatrixProperty::kUnsymmetric, false},
      {SolverKind::kCholmod, linalg::MatrixProperty::kSymmetricPositiveDefinite, true},
      {SolverKind::kCholmodLdlt, linalg::MatrixProperty::kSymmetricIndefinite, true},
      {SolverKind::kMumps, linalg::MatrixProperty::kUnsymmetric, false},
      {SolverKind::kMumpsLdlt, linalg::MatrixProperty::kSymmetricIndefinite, true},
  };
  const Eigen::VectorXd b = fixed_random(full.n_active());
  for (const Trial& t : trials) {
    if (!linalg::solver_available(t.kind)) {
      std::printf("%-12s not in this build\n", linalg::to_string(t.kind).c_str());
      continue;
    }
    if (!solvers.empty() && solvers.find("," + linalg::to_string(t.kind) + ",") == std::string::npos) continue;
    for (Ordering o : {Ordering::kDefault, Ordering::kAmd, Ordering::kMetis, Ordering::kNesdis}) {
      if (TangentSolver::default_ordering() != Ordering::kDefault && o != TangentSolver::default_ordering()) continue;
      const bool cholmod = t.kind == SolverKind::kCholmod || t.kind == SolverKind::kCholmodLdlt;
      if (!cholmod && o == Ordering::kNesdis) continue;  // METIS stands in for it
      if (t.kind == SolverKind::kCholmodLdlt && full.n_active() > 20000) {
        // Simplicial (no BLAS): 6-10 processor seconds a factorisation at 10.6k unknowns.
        std::printf("%-12s %-8s skipped above 20000 unknowns (simplicial: minutes)\n", "cholmod-ldlt",
                    linalg::to_string(o).c_str());
        continue;
      }
      linalg::LinearSolver solver(t.kind, t.property);
      solver.set_ordering(o);
      const linalg::SparseMatrix& k = t.use_lower ? lower.matrix() : full.matrix();
      const linalg::SolveReport first = solver.factorize(k);
      const double c0 = cpu_seconds();
      const linalg::SolveReport& r = solver.factorize(k);  // the analysis kept: a Newton iteration's cost
      const double cpu = cpu_seconds() - c0;
      double residual = std::numeric_limits<double>::quiet_NaN(), solve_cpu = 0.0;
      if (r.ok()) {
        const double c1 = cpu_seconds();
        const Eigen::MatrixXd sol = solver.solve(b);
        solve_cpu = cpu_seconds() - c1;
        residual = solver.residual(b, sol).norm() / b.norm();
      }
      std::printf("%-12s %-8s %-30s %12.4g %7.1f %9.3f %10.3f %10.3f %10.3f %10.3f %9.2g %6d %s\n",
                  linalg::to_string(t.kind).c_str(), linalg::to_string(o).c_str(), first.ordering.c_str(),
                  r.factor_nonzeros, r.factor_nonzeros / static_cast<double>(k.nonZeros()), r.factor_flops * 1e-9,
                  first.analyze_seconds, r.factor_seconds, cpu, solve_cpu, residual, r.negative_pivots,
                  r.ok() ? "ok" : (linalg::to_string(r.status) + ": " + r.message).c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  // Freed factorisation memory kept for reuse (common/core/memory.hpp), at start-up as in
  // every program that factorises; GLIBC_TUNABLES=glibc.malloc... restores glibc's default.
  const bool kept = keep_freed_memory();
  std::string file = std::string(SF_SOURCE_DIR) + "/data/forming/processes/dome_0_90s.yaml";
  bool quick = false;
  int max_steps = 0;
  int n_elements = 0;
  bool only_factor = false;
  bool iterative = false;
  std::string linear;
  std::string solvers;  // --solvers: ",kind,kind," (empty: all)
  std::string keep;     // --keep DIR: the results folder, kept
  double time_limit = 0.0;
  double stabilise = 0.0;
  double damping = 0.0;
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
    } else if (a == "--ordering" && i + 1 < argc) {
      try {
        TangentSolver::set_default_ordering(linalg::parse_ordering(argv[++i], "--ordering"));
      } catch (const std::exception& e) {
        std::fprintf(stderr, "simform_dome_bench: %s\n", e.what());
        return 2;
      }
    } else if (a == "--time-limit" && i + 1 < argc) {
      time_limit = std::atof(argv[++i]);
      if (!(time_limit > 0.0)) {
        std::fprintf(stderr, "simform_dome_bench: --time-limit: expected seconds > 0, found '%s'\n", argv[i]);
        return 2;
      }
    } else if (a == "--factor-only") {
      only_factor = true;
    } else if (a == "--iterative") {
      only_factor = true;
      iterative = true;
    } else if (a == "--no-band-pattern") {
      Model::set_band_pattern(false);
    } else if (a == "--solvers" && i + 1 < argc) {
      solvers = std::string(",") + argv[++i] + ",";
    } else if (a == "--linear" && i + 1 < argc) {
      linear = argv[++i];
    } else if (a == "--case" && i + 1 < argc) {
      file = argv[++i];
    } else if (a == "--keep" && i + 1 < argc) {
      keep = argv[++i];
    } else if (a == "--stabilise" && i + 1 < argc) {
      stabilise = std::atof(argv[++i]);
      if (!(stabilise > 0.0 && stabilise < 1.0)) {
        std::fprintf(stderr, "simform_dome_bench: --stabilise: expected a fraction in (0, 1), found '%s'\n", argv[i]);
        return 2;
      }
    } else if (a == "--damping" && i + 1 < argc) {
      damping = std::atof(argv[++i]);
      if (!(damping > 0.0 && std::isfinite(damping))) {
        std::fprintf(stderr, "simform_dome_bench: --damping: expected a damping factor > 0 (N s/mm^4), found '%s'\n",
                     argv[i]);
        return 2;
      }
    } else {
      std::fprintf(stderr,
                   "usage: simform_dome_bench [--quick] [--elements N] [--max-steps N] [--case FILE] [--ordering O] "
                   "[--factor-only [--solvers K,K] | --iterative] [--linear direct|iterative|iterative-ply|auto] "
                   "[--no-band-pattern] [--time-limit S] [--stabilise FRACTION | --damping C] [--keep DIR]\n");
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
    std::printf("threads: %d for the element loop (OpenMP; SF_THREADS), factorisation BLAS: %s; freed memory %s\n",
                sf::default_threads(), linalg::blas_description().c_str(),
                kept ? "kept for reuse (mallopt)" : "returned to the system (malloc tuned by the environment)");
    std::fflush(stdout);
    if (!linear.empty()) spec.solver.linear = to_string(parse_linear_mode(linear, "--linear"));
    if (stabilise > 0.0) {  // solver: {stabilise: {fraction: F}} (forming/solve/stabilisation.hpp)
      spec.solver.stabilise_fraction = stabilise;
      spec.solver.stabilise_damping = 0.0;
    }
    if (damping > 0.0) {  // solver: {stabilise: {damping: C}}
      spec.solver.stabilise_fraction = 0.0;
      spec.solver.stabilise_damping = damping;
    }
    if (only_factor) return factor_only(spec, iterative, solvers);
    // One folder per process: runs side by side (sizes, orderings) do not collide.
    const std::filesystem::path dir =
        keep.empty() ? std::filesystem::temp_directory_path() / ("sf_simform_dome_bench_" + std::to_string(getpid()))
                     : std::filesystem::path(keep);
    if (keep.empty()) std::filesystem::remove_all(dir);
    RunOptions o;
    o.out_dir = dir.string();
    o.quiet = false;  // simform's step lines on stderr: progress on a long run
    o.stop_after = max_steps;
    solve_profile().reset();
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    if (time_limit > 0.0) {
      // A watchdog: the profile is read while the solve writes it (a benchmark's snapshot).
      std::thread([time_limit, t0, cpu0] {
        std::this_thread::sleep_for(std::chrono::duration<double>(time_limit));
        const SolveProfile snapshot = solve_profile();
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("time limit %.0f s reached before the run ended; figures so far (%ld factorisations):\n",
                    time_limit, snapshot.factorizations);
        print_split(snapshot, wall, cpu_seconds() - cpu0, snapshot.factorizations);
        std::printf("contact state changes: %ld (points whose state changed between tangent assemblies)\n",
                    contact_state_flips());
        std::fflush(stdout);
        std::_Exit(3);
      }).detach();
    }
    const RunReport r = run_case(spec, o);
    const double cpu = cpu_seconds() - cpu0;
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const SolveProfile p = solve_profile();

    const io::CsvTable h = io::read_csv((dir / "history.csv").string());
    const auto col = [&](const char* name) { return h.column_index(name); };
    const bool stabilised = h.has_column("stabilisation_ratio");
    // The blank holder's force along z (N; positive: the plies push it up): what the
    // holder's closure (dome_*.yaml) presses the flange with.
    const bool holder = h.has_column("holder_fz");
    std::printf("%5s %10s %18s %7s %9s%s%s\n", "step", "punch_uz", "punch_fz", "newton", "cutbacks",
                holder ? "  holder_fz" : "", stabilised ? "  stabilisation_ratio" : "");
    for (std::size_t row = 1; row < h.n_rows(); ++row) {
      char holder_cell[32] = "";
      if (holder)
        std::snprintf(holder_cell, sizeof holder_cell, "  %9.4f", std::stod(std::string(h.cell(row, col("holder_fz")))));
      std::printf("%5zu %10.4f %18.12g %7s %9s%s%s\n", row, std::stod(std::string(h.cell(row, col("punch_uz")))),
                  std::stod(std::string(h.cell(row, col("punch_fz")))),
                  std::string(h.cell(row, col("newton_iterations"))).c_str(),
                  std::string(h.cell(row, col("cutbacks"))).c_str(), holder_cell,
                  stabilised ? ("  " + std::string(h.cell(row, col("stabilisation_ratio")))).c_str() : "");
    }
    std::printf("status %s: %d steps, %d Newton iterations, %ld assemblies, %ld factorisations, %ld solves\n",
                r.ok() ? "ok" : "not converged", r.steps_converged, r.total_iterations, p.assemblies, p.factorizations,
                p.solves);
    if (!r.ok()) std::printf("message: %s\n", r.message.c_str());
    // Contact points whose state (normal: open / band / closed / out of reach; the viscous
    // layer) changed between consecutive tangent assemblies: Newton converges quadratically
    // only once these stop (SF_NEWTON_TRACE=1 lists where, forming/contact/surface_contact.hpp).
    std::printf("contact state changes: %ld, %.1f a factorisation\n", contact_state_flips(),
                static_cast<double>(contact_state_flips()) / std::max<long>(1, p.factorizations));
    std::printf("largest displacement (x, y, z) %.12g %.12g %.12g mm\n", r.max_displacement.x(), r.max_displacement.y(),
                r.max_displacement.z());
    print_split(p, total, cpu, r.total_iterations);
    print_forming_results(dir / "summary.json");
    if (keep.empty())
      std::filesystem::remove_all(dir);
    else
      std::printf("results kept in %s (simform plot %s draws the pictures)\n", dir.string().c_str(),
                  dir.string().c_str());
    return r.ok() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simform_dome_bench: %s\n", e.what());
    return 1;
  }
}

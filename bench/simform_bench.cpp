// Cost of one Newton iteration of the forming solver, piece by piece, on flat plies, and
// the Newton iterations of the shear-and-stretch ply. A program that prints figures, not
// a timed test.
//
//   build/bin/simform_bench [max_elements_per_side=40] [repeats=3]
//   build/bin/simform_bench --factorisation N PLIES [repeats]   (orderings, CHOLMOD variants)
//   build/bin/simform_bench --case N PLIES [repeats]            (one line of the table)
//   build/bin/simform_bench --kernel N PLIES [rounds]           (the brick kernel alone, one thread)
//   build/bin/simform_bench --shear-stretch CASE.yaml [N]   (N: N x N elements instead of the file's)
//   --lu KIND (with any of the above): the tangent stored with both triangles and factorised
//   as an unsymmetric tangent is (forming/solve/tangent_solver.hpp): auto (MUMPS's LU, checked,
//   UMFPACK without MUMPS) or umfpack; the Newton tangents of the static solves stay symmetric
//
// For n x n bricks per ply (n = 10, 20, 40) and 1 or 4 plies (100 x 100 x 0.25 mm,
// compressible transversely isotropic law, fibres 0/90/0/90, stacked as separate bodies:
// no contact yet, so the 4-ply system is block diagonal), each case runs in its own
// process (so that its peak memory is its own) and prints one line:
//   n_dofs, n_free   unknowns, and those left free by the grips (every parameter of the
//                    nodes at x = 0 and x = L prescribed: a uniaxial 5 % stretch)
//   layout_s         laying out the free-unknown pattern and the element scatter tables,
//                    and ordering it for the Cholesky (TangentSolver::lay_out; once per model)
//   kernel_s         the element kernels alone (force + tangent, all bricks, threaded)
//   scatter_s        the rest of an assembly with the tangent: writing into the pattern
//   resid_s          an assembly of the force only (the line search's trial)
//   fact_s           numeric factorisation of K_ff (symbolic analysis kept; analyse_s once,
//                    the supernodal analysis: the ordering is in layout_s)
//   solve_s          one forward/back substitution
//   iter_s           kernel + scatter + residual + factorisation + solve: one Newton iteration
//   kern_GF, fact_GF GFLOP/s of the kernel (flops counted from the algorithm,
//                    BrickKernel::tangent_flops) and of the factorisation (CHOLMOD's count)
//   kern_%           the kernel's share of a core's double-precision peak: every brick
//                    once on one thread, on that thread's processor clock, against
//                    linalg::fma_peak_gflops on the same thread (independent of the load;
//                    the two cores' share is this when the element loop scales, as
//                    kernel_s shows)
//   newton, static_s Newton iterations and wall time of the whole static solve (stretch
//                    in two load steps sharing one TangentWorkspace, as a run's steps do)
//   layouts          times the pattern was laid out in that solve (1: kept across steps)
//   iter_MB          peak resident memory of the case's process up to the end of the timed
//                    iteration (model, pattern, factor, solve)
//   peak_MB          peak resident memory of the whole case (the timed iteration's pattern
//                    and solver are freed before the static solve, which lays out its own)
// Times are medians over `repeats` repetitions, wall clock, seconds. The first line says
// how many threads the element loop uses and which vector instructions the kernel runs.
//
// Then the shear-and-stretch ply (bench/cases/shear_stretch_ply.yaml: 200 mm square ply,
// 40 x 40 elements, fibres at 30 degrees, clamped on x0, x1 moved 4 mm across and 2 mm
// along in two load steps): Newton iterations and cut-backs per step, and time.
#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <omp.h>

#include "common/core/memory.hpp"
#include "common/core/parallel.hpp"
#include "common/linalg/dense_kernels.hpp"
#include "common/linalg/solver.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/solve/static_solver.hpp"
#include "forming/solve/stepper.hpp"
#include "forming/solve/tangent_solver.hpp"

using namespace sf;
using namespace sf::forming;

namespace {

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

// A field of /proc/self/status in MB (VmRSS, VmHWM), -1 when not there (not Linux).
double status_mb(const char* field) {
  FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return -1.0;
  char line[256];
  double mb = -1.0;
  const std::size_t len = std::strlen(field);
  while (std::fgets(line, sizeof line, f))
    if (std::strncmp(line, field, len) == 0 && line[len] == ':') mb = std::atof(line + len + 1) / 1024.0;
  std::fclose(f);
  return mb;
}

// Resets the kernel's peak resident memory (VmHWM) to the current one: each stage of
// --memory then reports its own peak. False when the kernel does not allow it.
bool reset_peak() {
  FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

// Heap bytes malloc has handed out and not had back, MB (glibc).
double heap_in_use_mb() {
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
  const struct mallinfo2 m = mallinfo2();
  return (m.uordblks + m.hblkhd) / 1048576.0;
#else
  return -1.0;
#endif
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <class F>
double median_time(int repeats, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(seconds_since(t0));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

constexpr double kL = 100.0, kH = 0.25, kStretch = 1.05;

TransverselyIsotropicParams ply_law() {
  TransverselyIsotropicParams tp;
  tp.mu_T = 1.0;
  tp.mu_L = 2.0;
  tp.kappa_f = 500.0;
  tp.incompressible = false;
  tp.lambda = 10.0;
  return tp;
}

// Factorisations of K_ff of one case by ordering and CHOLMOD variant: flops, time, GFLOP/s.
void factorisation_study(const linalg::SparseMatrix& k, int repeats) {
  std::printf("# factorisation of K_ff (n %ld, nnz of the lower triangle %ld) by ordering; BLAS: %s\n",
              static_cast<long>(k.rows()), static_cast<long>(k.nonZeros()), linalg::blas_description().c_str());
  std::printf("%-20s %-8s %9s %9s %9s %8s\n", "solver", "ordering", "analyse_s", "GFLOP", "fact_s", "GFLOP/s");
  for (linalg::SolverKind kind : {linalg::SolverKind::kCholmod, linalg::SolverKind::kCholmodSimplicial})
    for (linalg::Ordering o :
         {linalg::Ordering::kDefault, linalg::Ordering::kAmd, linalg::Ordering::kMetis, linalg::Ordering::kNesdis}) {
      linalg::LinearSolver solver(kind, linalg::MatrixProperty::kSymmetricPositiveDefinite);
      solver.set_ordering(o);
      const linalg::SolveReport first = solver.factorize(k);
      if (!first.ok()) {
        std::printf("%-20s %-8s failed: %s\n", linalg::to_string(kind).c_str(), linalg::to_string(o).c_str(),
                    first.brief().c_str());
        continue;
      }
      const double fact_s = median_time(repeats, [&] { solver.factorize(k); });
      std::printf("%-20s %-8s %9.3f %9.2f %9.3f %8.2f\n", linalg::to_string(kind).c_str(), linalg::to_string(o).c_str(),
                  first.analyze_seconds, first.factor_flops / 1e9, fact_s, first.factor_flops / fact_s / 1e9);
      std::fflush(stdout);
    }
}

// --lu KIND: the tangent stored with both triangles and factorised as an unsymmetric one
// would be (TangentSolver(KIND, unsymmetric)): "auto" (MUMPS's LU, UMFPACK without MUMPS)
// or "umfpack". Empty: the symmetric path (Cholesky).
std::string g_lu;

// The stretched plies of one case: the model, the grips and a deformed state.
struct Setup {
  Model model;
  VecX X, x;
  std::vector<PrescribedDof> bcs;
  std::vector<bool> is_free;
};

void make_setup(int n, int plies, Setup& setup) {
  Model& model = setup.model;
  for (int k = 0; k < plies; ++k) {
    PlyMesh ply(mesh::make_rectangle_mesh(Vec3(0.0, 0.0, k * kH), Vec3::UnitX(), Vec3::UnitY(), kL, kL, n, n), kH,
                k % 2 == 0 ? 0.0 : 90.0);
    auto material = std::make_shared<TransverselyIsotropic>(ply_law(), ply.fibre_direction());
    model.add_ply(std::move(ply), material);
  }
  const Index nd = model.n_dofs();
  const VecX& X = setup.X = model.reference_positions();
  // Grips: every parameter of the nodes at x = 0 (held) and x = L (x -> 1.05 x).
  std::vector<PrescribedDof>& bcs = setup.bcs;
  std::vector<bool>& is_free = setup.is_free;
  is_free.assign(static_cast<std::size_t>(nd), true);
  VecX target = X;
  for (int b = 0; b < model.n_bodies(); ++b) {
    const PlyMesh& ply = model.ply(b);
    for (Index s = 0; s < ply.n_surface_nodes(); ++s) {
      const double xs = ply.surface().node_position(s).x();
      const bool left = std::abs(xs) < 1e-9, right = std::abs(xs - kL) < 1e-9;
      if (!left && !right) continue;
      for (int layer = 0; layer < 2; ++layer)
        for (int d = 0; d < 4; ++d) {
          const Index dx = model.dof(b, ply.node(s, layer), d, 0);
          if (right) target(dx) = kStretch * X(dx);
          for (int i = 0; i < 3; ++i) {
            const Index dof = model.dof(b, ply.node(s, layer), d, i);
            bcs.push_back({dof, target(dof)});
            is_free[static_cast<std::size_t>(dof)] = false;
          }
        }
    }
  }
  // A deformed state for the timing: the affine stretch everywhere.
  setup.x = X;
  for (Index p = 0; p < nd / 3; ++p) setup.x(3 * p) *= kStretch;
}

int run_case(int n, int plies, int repeats, bool study = false) {
  Setup setup;
  make_setup(n, plies, setup);
  Model& model = setup.model;
  const Index nd = model.n_dofs();
  const VecX& X = setup.X;
  const VecX& x = setup.x;
  const std::vector<PrescribedDof>& bcs = setup.bcs;
  const std::vector<bool>& is_free = setup.is_free;

  const bool unsym = !g_lu.empty();
  // Held by pointers: freed before the static solve, which makes its own (its peak is then
  // its own, not on top of this iteration's).
  auto solver_held = std::make_unique<TangentSolver>(
      unsym ? linalg::parse_solver_kind(g_lu, "--lu") : linalg::SolverKind::kAuto, unsym);
  TangentSolver& solver = *solver_held;
  auto t0 = std::chrono::steady_clock::now();
  auto pattern_held = std::make_unique<linalg::PatternAssembler>(model.make_pattern(is_free, solver.lower()));
  linalg::PatternAssembler& pattern = *pattern_held;
  // As TangentWorkspace lays it out: in the Cholesky's order (the study wants the natural one).
  if (!study) solver.lay_out(pattern);
  const double layout_s = seconds_since(t0);
  if (study) {
    if (!model.assemble_into(x, InteractionContext{}, &pattern).ok) return 1;
    factorisation_study(pattern.matrix(), repeats);
    return 0;
  }

  // Kernels alone: the model's loop without the writing (same threads, same buffers).
  const std::vector<linalg::ElementEntries>& entries = model.element_entries();
  std::vector<std::pair<int, Index>> bricks;
  std::vector<BrickParams> X_e;
  for (int b = 0; b < model.n_bodies(); ++b)
    for (Index e = 0; e < model.ply(b).n_elements(); ++e) {
      bricks.emplace_back(b, e);
      X_e.push_back(model.ply(b).element_parameters(e, model.ply(b).reference()));
    }
  const Index n_el = static_cast<Index>(bricks.size());
  const int threads = model.threads();
  auto kernels_only = [&] {
#pragma omp parallel num_threads(threads)
    {
      thread_local BrickScratch scratch;
      thread_local ElementResult result;
#pragma omp for schedule(dynamic, 4)
      for (Index g = 0; g < n_el; ++g) {
        const linalg::ElementEntries& en = entries[static_cast<std::size_t>(g)];
        BrickParams xe = BrickParams::Zero();
        for (std::size_t a = 0; a < en.dofs.size(); ++a)
          xe(en.local[a] / 3, en.local[a] % 3) += en.coefs[a] * x(en.dofs[a]);
        model.kernel().evaluate(X_e[static_cast<std::size_t>(g)], xe, model.material(bricks[g].first), true, {},
                                scratch, result);
      }
    }
  };
  kernels_only();  // warm-up (thread buffers)
  // The kernel's share of a core's peak, on the processor clock of one thread (so the
  // machine's load does not enter): every brick once on this thread, against the same
  // thread's fused multiply-add rate with the same vector set.
  double kern_1_s = 0.0;
  {
    BrickScratch scratch;
    ElementResult result;
    const double t_start = thread_seconds();
    for (Index g = 0; g < n_el; ++g) {
      const linalg::ElementEntries& en = entries[static_cast<std::size_t>(g)];
      BrickParams xe = BrickParams::Zero();
      for (std::size_t a = 0; a < en.dofs.size(); ++a)
        xe(en.local[a] / 3, en.local[a] % 3) += en.coefs[a] * x(en.dofs[a]);
      model.kernel().evaluate(X_e[static_cast<std::size_t>(g)], xe, model.material(bricks[g].first), true, {}, scratch,
                              result);
    }
    kern_1_s = thread_seconds() - t_start;
  }
  const double core_peak_gf = linalg::fma_peak_gflops(0.2);
  model.assemble_into(x, InteractionContext{}, &pattern);
  const double kernel_s = median_time(repeats, kernels_only);
  const double asm_s = median_time(repeats, [&] { model.assemble_into(x, InteractionContext{}, &pattern); });
  const double resid_s = median_time(repeats, [&] { model.assemble_into(x, InteractionContext{}, nullptr); });

  t0 = std::chrono::steady_clock::now();
  linalg::SolveReport first = solver.factorize(pattern.matrix());
  const double first_s = seconds_since(t0);
  if (!first.ok()) std::printf("# factorisation failed: %s\n", first.brief().c_str());
  if (unsym)
    std::printf("# --lu %s: %s (%s)\n", g_lu.c_str(), linalg::to_string(first.used).c_str(), first.ordering.c_str());
  const double analyse_s = first.analyze_seconds;
  double flops = first.factor_flops;
  const double fact_s = median_time(repeats, [&] { flops = solver.factorize(pattern.matrix()).factor_flops; });
  (void)first_s;
  const VecX rhs = VecX::Ones(pattern.n_active());
  double solve_s = median_time(repeats, [&] {
    const Eigen::MatrixXd sol = solver.solve(rhs);
    if (!sol.allFinite()) std::printf("# warning: non-finite solution\n");
  });
  const double iter_s = asm_s + resid_s + fact_s + solve_s;
  const double iter_mb = peak_mb();
  const Index n_free = pattern.n_active();
  pattern_held.reset();
  solver_held.reset();

  // The stretch in two load steps, as a run takes them: one workspace (pattern, scatter
  // tables, symbolic factorisation) for both, so the second step lays nothing out.
  StaticOptions so;
  so.workspace = std::make_shared<TangentWorkspace>();
  std::vector<PrescribedDof> half = bcs;
  for (PrescribedDof& p : half) p.value = 0.5 * (p.value + X(p.dof));
  t0 = std::chrono::steady_clock::now();
  const StaticResult res1 = solve_static(model, X, half, VecX(), so);
  const StaticResult res = solve_static(model, res1.positions, bcs, VecX(), so);
  const double static_s = seconds_since(t0);
  if (!res1.report.ok()) std::printf("# static solve, step 1: %s\n", res1.report.brief().c_str());
  if (!res.report.ok()) std::printf("# static solve, step 2: %s\n", res.report.brief().c_str());
  const int newton = res1.report.total_iterations + res.report.total_iterations;

  const double kern_gf = n_el * model.kernel().tangent_flops() / kernel_s / 1e9;
  const double kern_pct = 100.0 * n_el * model.kernel().tangent_flops() / kern_1_s / 1e9 / core_peak_gf;
  std::printf(
      "%3dx%-3d %5d %8ld %8ld %8.3f %8.3f %9.3f %8.3f %8.3f %8.3f %8.4f %8.3f %7.1f %6.0f%% %7.1f %6d %7d %8.2f %8.1f "
      "%8.1f\n",
      n, n, plies, static_cast<long>(nd), static_cast<long>(n_free), layout_s, kernel_s, asm_s - kernel_s, resid_s,
      analyse_s, fact_s, solve_s, iter_s, kern_gf, kern_pct, flops / fact_s / 1e9, newton, so.workspace->layouts(),
      static_s, iter_mb, peak_mb());
  std::fflush(stdout);
  return 0;
}

// --kernel N PLIES [rounds]: the brick kernel alone (force and tangent of every brick of
// the stretched plies, `rounds` times) on this thread: seconds per brick on the thread's
// processor clock, GFLOP/s (BrickKernel::tangent_flops) and the share of this thread's
// fused multiply-add peak. A steady loop for a profiler (perf record) to split by part.
int run_kernel(int n, int plies, int rounds) {
  Setup setup;
  make_setup(n, plies, setup);
  const Model& model = setup.model;
  std::vector<const Material*> materials;
  std::vector<BrickParams> X_e, x_e;
  const std::vector<linalg::ElementEntries>& entries = model.element_entries();
  for (int b = 0; b < model.n_bodies(); ++b)
    for (Index e = 0; e < model.ply(b).n_elements(); ++e) {
      const linalg::ElementEntries& en = entries[X_e.size()];
      BrickParams xe = BrickParams::Zero();
      for (std::size_t a = 0; a < en.dofs.size(); ++a)
        xe(en.local[a] / 3, en.local[a] % 3) += en.coefs[a] * setup.x(en.dofs[a]);
      X_e.push_back(model.ply(b).element_parameters(e, model.ply(b).reference()));
      x_e.push_back(xe);
      materials.push_back(&model.material(b));
    }
  BrickScratch scratch;
  ElementResult result;
  double checksum = 0.0;
  auto sweep = [&] {
    for (std::size_t g = 0; g < X_e.size(); ++g) {
      model.kernel().evaluate(X_e[g], x_e[g], *materials[g], true, {}, scratch, result);
      checksum += result.tangent(95, 0) + result.force(0);
    }
  };
  sweep();  // warm-up
  const double t0 = thread_seconds();
  for (int r = 0; r < rounds; ++r) sweep();
  const double per_brick = (thread_seconds() - t0) / (static_cast<double>(rounds) * X_e.size());
  const double peak = linalg::fma_peak_gflops(0.2);
  const double gf = model.kernel().tangent_flops() / per_brick / 1e9;
  std::printf("kernel %dx%d x %d plies, %s: %.2f us a brick (%.3f MFLOP), %.1f GFLOP/s, %.0f%% of %.1f (checksum %.6e)\n",
              n, n, plies, linalg::to_string(linalg::kernel_isa()).c_str(), 1e6 * per_brick,
              model.kernel().tangent_flops() / 1e6, gf, 100.0 * gf / peak, peak, checksum);
  return 0;
}

// --memory N PLIES: where the memory of one case goes, stage by stage. Each stage
// reports its own peak resident memory (the kernel's high-water mark, reset before the
// stage), the resident memory and malloc's bytes in use after it, MB, and its wall time.
// Freed memory stays resident (keep_freed_memory), so a stage's peak above the one before
// is memory it touched that no earlier stage had.
int run_memory(int n, int plies) {
  const bool resettable = reset_peak();
  std::printf("# memory by stage, %dx%d x %d plies; MB; peak: the stage's own%s\n", n, n, plies,
              resettable ? "" : " (cannot reset the high-water mark here: peak since start)");
  std::printf("%-34s %9s %9s %9s %9s %8s\n", "stage", "peak", "rss", "heap", "d_heap", "wall_s");
  double heap_before = heap_in_use_mb();
  auto t_stage = std::chrono::steady_clock::now();
  auto stage = [&](const char* name, const std::string& note = {}) {
    const double heap = heap_in_use_mb();
    std::printf("%-34s %9.1f %9.1f %9.1f %+9.1f %8.3f %s\n", name, status_mb("VmHWM"), status_mb("VmRSS"), heap,
                heap - heap_before, seconds_since(t_stage), note.c_str());
    std::fflush(stdout);
    heap_before = heap;
    reset_peak();
    t_stage = std::chrono::steady_clock::now();
  };
  stage("start");
  auto setup = std::make_unique<Setup>();
  make_setup(n, plies, *setup);
  const Model& model = setup->model;
  stage("model", fmt::format("{} dofs, {} elements", model.n_dofs(), model.element_entries().size()));
  {
    TangentSolver solver(linalg::SolverKind::kAuto, false);
    linalg::PatternAssembler pattern = model.make_pattern(setup->is_free, solver.lower());
    stage("pattern and scatter tables");
    solver.lay_out(pattern);
    stage("ordered for the Cholesky",
          fmt::format("n {} nnz {} (pattern's own count {:.1f} MB)", pattern.n_active(), pattern.matrix().nonZeros(),
                      pattern.memory_bytes() / 1048576.0));
    model.assemble_into(setup->x, InteractionContext{}, &pattern);
    stage("assembly (force and tangent)");
    const linalg::SolveReport first = solver.factorize(pattern.matrix());
    stage("analysis and factorisation",
          fmt::format("{}; nnz(L) {:.0f} ({:.1f} MB of values)", first.ok() ? "ok" : first.brief(),
                      first.factor_nonzeros, first.factor_nonzeros * 8 / 1048576.0));
    model.assemble_into(setup->x, InteractionContext{}, &pattern);
    stage("assembly again");
    solver.factorize(pattern.matrix());
    stage("factorisation again");
    const VecX rhs = VecX::Ones(pattern.n_active());
    const VecX sol = solver.solve(rhs);
    stage("solve");
    model.assemble_into(setup->x, InteractionContext{}, nullptr);
    stage("assembly (force only)");
  }
  stage("pattern and solver freed");
  StaticOptions so;
  so.workspace = std::make_shared<TangentWorkspace>();
  std::vector<PrescribedDof> half = setup->bcs;
  for (PrescribedDof& p : half) p.value = 0.5 * (p.value + setup->X(p.dof));
  const StaticResult res1 = solve_static(model, setup->X, half, VecX(), so);
  stage("static solve, step 1", fmt::format("{} Newton iterations", res1.report.total_iterations));
  const StaticResult res = solve_static(model, res1.positions, setup->bcs, VecX(), so);
  stage("static solve, step 2", fmt::format("{} Newton iterations", res.report.total_iterations));
  std::printf("# process peak %.1f MB\n", peak_mb());
  return 0;
}

// Keeps each converged step and shows it on stderr as it comes (a long case otherwise
// runs minutes without a line).
class Recorder final : public StepObserver {
 public:
  std::vector<StepInfo> steps;
  StepAction on_step(const StepInfo& step, const SteppingState&, const VecX&) override {
    steps.push_back(step);
    std::fprintf(stderr, "#   step %d converged: load factor %.3f, %d Newton iterations, %d cut-backs, %.1f s\n",
                 step.index, step.load_factor, step.iterations, step.cutbacks, seconds_since(t0_));
    return StepAction::kContinue;
  }

 private:
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

// elements > 0: every ply meshed with elements x elements bricks instead of the file's
// (the 40 x 40 case costs minutes a step; 10 x 10 shows the same Newton behaviour).
int run_shear_stretch(const std::string& path, int elements = 0) {
  FormingCase spec = load_case(path);
  if (elements > 0)
    for (CasePly& ply : spec.plies) ply.n1 = ply.n2 = elements;
  Problem problem = build_problem(spec);
  const StepperSettings settings = stepper_settings(spec);
  std::unique_ptr<Stepper> stepper = make_stepper(problem, settings);
  SteppingState state;
  state.x = problem.model.reference_positions();
  state.v = VecX::Zero(state.x.size());
  Recorder recorder;
  const auto t0 = std::chrono::steady_clock::now();
  const SteppingReport report = stepper->run(state, recorder);
  const double total_s = seconds_since(t0);
  std::printf("# shear-and-stretch ply (%s, %d x %d elements): %ld dofs, %s\n", path.c_str(), spec.plies.at(0).n1,
              spec.plies.at(0).n2, static_cast<long>(problem.model.n_dofs()),
              report.status == SteppingReport::Status::kFinished ? "finished" : report.message.c_str());
  int iterations = 0;
  for (const StepInfo& s : recorder.steps) {
    std::printf("  step %d (load factor %.2f): %d Newton iterations, %d cut-backs, |r| %.3g N\n", s.index,
                s.load_factor, s.iterations, s.cutbacks, s.residual);
    iterations += s.iterations;
  }
  std::printf("  %d iterations in %zu steps (%.1f per step), %d in all (failed attempts included), %.1f s, peak %.0f MB\n",
              iterations, recorder.steps.size(), recorder.steps.empty() ? 0.0 : double(iterations) / recorder.steps.size(),
              report.total_iterations, total_s, peak_mb());
  return report.status == SteppingReport::Status::kFinished ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  keep_freed_memory();  // as simform does (common/core/memory.hpp)
  try {
    // --lu KIND anywhere: taken out of the arguments, passed on to the cases.
    std::vector<char*> args;
    for (int i = 0; i < argc; ++i) {
      if (std::strcmp(argv[i], "--lu") == 0 && i + 1 < argc) {
        g_lu = argv[++i];
        linalg::parse_solver_kind(g_lu, "--lu");  // a bad name fails here, with the accepted ones
        continue;
      }
      args.push_back(argv[i]);
    }
    argc = static_cast<int>(args.size());
    argv = args.data();
    const std::string lu_arg = g_lu.empty() ? std::string() : " --lu " + g_lu;
    if (argc >= 4 && std::strcmp(argv[1], "--case") == 0)
      return run_case(std::atoi(argv[2]), std::atoi(argv[3]), argc > 4 ? std::atoi(argv[4]) : 3);
    if (argc >= 4 && std::strcmp(argv[1], "--factorisation") == 0)
      return run_case(std::atoi(argv[2]), std::atoi(argv[3]), argc > 4 ? std::atoi(argv[4]) : 3, true);
    if (argc >= 4 && std::strcmp(argv[1], "--kernel") == 0)
      return run_kernel(std::atoi(argv[2]), std::atoi(argv[3]), argc > 4 ? std::atoi(argv[4]) : 20);
    if (argc >= 4 && std::strcmp(argv[1], "--memory") == 0) return run_memory(std::atoi(argv[2]), std::atoi(argv[3]));
    if (argc >= 3 && std::strcmp(argv[1], "--shear-stretch") == 0)
      return run_shear_stretch(argv[2], argc > 3 ? std::atoi(argv[3]) : 0);
    const int max_n = argc > 1 ? std::atoi(argv[1]) : 40;
    const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
    const TransverselyIsotropicParams tp = ply_law();
    std::printf(
        "# simform_bench: flat plies %g x %g x %g mm, compressible TI (mu_T %g, mu_L %g, kappa_f %g, lambda %g "
        "MPa), fibres 0/90/0/90; plies are independent bodies (no contact yet)\n",
        kL, kL, kH, tp.mu_T, tp.mu_L, tp.kappa_f, tp.lambda);
    std::printf(
        "# element loop on %d threads (OpenMP; SF_THREADS), kernel vector instructions: %s (processor's best: %s); "
        "linear solver: %s\n"
        "# BLAS: %s\n",
        sf::default_threads(), linalg::to_string(linalg::kernel_isa()).c_str(),
        linalg::to_string(linalg::best_kernel_isa()).c_str(),
        g_lu.empty() ? "CHOLMOD supernodal Cholesky, MUMPS LDL^T when indefinite (UMFPACK LU without MUMPS)"
                     : ("--lu " + g_lu + ": the tangent as an unsymmetric one (both triangles, LU)").c_str(),
        linalg::blas_description().c_str());
    const int threads = sf::default_threads();
    double peak_gf = 0.0;
#pragma omp parallel num_threads(threads) reduction(+ : peak_gf)
    peak_gf += linalg::fma_peak_gflops(0.3);
    std::printf(
        "# double-precision peak measured (%s fused multiply-add chains, processor time): %.1f GFLOP/s on %d "
        "threads at once, %.1f a core alone\n",
        linalg::to_string(linalg::kernel_isa()).c_str(), peak_gf, threads, linalg::fma_peak_gflops(0.3));
    std::printf(
        "# per Newton iteration, wall-clock seconds (medians of %d), GFLOP/s, memory MB (peak RSS of the case)\n",
        repeats);
    std::printf("%7s %5s %8s %8s %8s %8s %9s %8s %8s %8s %8s %8s %7s %7s %7s %6s %7s %8s %8s %8s\n", "n x n", "plies",
                "n_dofs", "n_free", "layout_s", "kernel_s", "scatter_s", "resid_s", "analyse", "fact_s", "solve_s",
                "iter_s", "kern_GF", "kern_%", "fact_GF", "newton", "layouts", "static_s", "iter_MB", "peak_MB");
    std::fflush(stdout);
    const std::string self = argv[0];
    for (int n : {10, 20, 40}) {
      if (n > max_n) break;
      for (int plies : {1, 4}) {
        const std::string cmd = "'" + self + "' --case " + std::to_string(n) + " " + std::to_string(plies) + " " +
                                std::to_string(repeats) + lu_arg;
        if (std::system(cmd.c_str()) != 0) std::printf("# case %dx%d, %d plies failed\n", n, n, plies);
      }
    }
    const std::string shear = std::string(SF_SOURCE_DIR) + "/bench/cases/shear_stretch_ply.yaml";
    if (max_n >= 40) {
      const std::string cmd = "'" + self + "' --shear-stretch '" + shear + "'";
      if (std::system(cmd.c_str()) != 0) std::printf("# shear-and-stretch ply did not finish\n");
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simform_bench: %s\n", e.what());
    return 1;
  }
}

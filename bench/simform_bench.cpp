// Cost of the forming solver's building blocks on flat plies: for n x n bricks per ply
// (n = 10, 20, 40) and 1 or 4 plies, prints one line per case:
//   n_dofs      unknowns (24 per surface node per ply)
//   asm_s       one assembly of internal force + tangent at a deformed state, seconds
//   fact_s      symbolic analysis + numeric factorisation of the free-dof tangent K_ff
//               with LinearSolver(kAuto, SPD) (= CHOLMOD when SuiteSparse is built in), s
//   solve_s     one back-substitution with that factorisation, s
//   newton      Newton iterations (predictor included) of a static solve: uniaxial 5 %
//               stretch along x of every ply (grips: all parameters of the nodes at x = 0
//               held, those at x = L moved affinely), compressible TI law, fibres 0/90
//   static_s    wall time of that solve (solve_static, its own linear solver choice), s
//   peak_MB     peak resident memory of the process so far (getrusage; high-water mark,
//               so it only grows from line to line)
// Plies: 100 x 100 mm, 0.25 mm thick, stacked in z as separate bodies. There is no
// contact or interaction between plies yet, so the 4-ply system is block diagonal (4
// independent plies); the figures show the scaling of assembly and factorisation only.
// A program that prints figures, not a timed test.
//   build/bin/simform_bench [max_elements_per_side=40]
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "common/linalg/solver.hpp"
#include "common/linalg/sparse.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/solve/static_solver.hpp"

using namespace sf;
using namespace sf::forming;

static double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

static double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int main(int argc, char** argv) {
  const int max_n = argc > 1 ? std::atoi(argv[1]) : 40;
  const double L = 100.0, h = 0.25, stretch = 1.05;
  TransverselyIsotropicParams tp;
  tp.mu_T = 1.0;
  tp.mu_L = 2.0;
  tp.kappa_f = 500.0;
  tp.incompressible = false;
  tp.lambda = 10.0;
  std::printf("# simform_bench: flat plies %g x %g x %g mm, compressible TI (mu_T %g, mu_L %g, kappa_f %g, lambda %g "
              "MPa), fibres 0/90/0/90\n",
              L, L, h, tp.mu_T, tp.mu_L, tp.kappa_f, tp.lambda);
  std::printf("# times in seconds, memory in MB (peak RSS so far); plies are independent bodies (no contact yet)\n");
  std::printf("%7s %5s %8s %8s %8s %8s %6s %9s %8s  %s\n", "n x n", "plies", "n_dofs", "asm_s", "fact_s", "solve_s",
              "newton", "static_s", "peak_MB", "linear solver");
  for (int n : {10, 20, 40}) {
    if (n > max_n) break;
    for (int plies : {1, 4}) {
      Model model;
      for (int k = 0; k < plies; ++k) {
        PlyMesh ply(mesh::make_rectangle_mesh(Vec3(0.0, 0.0, k * h), Vec3::UnitX(), Vec3::UnitY(), L, L, n, n), h,
                    k % 2 == 0 ? 0.0 : 90.0);
        auto material = std::make_shared<TransverselyIsotropic>(tp, ply.fibre_direction());
        model.add_ply(std::move(ply), material);
      }
      const Index nd = model.n_dofs();
      const VecX X = model.reference_positions();

      // Grips: every parameter of the nodes at x = 0 (held) and x = L (x -> F X).
      std::vector<PrescribedDof> bcs;
      std::vector<bool> fixed(nd, false);
      VecX target = X;
      for (int b = 0; b < model.n_bodies(); ++b) {
        const PlyMesh& ply = model.ply(b);
        for (Index s = 0; s < ply.n_surface_nodes(); ++s) {
          const double xs = ply.surface().node_position(s).x();
          const bool left = std::abs(xs) < 1e-9, right = std::abs(xs - L) < 1e-9;
          if (!left && !right) continue;
          for (int layer = 0; layer < 2; ++layer)
            for (int d = 0; d < 4; ++d) {
              const Index dx = model.dof(b, ply.node(s, layer), d, 0);
              if (right) target(dx) = stretch * X(dx);
              for (int i = 0; i < 3; ++i) {
                const Index dof = model.dof(b, ply.node(s, layer), d, i);
                bcs.push_back({dof, target(dof)});
                fixed[dof] = true;
              }
            }
        }
      }
      // A deformed state for the timing: the affine stretch everywhere.
      VecX x = X;
      for (Index p = 0; p < nd / 3; ++p) x(3 * p) *= stretch;

      auto t0 = std::chrono::steady_clock::now();
      const Assembly a = model.assemble(x, true);
      const double asm_s = seconds_since(t0);
      if (!a.ok) {
        std::printf("assembly failed: %s\n", a.message.c_str());
        return 1;
      }
      // K_ff of the free dofs.
      std::vector<int> free_index(nd, -1);
      int nf = 0;
      for (Index d = 0; d < nd; ++d)
        if (!fixed[d]) free_index[d] = nf++;
      std::vector<Eigen::Triplet<double, int>> trip;
      trip.reserve(a.tangent.nonZeros());
      for (int c = 0; c < a.tangent.outerSize(); ++c)
        for (linalg::SparseMatrix::InnerIterator it(a.tangent, c); it; ++it) {
          const int r = free_index[it.row()], cc = free_index[it.col()];
          if (r >= 0 && cc >= 0) trip.emplace_back(r, cc, it.value());
        }
      linalg::SparseMatrix kff(nf, nf);
      kff.setFromTriplets(trip.begin(), trip.end());
      linalg::LinearSolver solver(linalg::SolverKind::kAuto, linalg::MatrixProperty::kSymmetricPositiveDefinite);
      t0 = std::chrono::steady_clock::now();
      const linalg::SolveReport& rep = solver.factorize(kff);
      const double fact_s = seconds_since(t0);
      double solve_s = 0.0;
      if (rep.ok()) {
        Eigen::VectorXd rhs = Eigen::VectorXd::Ones(nf);
        t0 = std::chrono::steady_clock::now();
        const Eigen::MatrixXd sol = solver.solve(rhs);
        solve_s = seconds_since(t0);
        if (!sol.allFinite()) std::printf("# warning: non-finite solution\n");
      } else {
        std::printf("# factorisation failed: %s\n", rep.brief().c_str());
      }
      const std::string kind = linalg::to_string(solver.kind());

      t0 = std::chrono::steady_clock::now();
      const StaticResult res = solve_static(model, X, bcs, VecX());
      const double static_s = seconds_since(t0);
      if (!res.report.ok()) std::printf("# static solve: %s\n", res.report.brief().c_str());
      std::printf("%3dx%-3d %5d %8ld %8.3f %8.3f %8.4f %6d %9.3f %8.1f  %s (K_ff nnz %ld)\n", n, n, plies,
                  static_cast<long>(nd), asm_s, fact_s, solve_s, res.report.total_iterations, static_s, peak_mb(),
                  kind.c_str(), static_cast<long>(kff.nonZeros()));
      std::fflush(stdout);
    }
  }
  return 0;
}

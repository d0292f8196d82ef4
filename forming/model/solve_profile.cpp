#include "forming/model/solve_profile.hpp"

#include <fmt/format.h>

namespace sf::forming {

SolveProfile& solve_profile() {
  static SolveProfile profile;
  return profile;
}

std::string solve_profile_linear_summary(const SolveProfile& p) {
  if (p.factorizations == 0) return "no factorisation";
  return fmt::format(
             "n {}, nnz(K) {} ({:.0f} a row), nnz(factor) {:.4g} (fill {:.1f}x), {:.3g} Gflop a factorisation, "
             "solver {} ({}), {} symbolic analyses ({:.3f} s) in {} factorisations, {} pattern growths",
             p.n, p.nnz, p.n > 0 ? static_cast<double>(p.nnz) / static_cast<double>(p.n) : 0.0, p.factor_nnz,
             p.nnz > 0 ? p.factor_nnz / static_cast<double>(p.nnz) : 0.0, p.factor_flops * 1e-9, p.solver,
             p.ordering.empty() ? "ordering unknown" : p.ordering, p.analyses, p.analyse_s, p.factorizations,
             p.pattern_growths) +
         (p.krylov_solves == 0
              ? std::string()
              : fmt::format("; iterative: {} GMRES solves, {:.1f} iterations a solve, worst |K dx + r|/|r| {:.2g}, "
                            "{} preconditioner factorisations, {} direct fallbacks",
                            p.krylov_solves,
                            static_cast<double>(p.krylov_iterations) / static_cast<double>(p.krylov_solves),
                            p.krylov_worst_residual, p.preconditioner_factorizations, p.direct_fallbacks)) +
         (p.indefinite_factorizations == 0
              ? std::string()
              : fmt::format("; indefinite: {} LDL^T factorisations, worst |K dx - b|/|b| {:.2g}, {} refinement "
                            "steps, {} residual fallbacks to LU",
                            p.indefinite_factorizations, p.indefinite_worst_residual, p.residual_refinements,
                            p.residual_fallbacks)) +
         (p.lu_checked_solves == 0 && p.lu_fallbacks == 0
              ? std::string()
              : fmt::format("; LU: {} checked solves, worst |K dx - b|/|b| {:.2g}, {} refinement steps, {} "
                            "fallbacks to UMFPACK",
                            p.lu_checked_solves, p.lu_worst_residual, p.lu_refinements, p.lu_fallbacks));
}

}  // namespace sf::forming

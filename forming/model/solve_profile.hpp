#pragma once
// Where the time of a solve goes, for benchmark programs (bench/simform_dome_bench.cpp):
// wall seconds accumulated by Model::assemble_into (element kernels and their scatter,
// then the contact and other interactions with their merge into the tangent) and by
// forming/solve/tangent_solver.cpp (factorisation, triangular solves). One process-wide
// record, updated only from the (single) thread that drives a solve; reset it before the
// part to measure. Costs two clock reads per phase, nothing else.
#include <string>

namespace sf::forming {

struct SolveProfile {
  double elements_s = 0.0;   // element kernels + scatter into the tangent pattern
  double contact_s = 0.0;    // interactions: contact search, laws, their tangent, merge
  double factorize_s = 0.0;  // numeric (and when needed symbolic) factorisation
  double solve_s = 0.0;      // triangular solves
  long assemblies = 0;       // Model::assemble_into calls (with or without tangent)
  long factorizations = 0;
  long solves = 0;
  // Parts of contact_s: the interactions' own evaluation (search, laws, local tangents,
  // and their entries: added straight into the kept tangent pattern, or as triplets when
  // the assembly also wants K d) and the merge of the triplets into the tangent pattern
  // (with its growth when a contact entry falls outside it).
  double contact_eval_s = 0.0;
  double contact_merge_s = 0.0;
  long contact_entries = 0;    // stiffness entries added or merged (summed over assemblies)
  long pattern_growths = 0;    // merges that grew the pattern (the next factorisation re-analyses)
  double band_layout_s = 0.0;  // part of contact_merge_s: laying the grown pattern out for the search band
  // Symbolic analyses (fill-reducing ordering) and their seconds, part of factorize_s.
  long analyses = 0;
  double analyse_s = 0.0;
  // The last factorised tangent: size, stored entries, factor entries, the back end that
  // did the work and its ordering (solve_profile_linear_summary() prints them).
  long n = 0;
  long nnz = 0;
  double factor_nnz = 0.0;
  double factor_flops = 0.0;
  std::string solver;
  std::string ordering;
  // Iterative solves of the tangent (forming/solve/tangent_solver.hpp, linear: iterative):
  // GMRES solves, their iterations in all, the largest relative residual |K dx + r| / |r|
  // they ended with, factorisations of the per-ply preconditioner, and solves that fell
  // back to the direct LU (GMRES did not converge).
  long krylov_solves = 0;
  long krylov_iterations = 0;
  double krylov_worst_residual = 0.0;
  long preconditioner_factorizations = 0;
  long direct_fallbacks = 0;
  // Direct solves of a symmetric tangent that is not positive definite (forming/solve/
  // tangent_solver.hpp): factorisations by the symmetric indefinite solver (MUMPS LDL^T),
  // the refinement steps its solutions took, the solves whose residual stayed above the
  // tolerance and went to the LU, and the largest |K dx - b|/|b| the indefinite solves
  // ended with.
  long indefinite_factorizations = 0;
  long residual_refinements = 0;
  long residual_fallbacks = 0;
  double indefinite_worst_residual = 0.0;
  // Direct solves of an unsymmetric tangent by MUMPS's LU (the default when MUMPS is built
  // in; forming/solve/tangent_solver.hpp): solves checked, refinement steps they took, the
  // largest |K dx - b|/|b| they ended with, and the factorisations or solves that went to
  // UMFPACK instead (MUMPS failed, or a solution failed its check).
  long lu_checked_solves = 0;
  long lu_refinements = 0;
  double lu_worst_residual = 0.0;
  long lu_fallbacks = 0;
  void reset() { *this = SolveProfile{}; }
};

SolveProfile& solve_profile();

// One line about the linear algebra so far, e.g. "n 2400, nnz(K) 1.1e6 (lower), nnz(L) ...,
// solver cholmod (amd), 3 analyses in 44 factorisations".
std::string solve_profile_linear_summary(const SolveProfile& p);

}  // namespace sf::forming

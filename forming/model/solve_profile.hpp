#pragma once
// Where the time of a solve goes, for benchmark programs (bench/simform_dome_bench.cpp):
// wall seconds accumulated by Model::assemble_into (element kernels and their scatter,
// then the contact and other interactions with their merge into the tangent) and by
// forming/solve/tangent_solver.cpp (factorisation, triangular solves). One process-wide
// record, updated only from the (single) thread that drives a solve; reset it before the
// part to measure. Costs two clock reads per phase, nothing else.
namespace sf::forming {

struct SolveProfile {
  double elements_s = 0.0;   // element kernels + scatter into the tangent pattern
  double contact_s = 0.0;    // interactions: contact search, laws, their tangent, merge
  double factorize_s = 0.0;  // numeric (and when needed symbolic) factorisation
  double solve_s = 0.0;      // triangular solves
  long assemblies = 0;       // Model::assemble_into calls (with or without tangent)
  long factorizations = 0;
  long solves = 0;
  void reset() { *this = SolveProfile{}; }
};

SolveProfile& solve_profile();

}  // namespace sf::forming

#pragma once
// Checks of the model a case describes, after it has read cleanly (issue 20): what makes a
// run fail late, or run for ever, is refused by `simform check` with its place.
//
//   held plies      static analysis: each ply's boundary conditions must remove its six
//                   rigid-body motions (three translations, three rotations), unless it
//                   is in a contact pair (a tool or another ply may hold it); otherwise
//                   the stiffness matrix is singular and Newton "does not converge";
//   geometry        coordinates within +-1e6 mm, sizes and thickness in [1e-4, 1e5] mm,
//                   a ply no thicker than it is wide, element sizes not below 1e-4 mm;
//   model size      the unknowns (24 per surface node pair) and an estimate of the memory
//                   to solve them (matrix and its Cholesky factor); refused beyond the
//                   machine's memory, naming both figures.
#include <cstdint>
#include <vector>

#include "forming/case/problems.hpp"
#include "forming/case/schema.hpp"

namespace sf::forming {

struct ModelEstimate {
  std::int64_t unknowns = 0;   // degrees of freedom
  double matrix_bytes = 0.0;   // assembled tangent (lower triangle, values and indices)
  double factor_bytes = 0.0;   // its Cholesky factor (nested dissection on each ply's grid)
  double total_bytes() const;  // both, plus vectors and element work (about 20 % more)
};
ModelEstimate estimate_model(const FormingCase& spec);

// The machine's physical memory in bytes (0 when unknown).
double machine_memory_bytes();

// The rules above; `memory_bytes` is the limit (the machine's memory; 0: not checked).
void check_model(const FormingCase& spec, std::vector<CaseProblem>& problems, double memory_bytes);

}  // namespace sf::forming

#pragma once
// Coordinates far from the origin (a measuring system's machine frame: 1e5 mm offsets, or
// 1e14 by mistake) lose their precision in the fits, whose normal equations square the
// values: issue 20 saw strain errors of order 100 with exit 0 at an offset of 1e14 mm.
// gsa therefore fits centred data: centre_grid() subtracts the centroid of each state's
// marks when it is far away compared with the part's size, and uncentre() adds it back to
// every position in the result (mesh, fitted surfaces, rigid motion, plane origin), so
// the outputs are in the coordinates given. Strains do not depend on the shift.
//
// The input itself keeps only what a double holds: at 1e14 mm that is 0.016 mm. When this
// is more than 1e-4 of the mark spacing a warning says so (and how large the error is).
#include <string>

#include "common/core/types.hpp"
#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"

namespace sf::gsa {

struct Centring {
  bool applied = false;
  Vec3 undeformed = Vec3::Zero(), deformed = Vec3::Zero();  // subtracted from each state
  std::string warning;                                      // precision lost in the input ("" when not)
};

// Centres `grid` in place when its coordinates lie more than 100 part sizes from the
// origin; never with a user mesh (`user_mesh`: its coordinates are the grid's).
Centring centre_grid(GridData& grid, bool user_mesh, const std::string& units);
// Moves the positions in `result` back by the offsets of `c`.
void uncentre(AnalysisResult& result, const Centring& c);

}  // namespace sf::gsa

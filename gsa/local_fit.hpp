#pragma once
// The local least-squares strain method of DIC and forming-strain systems, for
// comparison: at each point a homogeneous deformation x = x0 + F (X - X0) is
// fitted by least squares to the point and its k nearest neighbours (k = 24: a
// 5 x 5 window on a regular grid), in the tangent plane of the neighbours'
// undeformed positions; the principal stretches are the square roots of the
// eigenvalues of F^T F (2 x 2, the plane's orthonormal axes).

#include <optional>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/grid.hpp"

namespace sf::gsa {

struct LocalStretch {
  double lambda1 = 1.0, lambda2 = 1.0;  // lambda1 >= lambda2
};

// One entry per point of `grid`; empty where the point lacks a position or its
// neighbourhood is degenerate (fewer than 3 usable neighbours, or collinear).
std::vector<std::optional<LocalStretch>> local_fit_stretches(const GridData& grid, int neighbours = 24);

}  // namespace sf::gsa

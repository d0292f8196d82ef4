#pragma once
// Nearest neighbours of scattered points (a kd-tree; CGAL stays in the .cpp).
//
// Used where a point is judged against the points around it: the local
// least-squares strain method, the check that a large fit residual is an
// isolated blunder and not a feature its neighbours share, noise statistics
// by distance.

#include <vector>

#include "common/core/types.hpp"

namespace sf::mesh {

// For every row p of `points` (n x 3), the indices of its k nearest other points,
// nearest first (fewer when n - 1 < k). Rows with a non-finite coordinate get no
// neighbours and are never anyone's neighbour.
std::vector<std::vector<Index>> nearest_neighbours(const Points3& points, int k);
// The same for the rows `query` only (out[i] for query[i]; the same lists as in the whole).
std::vector<std::vector<Index>> nearest_neighbours(const Points3& points, int k, const std::vector<Index>& query);

// For every row p of `points`, the indices of the other points within `radius`
// (unsorted). Non-finite rows as above.
std::vector<std::vector<Index>> neighbours_within(const Points3& points, double radius);
// The same for the rows `query` only (out[i] for query[i]).
std::vector<std::vector<Index>> neighbours_within(const Points3& points, double radius,
                                                  const std::vector<Index>& query);

}  // namespace sf::mesh

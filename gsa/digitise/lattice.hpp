#pragma once
// Grid indices (i, j) for mark centres in one image: growing a quadrilateral lattice from a
// seed mark through neighbour geometry.
//
//            j-1
//             |
//     i-1 --- P --- i+1        axis_i: the lattice direction nearest the image's +u (right)
//             |                axis_j: the other one, pointing down the image (+v)
//            j+1
//
// At the seed, the two shortest non-parallel neighbour vectors are the lattice axes. From
// every labelled mark the four neighbours are predicted -- by quadratic extrapolation along
// the row or column when the two marks behind are labelled, linear with one, the local
// axis vector with none -- and a detected centre is accepted only when it is the ONLY
// centre within `tolerance` x the step of the prediction. The local axes follow the marks,
// so smoothly varying distortion (perspective, forming strains, shear of 30+ degrees) is
// followed; the flat blank is the special case with no distortion. Marks are expanded best
// prediction first. A label that two paths put in different places, a mark that two
// paths give different labels, and two candidates near one prediction are reported and
// left unlabelled: never guessed.
//
// Why not a Delaunay triangulation of the centres reduced to quads (dropping each
// triangle's longest edge)? Beyond about 30 degrees of shear a cell's short diagonal is
// shorter than its sides and the reduction drops a lattice edge instead; the growth above
// never compares lengths across directions, and it labels the flat blank as well.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa::digitise {

using Label = Eigen::Vector2i;  // (i, j)

struct LatticeOptions {
  double tolerance = 0.3;  // acceptance radius around a prediction, fraction of the step
};

struct LatticeResult {
  std::vector<std::optional<Label>> labels;  // per input point
  std::vector<Vec2> axis_i, axis_j;          // local lattice vectors (pixels) per labelled point
  std::vector<Index> ambiguous;              // points left unlabelled: two candidates at one prediction
  std::vector<Index> conflicting;            // points left unlabelled: paths disagree
  Index n_labelled() const;
};

// Labels `points` (pixels) starting with `seed` at (0, 0). Points not connected to the seed
// through the lattice stay unlabelled. Throws nothing; fewer than 3 points labels only the seed.
LatticeResult grow_lattice(const std::vector<Vec2>& points, Index seed, const LatticeOptions& options = {});

// Uniform-grid bucketing of 2-D points for radius queries.
class PointGrid {
 public:
  PointGrid(const std::vector<Vec2>& points, double cell);
  // Indices of the points within `radius` of p.
  std::vector<Index> within(const Vec2& p, double radius) const;
  // The nearest point other than `exclude` within `max_radius`, or -1.
  Index nearest(const Vec2& p, double max_radius, Index exclude = -1) const;

 private:
  const std::vector<Vec2>& points_;
  double cell_;
  Vec2 origin_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<Index>> buckets_;
};

// Median nearest-neighbour distance of the points (0 for fewer than 2).
double median_spacing(const std::vector<Vec2>& points);

}  // namespace sf::gsa::digitise

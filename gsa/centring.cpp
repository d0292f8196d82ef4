#include "gsa/centring.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

namespace sf::gsa {
namespace {

// Centroid and size (bounding-box diagonal) of the rows without NaN; false when none.
bool centroid_of(const Points3& p, Vec3& centroid, double& size, double& largest) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo, sum = Vec3::Zero();
  Index n = 0;
  largest = 0.0;
  for (Index i = 0; i < p.rows(); ++i) {
    const Vec3 x = p.row(i).transpose();
    if (!x.allFinite()) continue;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
    sum += x;
    largest = std::max(largest, x.cwiseAbs().maxCoeff());
    ++n;
  }
  if (n == 0) return false;
  centroid = sum / static_cast<double>(n);
  size = (hi - lo).norm();
  return true;
}

}  // namespace

Centring centre_grid(GridData& grid, bool user_mesh, const std::string& units) {
  Centring c;
  Vec3 cu, cd;
  double su = 0, sd = 0, lu = 0, ld = 0;
  if (!centroid_of(grid.undeformed, cu, su, lu) || !centroid_of(grid.deformed, cd, sd, ld)) return c;
  const double size = std::max(su, sd);
  if (!(size > 0.0)) return c;
  // The resolution of the largest coordinate against the mark spacing (size / sqrt(n)).
  const double largest = std::max(lu, ld);
  const double resolution = largest * std::numeric_limits<double>::epsilon();
  const double spacing = size / std::sqrt(static_cast<double>(std::max<Index>(grid.n_points(), 1)));
  if (resolution > 1e-4 * spacing)
    c.warning = fmt::format(
        "coordinates as large as {:.3g} {} keep only {:.2g} {} of precision in a double ({:.2g} % of the mark "
        "spacing): the strains carry an error of that order; export the marks in a frame near the part",
        largest, units, resolution, units, 100.0 * resolution / spacing);
  if (user_mesh || std::max(cu.norm(), cd.norm()) < 100.0 * size) return c;
  c.applied = true;
  c.undeformed = cu;
  c.deformed = cd;
  for (Index i = 0; i < grid.undeformed.rows(); ++i) grid.undeformed.row(i) -= cu.transpose();
  for (Index i = 0; i < grid.deformed.rows(); ++i) grid.deformed.row(i) -= cd.transpose();
  return c;
}

void uncentre(AnalysisResult& r, const Centring& c) {
  if (!c.applied) return;
  const auto shift_values = [](MatX& params, const Vec3& by) {
    // Global dof 4 node + d; d = 0 is the value (position), the others are derivatives.
    for (Index row = 0; row < params.rows(); row += mesh::kParamsPerNode) params.row(row) += by.transpose();
  };
  if (r.mesh.geometry().rows() > 0) shift_values(r.mesh.geometry(), c.undeformed);
  if (r.undeformed_parameters.rows() > 0) shift_values(r.undeformed_parameters, c.undeformed);
  if (r.deformed_parameters.rows() > 0) shift_values(r.deformed_parameters, c.deformed);
  r.centroid += c.undeformed;
  // x = R X + t on centred data: x + cd = R (X + cu) + t + cd - R cu.
  r.rigid.translation += c.deformed - r.rigid.rotation * c.undeformed;
}

}  // namespace sf::gsa

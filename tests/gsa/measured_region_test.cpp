// The tessellated surfaces (undeformed.vtp, deformed.vtp and the pictures drawn from
// them) cover the measured region only (gsa/measured_region.hpp): a round blank's rim
// elements reach beyond the marks, and those cells are left out; a square grid keeps
// every cell.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "gsa/analysis.hpp"
#include "gsa/output.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {
namespace {

// Area and largest distance from the origin of the polygons' centres.
struct Covered {
  double area = 0.0, reach = 0.0;
};
Covered covered(const io::PolyMesh& m) {
  Covered c;
  for (const auto& poly : m.polygons) {
    Vec3 centre = Vec3::Zero(), n = Vec3::Zero();
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const Vec3 a = m.points.row(poly[k]).transpose(), b = m.points.row(poly[(k + 1) % poly.size()]).transpose();
      centre += a / static_cast<double>(poly.size());
      n += a.cross(b);
    }
    c.area += 0.5 * n.norm();
    c.reach = std::max(c.reach, std::hypot(centre.x(), centre.y()));
  }
  return c;
}

TEST(GsaMeasuredRegion, RoundBlankIsDrawnWhereItsMarksAre) {
  SyntheticGridOptions o;  // 21 x 21 marks 5 mm apart; the round blank has radius 50 mm
  o.round = true;
  const GridData g = make_synthetic_grid(synthetic_case("dome"), o);
  const AnalysisResult r = analyse(g, AnalyseOptions{});
  const io::PolyMesh m = surface_polymesh(r, false, 8);
  const Covered c = covered(m);
  // Unclipped, the 7 x 7 mesh's corner elements reach 57 mm and more from the centre.
  EXPECT_LT(static_cast<double>(m.polygons.size()), 0.97 * static_cast<double>(r.mesh.n_elements() * 64));
  EXPECT_LT(c.reach, 50.0);
  // The polygon through the rim marks, in cells of an eighth of an element, holds 95 % of
  // the disk (measured 7483 of 7854 mm^2).
  EXPECT_GT(c.area, 0.93 * kPi * 50.0 * 50.0);
  // Every point is kept (the pictures find each element's points by position).
  EXPECT_EQ(m.n_points(), r.mesh.n_elements() * 81);
}

TEST(GsaMeasuredRegion, SquareGridKeepsEveryCell) {
  const GridData g = make_synthetic_grid(synthetic_case("stretch"), SyntheticGridOptions{});
  const AnalysisResult r = analyse(g, AnalyseOptions{});
  const io::PolyMesh m = surface_polymesh(r, false, 8);
  EXPECT_EQ(static_cast<Index>(m.polygons.size()), r.mesh.n_elements() * 64);
}

}  // namespace
}  // namespace sf::gsa

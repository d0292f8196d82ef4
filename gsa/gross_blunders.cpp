#include "gsa/gross_blunders.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/mesh/neighbours.hpp"

namespace sf::gsa {
namespace {

void screen_state(Points3& points, bool undeformed, std::vector<GrossBlunder>& out) {
  const auto nn = mesh::nearest_neighbours(points, 1);
  std::vector<double> d(static_cast<std::size_t>(points.rows()), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> finite;
  for (Index p = 0; p < points.rows(); ++p) {
    const auto& n = nn[static_cast<std::size_t>(p)];
    if (n.empty()) continue;
    d[static_cast<std::size_t>(p)] = (points.row(p) - points.row(n.front())).norm();
    finite.push_back(d[static_cast<std::size_t>(p)]);
  }
  if (finite.size() < 8) return;  // too few marks to judge
  std::nth_element(finite.begin(), finite.begin() + static_cast<long>(finite.size() / 2), finite.end());
  const double spacing = finite[finite.size() / 2];
  if (!(spacing > 0.0)) return;
  for (Index p = 0; p < points.rows(); ++p) {
    const double dp = d[static_cast<std::size_t>(p)];
    if (dp > kGrossBlunderFactor * spacing) out.push_back({p, undeformed, dp, spacing});
  }
  // Two blunders typed alike (both at X = 150) are each other's nearest mark: they are
  // isolated from the grid all the same, but this test sees them as a pair; fine.
  for (const GrossBlunder& b : out)
    if (b.undeformed == undeformed) points.row(b.point).setConstant(std::numeric_limits<double>::quiet_NaN());
}

}  // namespace

std::vector<GrossBlunder> screen_gross_blunders(GridData& grid) {
  std::vector<GrossBlunder> out;
  screen_state(grid.undeformed, true, out);
  screen_state(grid.deformed, false, out);
  return out;
}

void report_gross_blunders(AnalysisResult& result, const GridData& grid, const std::vector<GrossBlunder>& blunders,
                           const std::string& units) {
  for (const GrossBlunder& b : blunders) {
    if (b.point < static_cast<Index>(result.points.size())) {
      PointResult& p = result.points[static_cast<std::size_t>(b.point)];
      p.status = b.undeformed ? kStatusOutlierUndeformed : kStatusOutlierDeformed;
      p.strain.reset();
    }
    result.warnings.push_back(fmt::format(
        "mark {}: its {} position lies {:.4g} {} from the nearest mark ({:.1f} times the mark spacing {:.4g} {}): a "
        "gross blunder (a number typed wrong?), left out of the analysis",
        grid.ids[static_cast<std::size_t>(b.point)], b.undeformed ? "undeformed" : "deformed", b.distance, units,
        b.distance / b.spacing, b.spacing, units));
  }
}

}  // namespace sf::gsa

#include "gsa/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

namespace sf::gsa {

StrainError strain_error(const GridData& grid, const AnalysisResult& result, const std::vector<ExactStrain>& exact,
                         int border) {
  StrainError e;
  std::set<std::pair<long, long>> present;
  for (Index p = 0; p < grid.n_points(); ++p) present.insert({grid.i[p], grid.j[p]});
  // Interior: every grid position within `border` steps (a (2 border + 1)^2 window) holds a mark.
  auto interior = [&](Index p) {
    for (long di = -border; di <= border; ++di)
      for (long dj = -border; dj <= border; ++dj)
        if (!present.count({grid.i[p] + di, grid.j[p] + dj})) return false;
    return true;
  };
  double s1 = 0, s2 = 0, ss = 0;
  for (Index p = 0; p < grid.n_points(); ++p) {
    if (!interior(p)) continue;
    const PointResult& pr = result.points[p];
    if (!pr.strain) {
      ++e.n_missing;
      continue;
    }
    const double d1 = pr.strain->green(0) - 0.5 * (exact[p].lambda1 * exact[p].lambda1 - 1.0);
    const double d2 = pr.strain->green(1) - 0.5 * (exact[p].lambda2 * exact[p].lambda2 - 1.0);
    s1 += d1 * d1;
    s2 += d2 * d2;
    e.max_abs = std::max({e.max_abs, std::abs(d1), std::abs(d2)});
    if (std::isfinite(pr.shear_angle_deg)) {
      const double ds = pr.shear_angle_deg - exact[p].shear_angle_deg;
      ss += ds * ds;
    }
    ++e.n;
  }
  if (e.n > 0) {
    e.rms_e1 = std::sqrt(s1 / e.n);
    e.rms_e2 = std::sqrt(s2 / e.n);
    e.rms_shear_deg = std::sqrt(ss / e.n);
  }
  return e;
}

}  // namespace sf::gsa

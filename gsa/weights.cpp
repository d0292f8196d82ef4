#include "gsa/weights.hpp"

#include <algorithm>
#include <cmath>

namespace sf::gsa {

SigmaWeights sigma_weights(const std::vector<double>& sigma, const std::vector<Index>& points, bool enabled) {
  SigmaWeights out;
  const auto m = static_cast<Index>(points.size());
  out.weight = VecX::Ones(m);
  if (!enabled || sigma.empty()) return out;
  std::vector<double> given;
  given.reserve(points.size());
  for (const Index p : points) {
    const double s = sigma[static_cast<std::size_t>(p)];
    if (std::isfinite(s) && s > 0) given.push_back(s);
  }
  if (given.empty()) return out;
  out.used = true;
  out.n_with_sigma = static_cast<Index>(given.size());
  const auto mid = given.begin() + static_cast<std::ptrdiff_t>(given.size() / 2);
  std::nth_element(given.begin(), mid, given.end());
  out.sigma_ref = *mid;
  const double floor = kSigmaFloor * out.sigma_ref;
  out.min_weight = out.max_weight = 1.0;
  bool first = true;
  for (Index k = 0; k < m; ++k) {
    double s = sigma[static_cast<std::size_t>(points[static_cast<std::size_t>(k)])];
    if (std::isnan(s) || s < 0) continue;  // no sigma (or a negative one, no uncertainty): weight 1
    if (s < floor) {                       // 0 or tiny: the floor
      s = floor;
      ++out.n_floored;
    }
    // sigma_ref / s first: equal sigmas give exactly 1.
    const double r = out.sigma_ref / s;
    out.weight[k] = r * r;
    if (out.weight[k] < kNegligibleWeight) {
      out.weight[k] = 0.0;
      ++out.n_left_out;
    }
    out.min_weight = first ? out.weight[k] : std::min(out.min_weight, out.weight[k]);
    out.max_weight = first ? out.weight[k] : std::max(out.max_weight, out.weight[k]);
    first = false;
  }
  return out;
}

}  // namespace sf::gsa

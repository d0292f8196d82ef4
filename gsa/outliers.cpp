#include "gsa/outliers.hpp"

#include <algorithm>

namespace sf::gsa {

namespace {

// Residuals beyond this fraction of the mark spacing may be flagged, however small the
// noise (a noise-free grid has a robust sigma of round-off).
constexpr double kFloorPerSpacing = 0.02;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Median of |r| over sigma for Gaussian residuals with `dims` components.
double median_over_sigma(ResidualKind kind) { return kind == ResidualKind::kNormal ? 0.6745 : 1.5382; }

}  // namespace

const char* to_string(OutlierReason reason) {
  switch (reason) {
    case OutlierReason::kResidual: return "residual";
  }
  return "residual";
}

double outlier_threshold(const VecX& residual, const VecX& weight, ResidualKind kind, const OutlierOptions& options,
                         double mark_spacing) {
  std::vector<double> r;
  for (Index i = 0; i < residual.size(); ++i)
    if (weight[i] > 0) r.push_back(residual[i]);
  return std::max(options.sigma * median(r) / median_over_sigma(kind), kFloorPerSpacing * mark_spacing);
}

std::vector<OutlierFlag> detect_outliers(const VecX& residual, const VecX& weight, ResidualKind kind,
                                         const OutlierOptions& options, double mark_spacing) {
  const double threshold = outlier_threshold(residual, weight, kind, options, mark_spacing);
  double worst = 0.0;
  for (Index i = 0; i < residual.size(); ++i)
    if (weight[i] > 0 && residual[i] > threshold) worst = std::max(worst, residual[i]);
  std::vector<OutlierFlag> out;
  for (Index i = 0; i < residual.size(); ++i)
    if (weight[i] > 0 && residual[i] > threshold && residual[i] >= 0.5 * worst)
      out.push_back({i, OutlierReason::kResidual, residual[i], threshold});
  return out;
}

std::vector<OutlierFlag> take_readmitted(std::vector<OutlierFlag>& flags, const VecX& residual, double threshold) {
  std::vector<OutlierFlag> readmitted, kept;
  for (const OutlierFlag& f : flags) (residual[f.mark] < threshold ? readmitted : kept).push_back(f);
  flags = std::move(kept);
  return readmitted;
}

}  // namespace sf::gsa

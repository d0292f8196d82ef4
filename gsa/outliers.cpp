#include "gsa/outliers.hpp"

#include <fmt/format.h>

#include "gsa/blunders.hpp"

namespace sf::gsa {

const char* to_string(OutlierReason reason) {
  switch (reason) {
    case OutlierReason::kUndeformedOffNeighbours:
      return "undeformed position off its neighbours' surface";
    case OutlierReason::kDeformedOffNeighbours:
      return "deformed position off its neighbours' deformation";
  }
  return "";
}

const char* code(OutlierReason reason) {
  switch (reason) {
    case OutlierReason::kUndeformedOffNeighbours:
      return "undeformed_off_neighbours";
    case OutlierReason::kDeformedOffNeighbours:
      return "deformed_off_neighbours";
  }
  return "";
}

std::string describe(const OutlierFlag& f, double sigma, const std::string& units) {
  return fmt::format("{} by {:.4g} {} (threshold {:.4g} {} = {:g} x noise {:.4g} {})", to_string(f.reason), f.deviation,
                     units, f.threshold, units, sigma, f.noise, units);
}

MarkOutliers find_outliers(const FitMarks& marks, const Points3& deformed, double mark_spacing,
                           const OutlierOptions& options) {
  const Index m = marks.size();
  BlunderOptions bo;
  bo.threshold = options.sigma;
  bo.isolation = options.isolation;
  bo.neighbours = options.neighbours;
  bo.floor = options.floor * mark_spacing;
  MarkOutliers out;
  const std::vector<bool> all(static_cast<std::size_t>(m), true);
  const BlunderCheck u = find_blunders(marks.undeformed, marks.undeformed, all, true, bo);
  out.noise_undeformed = u.noise;
  std::vector<bool> usable(static_cast<std::size_t>(m));
  for (Index k = 0; k < m; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (u.flagged[kk])
      out.undeformed.push_back({k, OutlierReason::kUndeformedOffNeighbours, u.deviation[kk], u.threshold, u.noise});
    usable[kk] = !u.flagged[kk] && deformed.row(k).allFinite();
  }
  const BlunderCheck d = find_blunders(marks.undeformed, deformed, usable, false, bo);
  out.noise_deformed = d.noise;
  for (Index k = 0; k < m; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (d.flagged[kk])
      out.deformed.push_back({k, OutlierReason::kDeformedOffNeighbours, d.deviation[kk], d.threshold, d.noise});
  }
  return out;
}

std::vector<OutlierFlag> take_readmitted(std::vector<OutlierFlag>& flags, const VecX& residual) {
  std::vector<OutlierFlag> readmitted, kept;
  for (const OutlierFlag& f : flags) (residual[f.mark] <= f.threshold ? readmitted : kept).push_back(f);
  flags = std::move(kept);
  return readmitted;
}

}  // namespace sf::gsa

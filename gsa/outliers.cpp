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

namespace {
BlunderOptions blunder_options(double mark_spacing, const OutlierOptions& options) {
  BlunderOptions bo;
  bo.threshold = options.sigma;
  bo.isolation = options.isolation;
  bo.neighbours = options.neighbours;
  bo.floor = options.floor * mark_spacing;
  return bo;
}
}  // namespace

std::shared_ptr<const BlunderNeighbours> undeformed_outlier_neighbours(const FitMarks& marks,
                                                                       const OutlierOptions& options) {
  const std::vector<bool> all(static_cast<std::size_t>(marks.size()), true);
  return blunder_neighbours(marks.undeformed, marks.undeformed, all, blunder_options(0.0, options));
}

MarkOutliers find_undeformed_outliers(const FitMarks& marks, double mark_spacing, const OutlierOptions& options,
                                      std::shared_ptr<const BlunderNeighbours> neighbours) {
  const Index m = marks.size();
  MarkOutliers out;
  const std::vector<bool> all(static_cast<std::size_t>(m), true);
  const BlunderOptions bo = blunder_options(mark_spacing, options);
  const BlunderCheck u = find_blunders(marks.undeformed, marks.undeformed, all, true, bo, std::move(neighbours));
  out.noise_undeformed = u.noise;
  out.neighbours = u.neighbours;
  for (Index k = 0; k < m; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (u.flagged[kk])
      out.undeformed.push_back({k, OutlierReason::kUndeformedOffNeighbours, u.deviation[kk], u.threshold_of(k, bo),
                                u.noise_along(k)});
  }
  return out;
}

void find_deformed_outliers(const FitMarks& marks, const Points3& deformed, double mark_spacing,
                            const OutlierOptions& options, MarkOutliers& out) {
  const Index m = marks.size();
  std::vector<bool> usable(static_cast<std::size_t>(m));
  for (Index k = 0; k < m; ++k) usable[static_cast<std::size_t>(k)] = deformed.row(k).allFinite();
  for (const OutlierFlag& f : out.undeformed) usable[static_cast<std::size_t>(f.mark)] = false;
  const BlunderOptions bo = blunder_options(mark_spacing, options);
  const BlunderCheck d = find_blunders(marks.undeformed, deformed, usable, false, bo, out.neighbours);
  out.noise_deformed = d.noise;
  out.noise_deformed_axis = d.noise_axis;
  out.noise_deformed_across = d.noise_across;
  out.deformed.clear();
  for (Index k = 0; k < m; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (d.flagged[kk])
      out.deformed.push_back({k, OutlierReason::kDeformedOffNeighbours, d.deviation[kk], d.threshold_of(k, bo),
                              d.noise_along(k)});
  }
}

MarkOutliers find_outliers(const FitMarks& marks, const Points3& deformed, double mark_spacing,
                           const OutlierOptions& options) {
  MarkOutliers out = find_undeformed_outliers(marks, mark_spacing, options);
  find_deformed_outliers(marks, deformed, mark_spacing, options, out);
  return out;
}

std::vector<OutlierFlag> take_readmitted(std::vector<OutlierFlag>& flags, const VecX& residual) {
  std::vector<OutlierFlag> readmitted, kept;
  for (const OutlierFlag& f : flags) (residual[f.mark] <= f.threshold ? readmitted : kept).push_back(f);
  flags = std::move(kept);
  return readmitted;
}

}  // namespace sf::gsa

#include "gsa/flc.hpp"

#include <algorithm>
#include <cmath>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"

namespace sf::gsa {

double FormingLimitCurve::major_at(double m) const {
  if (minor.size() < 2 || !std::isfinite(m) || m < minor.front() || m > minor.back())
    return std::numeric_limits<double>::quiet_NaN();
  const auto it = std::upper_bound(minor.begin(), minor.end(), m);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(it - minor.begin()), minor.size() - 1);
  const std::size_t a = i - 1, b = i;
  if (minor[b] == minor[a]) return std::min(major[a], major[b]);
  const double t = (m - minor[a]) / (minor[b] - minor[a]);
  return (1 - t) * major[a] + t * major[b];
}

FormingLimitCurve read_flc(const std::string& path) {
  const io::CsvTable t = io::read_csv(path);
  const std::size_t cm = t.column_index("minor"), cM = t.column_index("major");
  std::vector<std::pair<double, double>> pts;
  for (std::size_t r = 0; r < t.n_rows(); ++r) pts.emplace_back(t.number(r, cm), t.number(r, cM));
  if (pts.size() < 2)
    throw InputError(path + ": a forming limit curve needs at least 2 rows (minor, major), found " +
                     std::to_string(pts.size()));
  // One major strain per minor strain: the rows must run monotonically in minor strain (either
  // way); a row that turns back is named with its line.
  if (pts.size() >= 2) {
    const bool rising = pts[1].first > pts[0].first;
    for (std::size_t r = 1; r < pts.size(); ++r) {
      const double prev = pts[r - 1].first, cur = pts[r].first;
      if (rising ? cur > prev : cur < prev) continue;
      throw InputError(path + ":" + std::to_string(t.line(r)) + ":" + std::to_string(t.char_column(r, cm)) +
                       ": minor strain " + std::string(t.cell(r, cm)) + " after " + std::string(t.cell(r - 1, cm)) +
                       " on line " + std::to_string(t.line(r - 1)) +
                       ": a forming limit curve must be monotone in minor strain (every row's minor strain " +
                       (rising ? "greater" : "smaller") + " than the previous row's, one major strain per minor)");
    }
  }
  std::stable_sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  FormingLimitCurve c;
  c.source = path;
  for (const auto& [m, M] : pts) {
    c.minor.push_back(m);
    c.major.push_back(M);
  }
  return c;
}

FlcMargins flc_margins(const FormingLimitCurve& curve, const MarkStrains& marks, StrainMeasure measure) {
  FlcMargins out;
  out.source = curve.source;
  out.measure = measure;
  out.margin.resize(marks.major.size());
  for (std::size_t i = 0; i < marks.major.size(); ++i) {
    const double margin = curve.major_at(marks.minor[i]) - marks.major[i];
    out.margin[i] = margin;
    if (std::isfinite(marks.major[i]) && std::isfinite(marks.minor[i])) ++out.n_marks;
    if (!std::isfinite(margin)) continue;
    if (margin < 0) ++out.n_beyond;
    if (!(std::isfinite(out.min_margin) && out.min_margin <= margin)) out.min_margin = margin;
  }
  return out;
}

std::string flc_margin_comment(const FlcMargins& m) {
  return "# flc_margin: forming limit major strain at the mark's minor strain minus its major strain (" +
         measure_word(m.measure) + " strain; curve " + m.source +
         "); negative = beyond the limit; empty where the mark has no strain or its minor strain is outside the "
         "curve";
}

}  // namespace sf::gsa

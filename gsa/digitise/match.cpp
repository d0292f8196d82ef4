#include "gsa/digitise/match.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fmt/format.h>
#include <map>
#include <unordered_map>

namespace sf::gsa::digitise {

namespace {

Eigen::Matrix2i symmetry_matrix(int k) {
  static const Eigen::Matrix2i rot[4] = {
      (Eigen::Matrix2i() << 1, 0, 0, 1).finished(), (Eigen::Matrix2i() << 0, -1, 1, 0).finished(),
      (Eigen::Matrix2i() << -1, 0, 0, -1).finished(), (Eigen::Matrix2i() << 0, 1, -1, 0).finished()};
  static const Eigen::Matrix2i swap = (Eigen::Matrix2i() << 0, 1, 1, 0).finished();
  return k < 4 ? rot[k] : Eigen::Matrix2i(rot[k - 4] * swap);
}

std::int64_t key(const Label& l) {
  return (static_cast<std::int64_t>(l.x()) << 32) ^ static_cast<std::uint32_t>(l.y());
}

}  // namespace

Label LabelTransform::apply(const Label& l) const {
  const Label r2(static_cast<int>(std::lround(2 * reference.x())), static_cast<int>(std::lround(2 * reference.y())));
  const Label d = symmetry_matrix(symmetry) * (2 * l - r2) + r2;
  return Label(d.x() / 2, d.y() / 2) + offset;
}

MatchResult match_view(const Camera& cam0, const ViewMarks& v0, const Camera& camv, const ViewMarks& vv,
                       const MatchOptions& o) {
  MatchResult res;
  const std::size_t n0 = v0.centres.size(), nv = vv.centres.size();
  std::vector<Vec3> x0(n0), xv(nv);
  for (std::size_t k = 0; k < n0; ++k) {
    const Vec2 x = cam0.pixel_to_normalised(v0.centres[k]);
    x0[k] = Vec3(x.x(), x.y(), 1.0);
  }
  for (std::size_t k = 0; k < nv; ++k) {
    const Vec2 x = camv.pixel_to_normalised(vv.centres[k]);
    xv[k] = Vec3(x.x(), x.y(), 1.0);
  }
  const Mat3 E = essential_matrix(camv, cam0);  // x0^T E xv = 0
  std::vector<Vec3> lines(nv);
  for (std::size_t k = 0; k < nv; ++k) {
    lines[k] = E * xv[k];
    lines[k] /= std::max(std::hypot(lines[k].x(), lines[k].y()), 1e-300);  // distances in normalised units
  }
  const double tol = o.tolerance_px / cam0.focal();
  std::unordered_map<std::int64_t, std::size_t> at0;
  for (std::size_t k = 0; k < n0; ++k) at0[key(v0.labels[k])] = k;

  // Candidate (S, o).
  std::vector<LabelTransform> cands;
  const bool fixed = v0.has_reference && vv.has_reference && v0.reference_lattice == vv.reference_lattice;
  // Rotations only: every camera sees the printed side, and each view's labels run along
  // its image's rows and down its columns, so two views' labels never differ by a mirror.
  for (int s = 0; s < 4; ++s) {
    LabelTransform t = LabelTransform::identity(v0.reference_lattice);
    t.symmetry = s;
    if (fixed) {
      cands.push_back(t);
      continue;
    }
    // Votes for shifts from marks near the middle of the view.
    Vec2 mid = Vec2::Zero();
    for (const Vec2& c : vv.centres) mid += c;
    mid /= static_cast<double>(std::max<std::size_t>(nv, 1));
    std::vector<std::size_t> order(nv);
    for (std::size_t k = 0; k < nv; ++k) order[k] = k;
    const std::size_t n_samples = std::min<std::size_t>(nv, 40);
    std::partial_sort(order.begin(), order.begin() + n_samples, order.end(), [&](std::size_t a, std::size_t b) {
      return (vv.centres[a] - mid).squaredNorm() < (vv.centres[b] - mid).squaredNorm();
    });
    std::map<std::pair<int, int>, int> votes;
    for (std::size_t q = 0; q < n_samples; ++q) {
      const std::size_t m = order[q];
      const Label mapped = t.apply(vv.labels[m]);
      for (std::size_t k = 0; k < n0; ++k)
        if (std::abs(lines[m].dot(x0[k])) < tol) {
          const Label off = v0.labels[k] - mapped;
          ++votes[{off.x(), off.y()}];
        }
    }
    std::vector<std::pair<int, std::pair<int, int>>> ranked;
    for (const auto& [off, n] : votes) ranked.push_back({n, off});
    std::sort(ranked.rbegin(), ranked.rend());
    for (std::size_t q = 0; q < std::min<std::size_t>(ranked.size(), 4); ++q) {
      LabelTransform c = t;
      c.offset = Label(ranked[q].second.first, ranked[q].second.second);
      cands.push_back(c);
    }
  }
  // Scores.
  struct Score {
    Index consistent = 0, overlap = 0;
  };
  std::vector<Score> scores(cands.size());
  std::size_t best = 0;
  for (std::size_t c = 0; c < cands.size(); ++c) {
    for (std::size_t m = 0; m < nv; ++m) {
      auto it = at0.find(key(cands[c].apply(vv.labels[m])));
      if (it == at0.end()) continue;
      ++scores[c].overlap;
      if (std::abs(lines[m].dot(x0[it->second])) < tol) ++scores[c].consistent;
    }
    if (scores[c].consistent > scores[best].consistent) best = c;
  }
  Index second = 0;
  for (std::size_t c = 0; c < cands.size(); ++c)
    if (c != best) second = std::max(second, scores[c].consistent);
  res.transform = cands.empty() ? LabelTransform::identity(v0.reference_lattice) : cands[best];
  res.n_consistent = cands.empty() ? 0 : scores[best].consistent;
  res.n_second = second;
  const Index overlap = cands.empty() ? 0 : scores[best].overlap;
  if (res.n_consistent < 6) {
    res.message = fmt::format(
        "only {} marks agree with the epipolar geometry of camera 0 (need 6): does the "
        "calibration belong to these cameras and images?",
        res.n_consistent);
    return res;
  }
  if (res.n_consistent < 0.8 * overlap) {
    res.message = fmt::format(
        "only {} of {} marks seen in both views agree with the epipolar geometry (within {} "
        "px): does the calibration belong to these cameras, and were the images taken "
        "at the same time?",
        res.n_consistent, overlap, o.tolerance_px);
    return res;
  }
  if (second >= o.ambiguity * res.n_consistent) {
    res.message = fmt::format(
        "the labels are ambiguous along the epipolar lines ({} marks agree with the best "
        "match, {} with another); print a reference mark, turn the part so the grid does "
        "not run along the cameras' baseline, or add a third camera",
        res.n_consistent, second);
    return res;
  }
  res.ok = true;
  return res;
}

}  // namespace sf::gsa::digitise

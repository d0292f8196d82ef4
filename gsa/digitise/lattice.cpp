#include "gsa/digitise/lattice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <queue>
#include <unordered_map>

namespace sf::gsa::digitise {

// ---------------------------------------------------------------------------------------
// PointGrid

PointGrid::PointGrid(const std::vector<Vec2>& points, double cell) : points_(points), cell_(std::max(cell, 1e-9)) {
  if (points.empty()) {
    origin_ = Vec2::Zero();
    buckets_.resize(1);
    return;
  }
  Vec2 lo = points[0], hi = points[0];
  for (const Vec2& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  origin_ = lo;
  // Keep the bucket count bounded whatever the cell size asked for.
  const double span = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  cell_ = std::max(cell_, span / 2048.0);
  nx_ = static_cast<int>((hi.x() - lo.x()) / cell_) + 1;
  ny_ = static_cast<int>((hi.y() - lo.y()) / cell_) + 1;
  buckets_.resize(static_cast<std::size_t>(nx_) * ny_);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const int bx = static_cast<int>((points[k].x() - lo.x()) / cell_);
    const int by = static_cast<int>((points[k].y() - lo.y()) / cell_);
    buckets_[static_cast<std::size_t>(by) * nx_ + bx].push_back(static_cast<Index>(k));
  }
}

std::vector<Index> PointGrid::within(const Vec2& p, double radius) const {
  std::vector<Index> out;
  if (points_.empty() || !(radius >= 0)) return out;
  const int x0 = std::max(0, static_cast<int>(std::floor((p.x() - radius - origin_.x()) / cell_)));
  const int x1 = std::min(nx_ - 1, static_cast<int>(std::floor((p.x() + radius - origin_.x()) / cell_)));
  const int y0 = std::max(0, static_cast<int>(std::floor((p.y() - radius - origin_.y()) / cell_)));
  const int y1 = std::min(ny_ - 1, static_cast<int>(std::floor((p.y() + radius - origin_.y()) / cell_)));
  const double r2 = radius * radius;
  for (int by = y0; by <= y1; ++by)
    for (int bx = x0; bx <= x1; ++bx)
      for (Index k : buckets_[static_cast<std::size_t>(by) * nx_ + bx])
        if ((points_[k] - p).squaredNorm() <= r2) out.push_back(k);
  return out;
}

Index PointGrid::nearest(const Vec2& p, double max_radius, Index exclude) const {
  Index best = -1;
  double best_d = max_radius * max_radius;
  for (Index k : within(p, max_radius)) {
    if (k == exclude) continue;
    const double d = (points_[k] - p).squaredNorm();
    if (d <= best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

double median_spacing(const std::vector<Vec2>& points) {
  if (points.size() < 2) return 0.0;
  Vec2 lo = points[0], hi = points[0];
  for (const Vec2& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double area = std::max((hi.x() - lo.x()) * (hi.y() - lo.y()), 1.0);
  const double s = std::max(std::sqrt(area / static_cast<double>(points.size())), 1.0);
  const PointGrid grid(points, s);
  std::vector<double> d;
  d.reserve(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    double radius = 2 * s;
    for (int tries = 0; tries < 6; ++tries, radius *= 3) {
      const Index n = grid.nearest(points[k], radius, static_cast<Index>(k));
      if (n >= 0) {
        d.push_back((points[n] - points[k]).norm());
        break;
      }
    }
  }
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

// ---------------------------------------------------------------------------------------
// Lattice growth

Index LatticeResult::n_labelled() const {
  Index n = 0;
  for (const auto& l : labels) n += l ? 1 : 0;
  return n;
}

namespace {

std::int64_t key(const Label& l) {
  return (static_cast<std::int64_t>(l.x()) << 32) ^ static_cast<std::uint32_t>(l.y());
}

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace

LatticeResult grow_lattice(const std::vector<Vec2>& P, Index seed, const LatticeOptions& o) {
  const Index n = static_cast<Index>(P.size());
  LatticeResult res;
  res.labels.assign(P.size(), std::nullopt);
  res.axis_i.assign(P.size(), Vec2::Zero());
  res.axis_j.assign(P.size(), Vec2::Zero());
  if (seed < 0 || seed >= n) return res;
  res.labels[seed] = Label(0, 0);
  const double d = median_spacing(P);
  if (n < 3 || !(d > 0)) return res;
  const PointGrid grid(P, d);

  // Seed axes: the two shortest non-parallel neighbour vectors.
  const Index nn = grid.nearest(P[seed], 4 * d, seed);
  if (nn < 0) return res;
  const double ds = (P[nn] - P[seed]).norm();
  std::vector<Vec2> nb;
  for (Index k : grid.within(P[seed], 2.5 * ds))
    if (k != seed) nb.push_back(P[k] - P[seed]);
  std::sort(nb.begin(), nb.end(), [](const Vec2& a, const Vec2& b) { return a.squaredNorm() < b.squaredNorm(); });
  if (nb.size() < 2) return res;
  const Vec2 A = nb[0];
  Vec2 B = Vec2::Zero();
  for (std::size_t k = 1; k < nb.size(); ++k)
    if (std::abs(cross(A, nb[k])) > 0.5 * A.norm() * nb[k].norm()) {
      B = nb[k];
      break;
    }
  if (B.isZero()) return res;
  // Orientation: axis i the most rightward of +-A, +-B; axis j the other pair, downward.
  Vec2 ai, aj;
  if (std::abs(A.x()) >= std::abs(B.x())) {
    ai = A.x() >= 0 ? A : Vec2(-A);
    aj = B.y() >= 0 ? B : Vec2(-B);
  } else {
    ai = B.x() >= 0 ? B : Vec2(-B);
    aj = A.y() >= 0 ? A : Vec2(-A);
  }
  res.axis_i[seed] = ai;
  res.axis_j[seed] = aj;

  std::unordered_map<std::int64_t, Index> owner;
  owner[key(Label(0, 0))] = seed;
  auto owner_of = [&](const Label& l) -> Index {
    auto it = owner.find(key(l));
    return it == owner.end() ? -1 : it->second;
  };
  std::vector<char> conflict(P.size(), 0), ambiguous(P.size(), 0), expanded(P.size(), 0);
  using Item = std::pair<double, Index>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  queue.push({0.0, seed});
  const Label dirs[4] = {Label(1, 0), Label(-1, 0), Label(0, 1), Label(0, -1)};

  while (!queue.empty()) {
    const Index p = queue.top().second;
    queue.pop();
    if (expanded[p] || !res.labels[p] || conflict[p]) continue;
    expanded[p] = 1;
    const Label L = *res.labels[p];
    // Local axes from the labelled neighbours.
    for (int axis = 0; axis < 2; ++axis) {
      const Label e = axis == 0 ? Label(1, 0) : Label(0, 1);
      const Index f = owner_of(L + e), b = owner_of(L - e);
      Vec2& a = axis == 0 ? res.axis_i[p] : res.axis_j[p];
      if (f >= 0 && b >= 0)
        a = 0.5 * (P[f] - P[b]);
      else if (f >= 0)
        a = P[f] - P[p];
      else if (b >= 0)
        a = P[p] - P[b];
    }
    for (const Label& dir : dirs) {
      const Label T = L + dir;
      const Index b1 = owner_of(L - dir);
      const Index b2 = b1 >= 0 ? owner_of(L - 2 * dir) : -1;
      const Vec2 step = dir.x() != 0 ? Vec2(dir.x() * res.axis_i[p]) : Vec2(dir.y() * res.axis_j[p]);
      Vec2 pred;
      if (b1 >= 0 && b2 >= 0)
        pred = 3.0 * P[p] - 3.0 * P[b1] + P[b2];
      else if (b1 >= 0)
        pred = 2.0 * P[p] - P[b1];
      else
        pred = P[p] + step;
      const double ell = std::max((pred - P[p]).norm(), 1e-9);
      const double radius = o.tolerance * ell;
      const Index taken = owner_of(T);
      if (taken >= 0) {
        // Another path got there first: it must agree.
        if ((P[taken] - pred).norm() > radius && !conflict[taken]) {
          conflict[taken] = 1;
          conflict[p] = 1;
        }
        continue;
      }
      const std::vector<Index> cands = grid.within(pred, radius);
      if (cands.empty()) continue;
      if (cands.size() > 1) {
        for (Index c : cands) ambiguous[c] = 1;
        continue;
      }
      const Index c = cands[0];
      if (res.labels[c]) {  // already labelled with another label
        conflict[c] = 1;
        conflict[p] = 1;
        continue;
      }
      res.labels[c] = T;
      owner[key(T)] = c;
      res.axis_i[c] = res.axis_i[p];
      res.axis_j[c] = res.axis_j[p];
      if (dir.x() != 0)
        res.axis_i[c] = dir.x() * (P[c] - P[p]);
      else
        res.axis_j[c] = dir.y() * (P[c] - P[p]);
      queue.push({(P[c] - pred).norm() / ell, c});
    }
  }
  for (Index k = 0; k < n; ++k) {
    if (conflict[k]) {
      res.labels[k].reset();
      res.conflicting.push_back(k);
    } else if (ambiguous[k] && !res.labels[k]) {
      res.ambiguous.push_back(k);
    }
  }
  return res;
}

}  // namespace sf::gsa::digitise

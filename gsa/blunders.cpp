#include "gsa/blunders.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "common/core/error.hpp"
#include "common/core/parallel.hpp"
#include "common/mesh/neighbours.hpp"

namespace sf::gsa {

namespace {

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Median of a chi distribution with k degrees of freedom (|e| of k unit normals).
double chi_median(int k) { return k == 1 ? 0.674490 : 1.538172; }
// Median of a chi-square distribution with 3 degrees of freedom.
constexpr double kChiSquare3Median = 2.365974;

// Robust covariance of the deviation vectors `v` (rows `use`): the covariance of the
// vectors within 3 x the median squared Mahalanobis distance, three times, then scaled so
// that the median squared distance is chi-square(3)'s median. A small ridge keeps it
// invertible for planar (2-D) data.
Mat3 robust_covariance(const Points3& v, const std::vector<Index>& use) {
  auto ridged_inverse = [](const Mat3& c) { return Mat3((c + 1e-12 * c.trace() * Mat3::Identity()).inverse()); };
  Mat3 cov = Mat3::Zero();
  for (Index p : use) cov += v.row(p).transpose() * v.row(p);
  cov /= std::max(1.0, static_cast<double>(use.size()));
  if (!(cov.trace() > 0)) return cov;
  std::vector<double> d2(use.size());
  auto distances = [&](const Mat3& c) {
    const Mat3 ci = ridged_inverse(c);
    for (std::size_t i = 0; i < use.size(); ++i) d2[i] = v.row(use[i]) * ci * v.row(use[i]).transpose();
  };
  for (int it = 0; it < 3; ++it) {
    distances(cov);
    const double cut = 3.0 * median_of(d2);
    Mat3 next = Mat3::Zero();
    double count = 0.0;
    for (std::size_t i = 0; i < use.size(); ++i)
      if (d2[i] <= cut) next += v.row(use[i]).transpose() * v.row(use[i]), count += 1.0;
    if (!(next.trace() > 0)) break;
    cov = next / count;
  }
  distances(cov);
  return cov * (median_of(d2) / kChiSquare3Median);
}

// A point's deviation (mm): its length e and, in the deformed state, the vector v
// (standardised like e).
struct Deviation {
  double e = std::numeric_limits<double>::quiet_NaN();
  Vec3 v = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
};

// Working storage of deviation(), one per thread (thread_local below): the matrices keep
// their size from point to point, so a check of 1e6 points does not allocate a dozen
// small heap blocks per fit. The same Eigen types and expressions as with fresh
// matrices, so the same operations in the same order: the deviations are the same bits.
struct DeviationWork {
  MatX A, b, ata, atb, c;
  VecX e0;
  Eigen::LDLT<MatX> ldlt;
  std::vector<Index> others;  // a neighbour's neighbours without the candidate
};

DeviationWork& deviation_work() {
  thread_local DeviationWork work;
  return work;
}

// Leave-one-out deviation of point p from the local quadratic of its neighbours.
Deviation deviation(const Points3& X, const Points3& v, Index p, const std::vector<Index>& nb, bool normal_only) {
  const Index k = static_cast<Index>(nb.size());
  if (k < 4) return {};
  Vec3 centre = Vec3::Zero();
  for (Index q : nb) centre += X.row(q).transpose();
  centre /= static_cast<double>(k);
  Mat3 cov = Mat3::Zero();
  double scale = 0.0;
  for (Index q : nb) {
    const Vec3 d = X.row(q).transpose() - centre;
    cov += d * d.transpose();
    scale += (X.row(q) - X.row(p)).norm();
  }
  scale = std::max(scale / static_cast<double>(k), 1e-300);
  const Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  const Vec3 n = es.eigenvectors().col(0), t1 = es.eigenvectors().col(2), t2 = es.eigenvectors().col(1);
  // Quadratic with >= 10 neighbours, else linear; coordinates scaled to O(1).
  const int terms = k >= 10 ? 6 : 3;
  DeviationWork& w = deviation_work();
  MatX& A = w.A;
  MatX& b = w.b;
  A.resize(k, terms);
  b.resize(k, normal_only ? 1 : 3);
  for (Index i = 0; i < k; ++i) {
    const Index q = nb[static_cast<std::size_t>(i)];
    const Vec3 d = X.row(q).transpose() - X.row(p).transpose();
    const double s = d.dot(t1) / scale, t = d.dot(t2) / scale;
    A(i, 0) = 1.0;
    A(i, 1) = s;
    A(i, 2) = t;
    if (terms == 6) {
      A(i, 3) = s * s;
      A(i, 4) = s * t;
      A(i, 5) = t * t;
    }
    if (normal_only)
      b(i, 0) = d.dot(n);
    else
      b.row(i) = v.row(q) - v.row(p);  // relative to the point: the prediction is then -deviation
  }
  w.ata.noalias() = A.transpose() * A;
  const Eigen::LDLT<MatX>& ldlt = w.ldlt.compute(w.ata);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-10)) return {};
  w.atb.noalias() = A.transpose() * b;
  w.c = ldlt.solve(w.atb);
  // Standardised: the prediction c0 carries noise of variance v0 sigma^2 on top of
  // the point's own (v0 = (A^T A)^-1_00: larger at gaps and at the outline).
  w.e0 = ldlt.solve(VecX::Unit(terms, 0));
  const double f = 1.0 / std::sqrt(1.0 + w.e0[0]);
  Deviation out;
  out.e = w.c.row(0).norm() * f;
  if (!normal_only) out.v = w.c.row(0).transpose() * f;
  return out;
}

// The first `k` of `candidates` (nearest first) neither flagged nor `left_out`, into `nb`
// (its storage reused).
void nearest_unflagged(const std::vector<Index>& candidates, const std::vector<bool>& flagged, int k,
                       std::vector<Index>& nb, Index left_out = -1) {
  nb.clear();
  nb.reserve(static_cast<std::size_t>(k));
  for (Index q : candidates) {
    if (static_cast<int>(nb.size()) == k) break;
    if (q != left_out && !flagged[static_cast<std::size_t>(q)]) nb.push_back(q);
  }
}

}  // namespace

void BlunderOptions::validate() const {
  if (neighbours < 8)
    throw UsageError("blunder check: at least 8 neighbours are needed, found " + std::to_string(neighbours));
  if (!(threshold > 0.0) || !std::isfinite(threshold))
    throw UsageError("blunder check: the threshold must be a positive number");
  if (!(isolation >= 1.0) || !std::isfinite(isolation))
    throw UsageError("blunder check: the isolation factor must be >= 1");
  if (passes < 1) throw UsageError("blunder check: at least one pass");
}

double BlunderCheck::noise_along(Index p) const {
  const auto pp = static_cast<std::size_t>(p);
  return score[pp] > 0 && std::isfinite(score[pp]) ? deviation[pp] / score[pp] : noise;
}

double BlunderCheck::threshold_of(Index p, const BlunderOptions& o) const {
  return std::max(o.threshold * noise_along(p), o.floor);
}

Index BlunderCheck::n_flagged() const { return static_cast<Index>(std::count(flagged.begin(), flagged.end(), true)); }

namespace {

// The points a check takes part among: usable, with finite values.
std::vector<bool> checked_points(const Points3& values, const std::vector<bool>& usable) {
  std::vector<bool> among(static_cast<std::size_t>(values.rows()));
  for (Index p = 0; p < values.rows(); ++p)
    among[static_cast<std::size_t>(p)] = usable[static_cast<std::size_t>(p)] && values.row(p).allFinite();
  return among;
}

// The positions of the points `among`, NaN elsewhere.
Points3 masked(const Points3& positions, const std::vector<bool>& among) {
  Points3 X = positions;
  for (Index p = 0; p < X.rows(); ++p)
    if (!among[static_cast<std::size_t>(p)]) X.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
  return X;
}

// Candidate neighbours per point among `among`: o.neighbours + 16 of them, nearest first.
std::shared_ptr<const BlunderNeighbours> search_neighbours(const Points3& positions, std::vector<bool> among,
                                                           const BlunderOptions& o) {
  const Points3 X = masked(positions, among);
  auto searched = std::make_shared<BlunderNeighbours>();
  searched->among = std::move(among);
  searched->count = o.neighbours + 16;
  searched->candidates = mesh::nearest_neighbours(X, searched->count);
  return searched;
}

}  // namespace

std::shared_ptr<const BlunderNeighbours> blunder_neighbours(const Points3& positions, const Points3& values,
                                                            const std::vector<bool>& usable, const BlunderOptions& o) {
  o.validate();
  return search_neighbours(positions, checked_points(values, usable), o);
}

BlunderCheck find_blunders(const Points3& positions, const Points3& values, const std::vector<bool>& usable,
                           bool normal_only, const BlunderOptions& o, std::shared_ptr<const BlunderNeighbours> reuse) {
  o.validate();
  const Index n = positions.rows();
  BlunderCheck out;
  out.deviation.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  out.flagged.assign(static_cast<std::size_t>(n), false);
  std::vector<bool> among = checked_points(values, usable);
  // Candidates once (or those of an earlier check among the same points); each pass
  // takes the nearest ones not flagged.
  const int count = o.neighbours + 16;
  if (reuse && reuse->count == count && reuse->among == among && reuse->candidates.size() == among.size())
    out.neighbours = std::move(reuse);
  else
    out.neighbours = search_neighbours(positions, std::move(among), o);
  const Points3 X = masked(positions, out.neighbours->among);
  const std::vector<std::vector<Index>>& candidates = out.neighbours->candidates;
  const int comps = normal_only ? 1 : 3;
  out.score.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  std::vector<std::vector<Index>> nb(static_cast<std::size_t>(n));
  Points3 vec = Points3::Constant(n, 3, std::numeric_limits<double>::quiet_NaN());  // deformed deviations
  for (int pass = 0; pass < o.passes; ++pass) {
    // Each point's neighbours and deviation (a flagged point keeps the deviation it was
    // flagged with); points are independent, so on all cores. After the first pass only
    // the points that lost a neighbour to the last pass's flags are fitted again: flags
    // are only added, so the others' nearest unflagged neighbours, and so their
    // deviations, are the same as before (a pass at 1e6 points costs seconds).
    parallel_for(n, [&](Index p) {
      const auto pp = static_cast<std::size_t>(p);
      if (out.flagged[pp]) return;
      if (pass > 0 &&
          std::none_of(nb[pp].begin(), nb[pp].end(), [&](Index q) { return out.flagged[static_cast<std::size_t>(q)]; }))
        return;
      nearest_unflagged(candidates[pp], out.flagged, o.neighbours, nb[pp]);
      const Deviation dv = X.row(p).allFinite() ? deviation(X, values, p, nb[pp], normal_only) : Deviation{};
      out.deviation[pp] = dv.e;
      vec.row(p) = dv.v.transpose();
    });
    std::vector<double> clean;
    std::vector<Index> use;
    for (Index p = 0; p < n; ++p) {
      const auto pp = static_cast<std::size_t>(p);
      if (!out.flagged[pp] && std::isfinite(out.deviation[pp])) {
        clean.push_back(out.deviation[pp]);
        use.push_back(p);
      }
    }
    out.noise = median_of(clean) / chi_median(comps);
    out.threshold = std::max(o.threshold * out.noise, o.floor);
    // The deformed state's noise covariance (two-level: the noisiest direction and the
    // two across it); a deviation is scored by its Mahalanobis length under it.
    Mat3 inverse = Mat3::Zero();
    const bool covariance = !normal_only && o.two_level;
    if (covariance) {
      const Mat3 cov = robust_covariance(vec, use);
      const Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
      out.noise_axis = std::sqrt(std::max(0.0, es.eigenvalues()[2]));
      out.noise_across = std::sqrt(std::max(0.0, 0.5 * (es.eigenvalues()[0] + es.eigenvalues()[1])));
      out.axis = es.eigenvectors().col(2);
      if (cov.trace() > 0) inverse = (cov + 1e-12 * cov.trace() * Mat3::Identity()).inverse();
    }
    auto score_of = [&](const Deviation& dv) {
      if (!std::isfinite(dv.e)) return std::numeric_limits<double>::quiet_NaN();
      if (covariance && inverse.trace() > 0) return std::sqrt(std::max(0.0, dv.v.dot(inverse * dv.v)));
      return out.noise > 0 ? dv.e / out.noise : dv.e > 0 ? std::numeric_limits<double>::infinity() : 0.0;
    };
    for (Index p = 0; p < n; ++p) {
      const auto pp = static_cast<std::size_t>(p);
      if (!out.flagged[pp]) out.score[pp] = score_of({out.deviation[pp], vec.row(p).transpose()});
    }
    // Only the largest score of its neighbourhood is judged in a pass: a blunder
    // spoils its neighbours' fits too, and they are judged again without it.
    auto local_max = [&](Index p, double e) {
      int seen = 0;
      for (Index q : nb[static_cast<std::size_t>(p)]) {
        if (seen++ == 8) break;
        if (out.score[static_cast<std::size_t>(q)] > e) return false;
      }
      return true;
    };
    std::vector<Index> newly;
    for (Index p = 0; p < n; ++p) {
      const auto pp = static_cast<std::size_t>(p);
      const double e = out.score[pp];
      if (!std::isfinite(e) || out.flagged[pp] || !(e > o.threshold) || !(out.deviation[pp] > o.floor)) continue;
      if (!local_max(p, e)) continue;
      // The neighbours' scores without the candidate (a blunder pulls its
      // neighbours' local fits towards itself).
      std::vector<double> around;
      for (Index q : nb[pp]) {
        std::vector<Index>& others = deviation_work().others;
        nearest_unflagged(candidates[static_cast<std::size_t>(q)], out.flagged, o.neighbours, others, p);
        const double eq = score_of(deviation(X, values, q, others, normal_only));
        if (std::isfinite(eq)) around.push_back(eq);
        if (around.size() == 8) break;
      }
      // A feature along a line (a neck) has at least two neighbours as far off as the
      // point; a blunder has none: compare with the second largest of the eight.
      std::sort(around.begin(), around.end(), std::greater<double>());
      const double second = around.size() >= 2 ? around[1] : 0.0;
      if (e > o.isolation * second) newly.push_back(p);
    }
    for (Index p : newly) out.flagged[static_cast<std::size_t>(p)] = true;
    if (newly.empty()) break;
  }
  return out;
}

}  // namespace sf::gsa

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
double deviation(const Points3& X, const Points3& v, Index p, const std::vector<Index>& nb, bool normal_only) {
  const Index k = static_cast<Index>(nb.size());
  if (k < 4) return std::numeric_limits<double>::quiet_NaN();
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
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-10)) return std::numeric_limits<double>::quiet_NaN();
  w.atb.noalias() = A.transpose() * b;
  w.c = ldlt.solve(w.atb);
  // Standardised: the prediction c0 carries noise of variance v0 sigma^2 on top of
  // the point's own (v0 = (A^T A)^-1_00: larger at gaps and at the outline).
  w.e0 = ldlt.solve(VecX::Unit(terms, 0));
  return w.c.row(0).norm() / std::sqrt(1.0 + w.e0[0]);
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

Index BlunderCheck::n_flagged() const { return static_cast<Index>(std::count(flagged.begin(), flagged.end(), true)); }

BlunderCheck find_blunders(const Points3& positions, const Points3& values, const std::vector<bool>& usable,
                           bool normal_only, const BlunderOptions& o, std::shared_ptr<const BlunderNeighbours> reuse) {
  o.validate();
  const Index n = positions.rows();
  BlunderCheck out;
  out.deviation.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  out.flagged.assign(static_cast<std::size_t>(n), false);
  Points3 X = positions;
  std::vector<bool> among(static_cast<std::size_t>(n));
  for (Index p = 0; p < n; ++p) {
    among[static_cast<std::size_t>(p)] = usable[static_cast<std::size_t>(p)] && values.row(p).allFinite();
    if (!among[static_cast<std::size_t>(p)]) X.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  // Candidates once (or those of an earlier check among the same points); each pass
  // takes the nearest ones not flagged.
  const int count = o.neighbours + 16;
  if (reuse && reuse->count == count && reuse->among == among && reuse->candidates.size() == among.size()) {
    out.neighbours = std::move(reuse);
  } else {
    auto searched = std::make_shared<BlunderNeighbours>();
    searched->among = std::move(among);
    searched->count = count;
    searched->candidates = mesh::nearest_neighbours(X, count);
    out.neighbours = std::move(searched);
  }
  const std::vector<std::vector<Index>>& candidates = out.neighbours->candidates;
  const int comps = normal_only ? 1 : 3;
  std::vector<std::vector<Index>> nb(static_cast<std::size_t>(n));
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
      out.deviation[pp] = X.row(p).allFinite() ? deviation(X, values, p, nb[pp], normal_only)
                                               : std::numeric_limits<double>::quiet_NaN();
    });
    std::vector<double> clean;
    for (Index p = 0; p < n; ++p) {
      const auto pp = static_cast<std::size_t>(p);
      if (!out.flagged[pp] && std::isfinite(out.deviation[pp])) clean.push_back(out.deviation[pp]);
    }
    out.noise = median_of(clean) / chi_median(comps);
    out.threshold = std::max(o.threshold * out.noise, o.floor);
    // Only the largest deviation of its neighbourhood is judged in a pass: a blunder
    // spoils its neighbours' fits too, and they are judged again without it.
    auto local_max = [&](Index p, double e) {
      int seen = 0;
      for (Index q : nb[static_cast<std::size_t>(p)]) {
        if (seen++ == 8) break;
        if (out.deviation[static_cast<std::size_t>(q)] > e) return false;
      }
      return true;
    };
    std::vector<Index> newly;
    for (Index p = 0; p < n; ++p) {
      const double e = out.deviation[static_cast<std::size_t>(p)];
      if (!std::isfinite(e) || out.flagged[static_cast<std::size_t>(p)] || !(e > out.threshold)) continue;
      if (!local_max(p, e)) continue;
      // The neighbours' deviations without the candidate (a blunder pulls its
      // neighbours' local fits towards itself).
      std::vector<double> around;
      for (Index q : nb[static_cast<std::size_t>(p)]) {
        std::vector<Index>& others = deviation_work().others;
        nearest_unflagged(candidates[static_cast<std::size_t>(q)], out.flagged, o.neighbours, others, p);
        const double eq = deviation(X, values, q, others, normal_only);
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

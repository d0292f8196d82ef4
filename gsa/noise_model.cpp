#include "gsa/noise_model.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <random>

#include "common/mesh/neighbours.hpp"
#include "common/core/error.hpp"

namespace sf::gsa {

double NoiseEstimate::sigma_total() const {
  return std::sqrt(sigma_correlated * sigma_correlated + sigma_white * sigma_white);
}

double NoiseEstimate::effective_length() const {
  return sigma_correlated > 0.3 * sigma_total() ? correlation_length : 0.0;
}

double NoiseEstimate::mean_variance(const Points3& p) const {
  const double n = static_cast<double>(p.rows());
  if (n < 1) return 0.0;
  double var = sigma_white * sigma_white / n;
  if (sigma_correlated > 0 && correlation_length > 0) {
    // Mean correlation over distinct pairs, from at most 100 evenly picked points.
    const double two_l2 = 2.0 * correlation_length * correlation_length;
    const Index k = std::min<Index>(p.rows(), 100);
    double sum = 0.0;
    for (Index a = 0; a < k; ++a)
      for (Index b = a + 1; b < k; ++b)
        sum += std::exp(-(p.row(a * p.rows() / k) - p.row(b * p.rows() / k)).squaredNorm() / two_l2);
    const double mean_rho = k > 1 ? sum / (0.5 * static_cast<double>(k) * static_cast<double>(k - 1)) : 0.0;
    var += sigma_correlated * sigma_correlated * (n + n * (n - 1.0) * mean_rho) / (n * n);
  } else {
    var += sigma_correlated * sigma_correlated / n;
  }
  return var;
}

namespace {

// Median of chi-square with k degrees of freedom, k = 1..3.
double chi2_median(int k) {
  static const double m[4] = {0.0, 0.45494, 1.38629, 2.36597};
  return m[std::clamp(k, 1, 3)];
}

// Non-negative weighted least squares of y ~ A c over the 2^k column subsets (k <= 3).
struct ModelFit {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double sse = std::numeric_limits<double>::infinity();
};
ModelFit nonnegative_fit(const MatX& A, const VecX& y, const VecX& w) {
  ModelFit best;
  const int k = static_cast<int>(A.cols());
  for (int mask = 1; mask < (1 << k); ++mask) {
    std::vector<int> cols;
    for (int j = 0; j < k; ++j)
      if (mask & (1 << j)) cols.push_back(j);
    MatX As(A.rows(), static_cast<Index>(cols.size()));
    for (std::size_t j = 0; j < cols.size(); ++j) As.col(static_cast<Index>(j)) = A.col(cols[j]);
    const MatX Aw = w.cwiseSqrt().asDiagonal() * As;
    const VecX yw = w.cwiseSqrt().asDiagonal() * y;
    const VecX c = Aw.colPivHouseholderQr().solve(yw);
    if ((c.array() < 0.0).any()) continue;
    const double sse = (Aw * c - yw).squaredNorm();
    if (sse < best.sse) {
      best.sse = sse;
      best.c.setZero();
      for (std::size_t j = 0; j < cols.size(); ++j) best.c[cols[j]] = c[static_cast<Index>(j)];
    }
  }
  return best;
}

}  // namespace

CorrelatedField::CorrelatedField(double sigma, double correlation_length, unsigned seed, int modes) {
  if (!(sigma > 0.0)) return;
  if (!(correlation_length > 0.0)) throw UsageError("correlated noise: the correlation length must be > 0");
  // cos(k.p + phi) with k ~ N(0, I / L^2), phi ~ U(0, 2 pi): E[cos(k.p + phi) cos(k.q + phi)]
  // = E[cos(k.(p - q))] / 2 = exp(-|p - q|^2 / (2 L^2)) / 2, so sqrt(2 / modes) normalises.
  std::mt19937_64 rng(seed * 7919ULL + 17ULL);
  std::normal_distribution<double> normal(0.0, 1.0 / correlation_length);
  std::uniform_real_distribution<double> uniform(0.0, 2.0 * kPi);
  amplitude_ = sigma * std::sqrt(2.0 / modes);
  for (int c = 0; c < 3; ++c) {
    k_[c].resize(modes, 3);
    phase_[c].resize(modes);
    for (int m = 0; m < modes; ++m) {
      k_[c](m, 0) = normal(rng);
      k_[c](m, 1) = normal(rng);
      k_[c](m, 2) = normal(rng);
      phase_[c][m] = uniform(rng);
    }
  }
}

Vec3 CorrelatedField::at(const Vec3& p) const {
  Vec3 out = Vec3::Zero();
  if (amplitude_ == 0.0) return out;
  for (int c = 0; c < 3; ++c) {
    const VecX arg = k_[c] * p + phase_[c];
    out[c] = amplitude_ * arg.array().cos().sum();
  }
  return out;
}

VariogramPairs::VariogramPairs(const Points3& positions, const std::vector<bool>& usable, double spacing,
                               const VariogramOptions& o)
    : spacing_(spacing) {
  const Index n = positions.rows();
  const double max_lag = o.max_lag > 0 ? o.max_lag : 12.0 * spacing;
  const double width = o.bin_width > 0 ? o.bin_width : 0.5 * spacing;
  Points3 pts = positions;
  std::vector<Index> query;
  for (Index p = 0; p < n; ++p) {
    if (!usable[static_cast<std::size_t>(p)] || !pts.row(p).allFinite())
      pts.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
    else
      query.push_back(p);
  }
  std::mt19937_64 rng(4242);
  if (static_cast<int>(query.size()) > o.max_query_points) {
    std::shuffle(query.begin(), query.end(), rng);
    query.resize(static_cast<std::size_t>(o.max_query_points));
  }
  const std::vector<std::vector<Index>> nb = mesh::neighbours_within(pts, max_lag);
  const int n_bins = std::max(1, static_cast<int>(std::ceil(max_lag / width)));
  bins_.resize(static_cast<std::size_t>(n_bins));
  std::vector<double> lag_sum(static_cast<std::size_t>(n_bins), 0.0);
  for (Index p : query)
    for (Index q : nb[static_cast<std::size_t>(p)]) {
      const double r = (pts.row(p) - pts.row(q)).norm();
      const int b = std::min(n_bins - 1, static_cast<int>(r / width));
      bins_[static_cast<std::size_t>(b)].emplace_back(p, q);
      lag_sum[static_cast<std::size_t>(b)] += r;
    }
  std::vector<std::vector<std::pair<Index, Index>>> kept;
  for (int b = 0; b < n_bins; ++b) {
    auto& v = bins_[static_cast<std::size_t>(b)];
    if (v.size() < 20) continue;
    lag_.push_back(lag_sum[static_cast<std::size_t>(b)] / static_cast<double>(v.size()));
    count_.push_back(static_cast<int>(v.size()));
    kept.push_back(std::move(v));
  }
  bins_ = std::move(kept);
}

std::vector<double> VariogramPairs::gamma(const MatX& values, int components) const {
  const int comps = std::min<int>(components, static_cast<int>(values.cols()));
  std::vector<double> out;
  std::vector<double> v;
  for (const auto& bin : bins_) {
    v.clear();
    for (const auto& [p, q] : bin) v.push_back(0.5 * (values.row(p).leftCols(comps) - values.row(q).leftCols(comps)).squaredNorm());
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    out.push_back(*mid / chi2_median(comps));
  }
  return out;
}

NoiseEstimate fit_noise_model(const VariogramPairs& pairs, const std::vector<double>& observed,
                              const Points3& positions, const std::function<MatX(const MatX&)>& smooth_residual,
                              double fixed_length) {
  NoiseEstimate out;
  out.lag = pairs.lag();
  out.gamma = observed;
  out.count = pairs.count();
  const Index nb = static_cast<Index>(observed.size());
  if (nb < 3) return out;
  const double h = pairs.spacing();
  const Index n = positions.rows();
  // Trial correlation lengths 0.5 .. 8 spacings; one unit field (3 components) each, and white probes.
  std::vector<double> lengths;
  if (fixed_length > 0)
    lengths.push_back(fixed_length);
  else
    for (int k = 0; k <= 24; ++k) lengths.push_back(h * 0.5 * std::pow(16.0, k / 24.0));
  const int nl = static_cast<int>(lengths.size());
  MatX probes(n, 3 * (nl + 1));
  std::mt19937_64 rng(777);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int l = 0; l < nl; ++l) {
    const CorrelatedField f(1.0, lengths[static_cast<std::size_t>(l)], 500u + static_cast<unsigned>(l), 128);
    for (Index p = 0; p < n; ++p) probes.block<1, 3>(p, 3 * l) = f.at(positions.row(p).transpose()).transpose();
  }
  for (Index p = 0; p < n; ++p)
    for (int c = 0; c < 3; ++c) probes(p, 3 * nl + c) = normal(rng);
  const MatX shrunk = smooth_residual(probes);
  const std::vector<double> vw = pairs.gamma(shrunk.rightCols(3), 3);
  VecX y(nb), w(nb);
  for (Index b = 0; b < nb; ++b) {
    y[b] = observed[static_cast<std::size_t>(b)];
    w[b] = pairs.count()[static_cast<std::size_t>(b)] / std::max(y[b] * y[b], 1e-300);
  }
  ModelFit best;
  double best_L = 0.0;
  for (int l = 0; l < nl; ++l) {
    const std::vector<double> vl = pairs.gamma(shrunk.middleCols(3 * l, 3), 3);
    MatX A(nb, 3);
    for (Index b = 0; b < nb; ++b) {
      A(b, 0) = vw[static_cast<std::size_t>(b)];
      A(b, 1) = vl[static_cast<std::size_t>(b)];
      A(b, 2) = pairs.lag()[static_cast<std::size_t>(b)] * pairs.lag()[static_cast<std::size_t>(b)];
    }
    const ModelFit f = nonnegative_fit(A, y, w);
    if (f.sse < best.sse) best = f, best_L = lengths[static_cast<std::size_t>(l)];
  }
  out.sigma_white = std::sqrt(best.c[0]);
  out.sigma_correlated = std::sqrt(best.c[1]);
  out.correlation_length = best.c[1] > 0 ? best_L : 0.0;
  out.bias_slope = best.c[2];
  return out;
}

MatX noise_probes(const NoiseEstimate& noise, const Points3& positions, int count, unsigned seed) {
  const Index n = positions.rows();
  MatX P = MatX::Zero(n, count);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int f = 0; 3 * f < count; ++f) {
    std::optional<CorrelatedField> field;
    if (noise.sigma_correlated > 0 && noise.correlation_length > 0)
      field.emplace(noise.sigma_correlated, noise.correlation_length, seed + 1000u + static_cast<unsigned>(f), 64);
    for (Index k = 0; k < n; ++k) {
      const Vec3 v = field ? field->at(positions.row(k).transpose()) : Vec3::Zero();
      for (int c = 0; c < 3 && 3 * f + c < count; ++c) P(k, 3 * f + c) = v[c] + noise.sigma_white * normal(rng);
    }
  }
  return P;
}

}  // namespace sf::gsa

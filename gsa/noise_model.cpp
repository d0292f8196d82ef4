#include "gsa/noise_model.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "common/core/error.hpp"
#include "common/core/parallel.hpp"
#include "common/linalg/dense_kernels.hpp"
#include "common/linalg/simd.hpp"
#include "common/mesh/neighbours.hpp"

namespace sf::gsa {

double NoiseEstimate::sigma_total() const {
  return std::sqrt(sigma_correlated * sigma_correlated + sigma_white * sigma_white);
}

double NoiseEstimate::effective_length() const {
  return sigma_correlated > 0.3 * sigma_total() ? correlation_length : 0.0;
}

double NoiseEstimate::correlation_at(double r) const {
  const double total = sigma_total();
  if (!(total > 0.0) || !(sigma_correlated > 0.0) || !(correlation_length > 0.0)) return 0.0;
  return sigma_correlated * sigma_correlated * std::exp(-r * r / (2.0 * correlation_length * correlation_length)) /
         (total * total);
}

bool NoiseEstimate::correlated_over(double d) const {
  const double length = effective_length();
  return length > 0.0 && (length >= d || correlation_at(d) >= kCorrelatedAtSpacing);
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

// cos(x) to about 1e-7 absolute: x reduced to [-pi, pi], then the Taylor series of
// cos in y^2 to y^18 (Horner). Random probe fields need no more, and the plain loop
// it allows vectorises where glibc's cos does not (the cosines were most of the cost
// of the noise estimate on 1e5 points).
[[gnu::always_inline]] inline double probe_cos(double x) {
  constexpr double kInvTwoPi = 0.15915494309189535, kTwoPi = 6.283185307179586;
  // Round to nearest by the 1.5 x 2^52 trick (plain additions, so the loop vectorises).
  constexpr double kRound = 6755399441055744.0;
  const double t = x * kInvTwoPi;
  const double y = x - kTwoPi * ((t + kRound) - kRound);
  const double z = y * y;
  double c = 1.0 / 6402373705728000.0;  // 1/18!
  c = c * z - 1.0 / 20922789888000.0;   // 1/16!
  c = c * z + 1.0 / 87178291200.0;
  c = c * z - 1.0 / 479001600.0;
  c = c * z + 1.0 / 3628800.0;
  c = c * z - 1.0 / 40320.0;
  c = c * z + 1.0 / 720.0;
  c = c * z - 1.0 / 24.0;
  c = c * z + 0.5;
  return 1.0 - z * c;
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
    const Index modes = k_[c].rows();
    const double* k0 = k_[c].col(0).data();
    const double* k1 = k_[c].col(1).data();
    const double* k2 = k_[c].col(2).data();
    const double* phase = phase_[c].data();
    const double p0 = p[0], p1 = p[1], p2 = p[2];
    double sum = 0.0;
    for (Index m = 0; m < modes; ++m) sum += probe_cos(k0[m] * p0 + k1[m] * p1 + k2[m] * p2 + phase[m]);
    out[c] = amplitude_ * sum;
  }
  return out;
}

namespace {

// The body of CorrelatedField::at_rows: each point's modes summed in order, the kBlock
// points side by side, which the compiler vectorises at the width of the instruction set
// it compiles for. It is compiled for three (below) and chosen at run time: no fused
// multiply-add anywhere (this file is compiled with -ffp-contract=off), so every set
// gives the same bits, those of at() (test GsaNoiseModel.ProbeFieldRowsAreAtBitForBit).
constexpr int kFieldBlock = CorrelatedField::kBlock;
[[gnu::always_inline]] inline void field_rows(const double* k0, const double* k1, const double* k2,
                                              const double* phase, Index modes, const double* x, const double* y,
                                              const double* z, double* sum) {
  for (Index m = 0; m < modes; ++m) {
    const double a = k0[m], b = k1[m], e = k2[m], ph = phase[m];
    for (int i = 0; i < kFieldBlock; ++i) sum[i] += probe_cos(a * x[i] + b * y[i] + e * z[i] + ph);
  }
}
#if SF_SIMD_X86
// Wider registers only: no "fma" in the target, so no multiply-add is fused.
__attribute__((target("avx512f"))) void field_rows_avx512(const double* k0, const double* k1, const double* k2,
                                                          const double* phase, Index modes, const double* x,
                                                          const double* y, const double* z, double* sum) {
  field_rows(k0, k1, k2, phase, modes, x, y, z, sum);
}
__attribute__((target("avx2"))) void field_rows_avx2(const double* k0, const double* k1, const double* k2,
                                                     const double* phase, Index modes, const double* x,
                                                     const double* y, const double* z, double* sum) {
  field_rows(k0, k1, k2, phase, modes, x, y, z, sum);
}
#endif
void field_rows_generic(const double* k0, const double* k1, const double* k2, const double* phase, Index modes,
                        const double* x, const double* y, const double* z, double* sum) {
  field_rows(k0, k1, k2, phase, modes, x, y, z, sum);
}
using FieldRows = void (*)(const double*, const double*, const double*, const double*, Index, const double*,
                           const double*, const double*, double*);
FieldRows field_rows_kernel() {
#if SF_SIMD_X86
  switch (linalg::kernel_isa()) {
    case linalg::KernelIsa::kAvx512:
      return field_rows_avx512;
    case linalg::KernelIsa::kAvx2:
      return field_rows_avx2;
    case linalg::KernelIsa::kGeneric:
      break;
  }
#endif
  return field_rows_generic;
}

}  // namespace

void CorrelatedField::at_rows(const Points3& positions, Index first, int count,
                              Eigen::Matrix<double, kBlock, 3>& out) const {
  out.setZero();
  if (amplitude_ == 0.0) return;
  alignas(64) double x[kBlock] = {}, y[kBlock] = {}, z[kBlock] = {};
  for (int i = 0; i < count; ++i) {
    x[i] = positions(first + i, 0);
    y[i] = positions(first + i, 1);
    z[i] = positions(first + i, 2);
  }
  const FieldRows rows = field_rows_kernel();
  for (int c = 0; c < 3; ++c) {
    alignas(64) double sum[kBlock] = {};
    // Each point's modes in order, as in at(): the same sums to the last bit.
    rows(k_[c].col(0).data(), k_[c].col(1).data(), k_[c].col(2).data(), phase_[c].data(), k_[c].rows(), x, y, z,
         sum);
    for (int i = 0; i < count; ++i) out(i, c) = amplitude_ * sum[i];
  }
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
  const std::vector<std::vector<Index>> nb = mesh::neighbours_within(pts, max_lag, query);
  const int n_bins = std::max(1, static_cast<int>(std::ceil(max_lag / width)));
  std::vector<std::vector<std::pair<Index, Index>>> bins_of(static_cast<std::size_t>(n_bins));
  for (std::size_t i = 0; i < query.size(); ++i)
    for (Index q : nb[i]) {
      const double r = (pts.row(query[i]) - pts.row(q)).norm();
      const int b = std::min(n_bins - 1, static_cast<int>(r / width));
      bins_of[static_cast<std::size_t>(b)].emplace_back(query[i], q);
    }
  // A bin's median needs a few thousand pairs, not the hundreds of thousands the outer
  // bins of a dense grid hold: a random subset (fixed seed) keeps each call cheap.
  std::vector<std::vector<std::pair<Index, Index>>> kept;
  for (int b = 0; b < n_bins; ++b) {
    auto& v = bins_of[static_cast<std::size_t>(b)];
    if (v.size() < 20) continue;
    if (static_cast<int>(v.size()) > o.max_pairs_per_bin) {
      std::shuffle(v.begin(), v.end(), rng);
      v.resize(static_cast<std::size_t>(o.max_pairs_per_bin));
    }
    double lag_sum = 0.0;
    for (const auto& [p, q] : v) lag_sum += (pts.row(p) - pts.row(q)).norm();
    lag_.push_back(lag_sum / static_cast<double>(v.size()));
    count_.push_back(static_cast<int>(v.size()));
    kept.push_back(std::move(v));
  }
  // The points the kept pairs use, and the pairs as positions among them.
  std::vector<int> slot(static_cast<std::size_t>(n), -1);
  for (const auto& v : kept)
    for (const auto& [p, q] : v) slot[static_cast<std::size_t>(p)] = slot[static_cast<std::size_t>(q)] = 0;
  for (Index p = 0; p < n; ++p)
    if (slot[static_cast<std::size_t>(p)] == 0) {
      slot[static_cast<std::size_t>(p)] = static_cast<int>(rows_.size());
      rows_.push_back(p);
    }
  bins_.resize(kept.size());
  for (std::size_t b = 0; b < kept.size(); ++b) {
    bins_[b].reserve(kept[b].size());
    for (const auto& [p, q] : kept[b])
      bins_[b].emplace_back(slot[static_cast<std::size_t>(p)], slot[static_cast<std::size_t>(q)]);
  }
}

std::vector<double> VariogramPairs::gamma(const MatX& values, int components) const {
  const int comps = std::min<int>(components, static_cast<int>(values.cols()));
  MatX at(static_cast<Index>(rows_.size()), comps);
  for (std::size_t i = 0; i < rows_.size(); ++i) at.row(static_cast<Index>(i)) = values.row(rows_[i]).leftCols(comps);
  return gamma_at_rows(at, comps);
}

std::vector<double> VariogramPairs::gamma_at_rows(const MatX& values, int components) const {
  const int comps = std::min<int>(components, static_cast<int>(values.cols()));
  // Row-major copy of the columns used: each pair reads two short contiguous rows.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = values.leftCols(comps);
  std::vector<double> out;
  std::vector<double> v;
  for (const auto& bin : bins_) {
    v.clear();
    for (const auto& [p, q] : bin) v.push_back(0.5 * (rows.row(p) - rows.row(q)).squaredNorm());
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    out.push_back(*mid / chi2_median(comps));
  }
  return out;
}

ProbeBank make_probe_bank(const Points3& positions, double spacing, double fixed_length) {
  ProbeBank bank;
  if (fixed_length > 0)
    bank.lengths.push_back(fixed_length);
  else
    for (int k = 0; k <= 12; ++k) bank.lengths.push_back(spacing * 0.5 * std::pow(16.0, k / 12.0));
  const Index n = positions.rows();
  const int nl = static_cast<int>(bank.lengths.size());
  bank.probes.resize(n, 3 * (nl + 1));
  std::vector<CorrelatedField> fields;
  for (int l = 0; l < nl; ++l)
    fields.emplace_back(1.0, bank.lengths[static_cast<std::size_t>(l)], 500u + static_cast<unsigned>(l), 48);
  // The cosines are most of the cost of the noise estimate: on all cores, by blocks of points.
  constexpr int kb = CorrelatedField::kBlock;
  parallel_for((n + kb - 1) / kb,
               [&](Index b) {
                 const Index first = b * kb;
                 const int count = static_cast<int>(std::min<Index>(kb, n - first));
                 Eigen::Matrix<double, kb, 3> v;
                 for (int l = 0; l < nl; ++l) {
                   fields[static_cast<std::size_t>(l)].at_rows(positions, first, count, v);
                   bank.probes.block(first, 3 * l, count, 3) = v.topRows(count);
                 }
               },
               32);
  std::mt19937_64 rng(777);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (Index p = 0; p < n; ++p)
    for (int c = 0; c < 3; ++c) bank.probes(p, 3 * nl + c) = normal(rng);
  return bank;
}

NoiseEstimate fit_noise_model(const VariogramPairs& pairs, const std::vector<double>& observed, const ProbeBank& bank,
                              const std::function<MatX(const MatX&, const std::vector<Index>&)>& smooth_residual) {
  NoiseEstimate out;
  out.lag = pairs.lag();
  out.gamma = observed;
  out.count = pairs.count();
  const Index nb = static_cast<Index>(observed.size());
  if (nb < 3) return out;
  const std::vector<double>& lengths = bank.lengths;
  const int nl = static_cast<int>(lengths.size());
  const MatX shrunk = smooth_residual(bank.probes, pairs.rows());  // at pairs.rows() only
  const std::vector<double> vw = pairs.gamma_at_rows(shrunk.rightCols(3), 3);
  VecX y(nb), w(nb);
  for (Index b = 0; b < nb; ++b) {
    y[b] = observed[static_cast<std::size_t>(b)];
    w[b] = pairs.count()[static_cast<std::size_t>(b)] / std::max(y[b] * y[b], 1e-300);
  }
  std::vector<std::vector<double>> v_of_length(static_cast<std::size_t>(nl));
  for (int l = 0; l < nl; ++l)
    v_of_length[static_cast<std::size_t>(l)] = pairs.gamma_at_rows(shrunk.middleCols(3 * l, 3), 3);
  // Between two trial lengths the variogram is interpolated (in log L, quarter steps):
  // the bank's lengths are a factor 1.26 apart, too coarse for the estimate itself.
  ModelFit best;
  double best_L = 0.0;
  for (int l = 0; l < nl; ++l) {
    const int steps = l + 1 < nl ? 4 : 1;
    for (int s = 0; s < steps; ++s) {
      const double t = s / 4.0;
      const auto& va = v_of_length[static_cast<std::size_t>(l)];
      const auto& vb = v_of_length[static_cast<std::size_t>(std::min(l + 1, nl - 1))];
      MatX A(nb, 3);
      for (Index b = 0; b < nb; ++b) {
        const auto bb = static_cast<std::size_t>(b);
        A(b, 0) = vw[bb];
        A(b, 1) = (1.0 - t) * va[bb] + t * vb[bb];
        A(b, 2) = pairs.lag()[bb] * pairs.lag()[bb];
      }
      const ModelFit f = nonnegative_fit(A, y, w);
      if (f.sse < best.sse) {
        best = f;
        const double la = lengths[static_cast<std::size_t>(l)];
        const double lb = lengths[static_cast<std::size_t>(std::min(l + 1, nl - 1))];
        best_L = la * std::pow(lb / la, t);
      }
    }
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
    // The correlated part on all cores, then the white part in the generator's order.
    if (noise.sigma_correlated > 0 && noise.correlation_length > 0) {
      const CorrelatedField field(noise.sigma_correlated, noise.correlation_length,
                                  seed + 1000u + static_cast<unsigned>(f), 64);
      constexpr int kb = CorrelatedField::kBlock;
      parallel_for((n + kb - 1) / kb,
                   [&](Index b) {
                     const Index first = b * kb;
                     const int rows = static_cast<int>(std::min<Index>(kb, n - first));
                     Eigen::Matrix<double, kb, 3> v;
                     field.at_rows(positions, first, rows, v);
                     for (int i = 0; i < rows; ++i)
                       for (int c = 0; c < 3 && 3 * f + c < count; ++c) P(first + i, 3 * f + c) = v(i, c);
                   },
                   32);
    }
    for (Index k = 0; k < n; ++k)
      for (int c = 0; c < 3 && 3 * f + c < count; ++c) P(k, 3 * f + c) += noise.sigma_white * normal(rng);
  }
  return P;
}

}  // namespace sf::gsa

namespace sf::gsa {

namespace {
// Radii of the local quadratic fits (spacings) of displacement_noise, and the fewest
// points a fit needs (6 parameters, kept well determined).
constexpr double kLocalRadii[] = {1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0};
// The longest correlation length tried (spacings): a local quadratic sees noise level off
// only at radii a few times its length.
constexpr double kLocalLongest = 3.2;
// The local fits: quadratic (6 terms) and quartic (15), each with at least 2 points a term.
constexpr int kLocalDegree[2] = {2, 4};
constexpr int kLocalTerms[2] = {6, 15};
constexpr int kLocalFewest[2] = {12, 30};
// The quartic fits' correlated amplitude and length agree with the quadratic ones' within
// this fraction (the length plus half a spacing).
constexpr double kLocalAgreement = 0.35;
constexpr int kLocalQueries = 3000;
}  // namespace

NoiseEstimate displacement_noise(const Points3& undeformed, const Points3& deformed, const VecX& weight,
                                 double spacing) {
  NoiseEstimate out;
  const Index m = undeformed.rows();
  const double d = spacing;
  const int nr = static_cast<int>(std::size(kLocalRadii));
  const double max_radius = kLocalRadii[nr - 1] * d;
  Points3 pts = undeformed;
  std::vector<Index> query;
  for (Index p = 0; p < m; ++p) {
    if (!(weight[p] > 0) || !undeformed.row(p).allFinite() || !deformed.row(p).allFinite())
      pts.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
    else
      query.push_back(p);
  }
  if (query.size() < 20) return out;
  std::mt19937_64 rng(4243);
  if (static_cast<int>(query.size()) > kLocalQueries) {
    std::shuffle(query.begin(), query.end(), rng);
    query.resize(static_cast<std::size_t>(kLocalQueries));
  }
  const std::vector<std::vector<Index>> nb = mesh::neighbours_within(pts, max_radius, query);
  // The rows any fit uses: the probes are needed there only.
  std::vector<int> slot(static_cast<std::size_t>(m), -1);
  std::vector<Index> rows;
  auto take = [&](Index p) {
    if (slot[static_cast<std::size_t>(p)] < 0) {
      slot[static_cast<std::size_t>(p)] = static_cast<int>(rows.size());
      rows.push_back(p);
    }
  };
  for (std::size_t i = 0; i < query.size(); ++i) {
    take(query[i]);
    for (Index q : nb[i]) take(q);
  }
  Points3 at(static_cast<Index>(rows.size()), 3);
  MatX values(static_cast<Index>(rows.size()), 3);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    at.row(static_cast<Index>(i)) = undeformed.row(rows[i]);
    values.row(static_cast<Index>(i)) = deformed.row(rows[i]) - undeformed.row(rows[i]);
  }
  ProbeBank bank = make_probe_bank(at, d);
  const int white = 1 + static_cast<int>(bank.lengths.size());  // the white probes' column triple in `all`
  int nl = static_cast<int>(bank.lengths.size());
  while (nl > 1 && bank.lengths[static_cast<std::size_t>(nl - 1)] > kLocalLongest * d) --nl;
  const Index cols = 3 + bank.probes.cols();
  // Row-major: each local fit reads whole rows (a point's data and probes) of it; the same
  // sums, the same bits, as from a column-major copy, without a cache line per entry.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> all(values.rows(), cols);
  all << values, bank.probes;
  // Squared residual norms per degree, radius, column triple (data, probes), query point.
  const int triples = static_cast<int>(cols / 3);
  using Table = std::vector<std::vector<std::vector<double>>>;
  std::array<Table, 2> sq;
  for (Table& t : sq)
    t.assign(static_cast<std::size_t>(nr), std::vector<std::vector<double>>(static_cast<std::size_t>(triples)));
  // The query points' local fits on all cores: each writes its own slice of `local`
  // and `made`, gathered into `sq` in query order below, so the
  // tables hold the same numbers in the same order whatever the threads.
  const std::size_t per_query = static_cast<std::size_t>(2 * nr * triples);
  std::vector<double> local(query.size() * per_query, 0.0);
  std::vector<char> made(query.size() * 2 * static_cast<std::size_t>(nr), 0);  // per query, degree, radius
  parallel_for(
      static_cast<Index>(query.size()),
      [&](Index qi) {
        const auto i = static_cast<std::size_t>(qi);
        double* const out_i = local.data() + i * per_query;
        const Vec3 c = undeformed.row(query[i]).transpose();
        const std::vector<Index>& around = nb[i];
        if (static_cast<int>(around.size()) + 1 < kLocalFewest[0]) return;
        // Local tangent plane: the principal directions of the neighbourhood.
        Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
        for (Index q : around) {
          const Vec3 r = undeformed.row(q).transpose() - c;
          cov += r * r.transpose();
        }
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
        const Vec3 e1 = eig.eigenvectors().col(2), e2 = eig.eigenvectors().col(1);
        std::vector<Index> in;
        std::vector<std::array<double, 2 * (kLocalDegree[1] + 1)>> powers;  // u^a, v^a per point, a = 0..4
        for (int k = 0; k < nr; ++k) {
          const double rho = kLocalRadii[k] * d;
          in.assign(1, query[i]);
          for (Index q : around)
            if ((undeformed.row(q).transpose() - c).norm() <= rho * (1.0 + 1e-9)) in.push_back(q);
          // std::pow of each power once per point (the same calls, so the same bits, as
          // one per term).
          powers.resize(in.size());
          for (std::size_t j = 0; j < in.size(); ++j) {
            const Vec3 r = (undeformed.row(in[j]).transpose() - c) / rho;
            const double u = r.dot(e1), v = r.dot(e2);
            for (int a = 0; a <= kLocalDegree[1]; ++a) {
              powers[j][static_cast<std::size_t>(a)] = std::pow(u, a);
              powers[j][static_cast<std::size_t>(kLocalDegree[1] + 1 + a)] = std::pow(v, a);
            }
          }
          for (int g = 0; g < 2; ++g) {
            const int np = kLocalTerms[g];
            if (static_cast<int>(in.size()) < kLocalFewest[g]) continue;
            MatX A(static_cast<Index>(in.size()), np);
            for (std::size_t j = 0; j < in.size(); ++j) {
              const auto& pw = powers[j];
              int col = 0;
              for (int deg = 0; deg <= kLocalDegree[g]; ++deg)
                for (int a = deg; a >= 0; --a)
                  A(static_cast<Index>(j), col++) =
                      pw[static_cast<std::size_t>(a)] * pw[static_cast<std::size_t>(kLocalDegree[1] + 1 + deg - a)];
            }
            const Eigen::ColPivHouseholderQR<MatX> qr(A);
            if (qr.rank() < np) continue;
            // The fit's value at the point (u = v = 0) is h^T y, h = A (A^T A)^-1 e_1.
            const MatX ata = A.transpose() * A;
            const VecX h = A * ata.ldlt().solve(VecX::Unit(np, 0));
            Eigen::RowVectorXd res = all.row(slot[static_cast<std::size_t>(query[i])]);
            for (std::size_t j = 0; j < in.size(); ++j)
              res -= h[static_cast<Index>(j)] * all.row(slot[static_cast<std::size_t>(in[j])]);
            for (int tr = 0; tr < triples; ++tr)
              out_i[(static_cast<std::size_t>(g) * nr + k) * triples + tr] = res.segment(3 * tr, 3).squaredNorm();
            made[(i * 2 + static_cast<std::size_t>(g)) * nr + static_cast<std::size_t>(k)] = 1;
          }
        }
      },
      8);
  for (std::size_t i = 0; i < query.size(); ++i)
    for (int g = 0; g < 2; ++g)
      for (int k = 0; k < nr; ++k) {
        if (!made[(i * 2 + static_cast<std::size_t>(g)) * nr + static_cast<std::size_t>(k)]) continue;
        const double* v = local.data() + i * per_query + (static_cast<std::size_t>(g) * nr + k) * triples;
        for (int tr = 0; tr < triples; ++tr)
          sq[static_cast<std::size_t>(g)][static_cast<std::size_t>(k)][static_cast<std::size_t>(tr)].push_back(v[tr]);
      }
  // The model fitted to one degree's statistics.
  auto fit_degree = [&](int g) {
    NoiseEstimate e;
    const Table& t = sq[static_cast<std::size_t>(g)];
    auto stat = [&](int k, int tr) {
      std::vector<double> v = t[static_cast<std::size_t>(k)][static_cast<std::size_t>(tr)];
      const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
      std::nth_element(v.begin(), mid, v.end());
      return *mid / chi2_median(3);
    };
    std::vector<int> used;
    for (int k = 0; k < nr; ++k)
      if (t[static_cast<std::size_t>(k)][0].size() >= 20) used.push_back(k);
    const Index nb_used = static_cast<Index>(used.size());
    if (nb_used < 4) return e;
    VecX y(nb_used), w(nb_used), trend(nb_used), vw(nb_used);
    std::vector<VecX> vl(static_cast<std::size_t>(nl), VecX(nb_used));
    for (Index b = 0; b < nb_used; ++b) {
      const int k = used[static_cast<std::size_t>(b)];
      y[b] = stat(k, 0);
      w[b] = 1.0 / std::max(y[b] * y[b], 1e-300);
      trend[b] = std::pow(kLocalRadii[k] / kLocalRadii[nr - 1], 2 * (kLocalDegree[g] + 2));
      for (int l = 0; l < nl; ++l) vl[static_cast<std::size_t>(l)][b] = stat(k, 1 + l);
      vw[b] = stat(k, white);
      e.lag.push_back(kLocalRadii[k] * d);
      e.gamma.push_back(y[b]);
      e.count.push_back(static_cast<int>(t[static_cast<std::size_t>(k)][0].size()));
    }
    ModelFit best;
    double best_L = 0.0;
    for (int l = 0; l < nl; ++l) {
      const int steps = l + 1 < nl ? 4 : 1;
      for (int s = 0; s < steps; ++s) {
        const double f = s / 4.0;
        MatX A(nb_used, 3);
        A.col(0) = vw;
        A.col(1) = (1.0 - f) * vl[static_cast<std::size_t>(l)] + f * vl[static_cast<std::size_t>(std::min(l + 1, nl - 1))];
        A.col(2) = trend;
        const ModelFit fit = nonnegative_fit(A, y, w);
        if (fit.sse < best.sse) {
          best = fit;
          const double la = bank.lengths[static_cast<std::size_t>(l)];
          const double lb = bank.lengths[static_cast<std::size_t>(std::min(l + 1, nl - 1))];
          best_L = la * std::pow(lb / la, f);
        }
      }
    }
    e.sigma_white = std::sqrt(best.c[0]);
    e.sigma_correlated = std::sqrt(best.c[1]);
    e.correlation_length = best.c[1] > 0 ? best_L : 0.0;
    e.bias_slope = best.c[2] / std::pow(max_radius, 2 * (kLocalDegree[g] + 2));
    return e;
  };
  out = fit_degree(0);
  // Confirmed by the quartic fits: noise gives the same model whatever the fit (the probes
  // correct for what each fit takes up), while the misfit of a smooth shape (a dome, a neck's
  // flanks) shrinks by orders once the fit follows quartic terms.
  const NoiseEstimate quartic = fit_degree(1);
  const double sc = out.sigma_correlated, sq4 = quartic.sigma_correlated;
  const double l2 = out.effective_length(), l4 = quartic.effective_length();
  const bool confirmed = sc > 0 && sq4 > 0 && std::abs(sc - sq4) <= kLocalAgreement * std::max(sc, sq4) &&
                         std::abs(l2 - l4) <= kLocalAgreement * std::max(l2, l4) + 0.5 * d;
  if (!confirmed) {
    out.sigma_white = out.sigma_total();
    out.sigma_correlated = out.correlation_length = 0.0;
  }
  return out;
}

}  // namespace sf::gsa

#pragma once
// Measurement noise with spatial correlation, estimated from fit residuals.
//
// Digitised grid marks have independent errors; points of digital image
// correlation do not: neighbouring points share image subsets, so their errors
// are correlated over about a subset (a few point spacings). A smoothing choice
// that assumes independent errors (cross-validation) takes correlated error for
// signal and under-smooths. The model here, per coordinate:
//
//   cov(e_i, e_j) = sigma_c^2 exp(-r_ij^2 / (2 L^2)) + sigma_w^2 [i = j]
//
// r_ij the distance between the points' undeformed positions, L the correlation
// length. It is estimated from the semivariogram of fit residuals,
// gamma(r) = E |e_i - e_j|^2 / 2 per component, binned by distance with a robust
// (median) estimate per bin. A smoother takes up part of the noise itself (all of
// it at scales longer than its gauge), so the model is fitted to what its noise
// would leave in the residuals: the variograms of (I - H) applied to noise probes
// (fit_noise_model), plus b r^2 for the smooth bias of the fit. Units: mm.

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa {

inline constexpr double kCorrelatedAtSpacing = 0.3;

struct NoiseEstimate {
  double sigma_correlated = 0.0;    // mm, per coordinate
  double correlation_length = 0.0;  // mm (0: no correlated part found)
  double sigma_white = 0.0;         // mm, per coordinate
  double bias_slope = 0.0;          // b of the model, 1 (mm^2 / mm^2)
  // Two levels (stereo DIC measures along the viewing direction, about the part's normal,
  // several times worse than across it): the noise per tangential component and along the
  // normal, mm, from the deformed fit's residuals projected on the fitted surface's tangent
  // plane and normal (robust: medians), scaled so that (2 sigma_tangent^2 + sigma_normal^2) / 3
  // = sigma_total^2 when the model has an amplitude. Both 0: not estimated (isotropic).
  // Reported (summary.json); the smoothing and its local relaxation do not use them yet.
  double sigma_tangent = 0.0, sigma_normal = 0.0;
  double sigma_total() const;
  // The correlation length when the correlated part matters (> 30 % of the total
  // sigma), else 0: the noise counts as independent.
  double effective_length() const;
  // Correlation of the noise of two points r apart (mm) as a fraction of its total
  // variance: sigma_c^2 exp(-r^2 / (2 L^2)) / sigma_total^2 (0 without noise).
  double correlation_at(double r) const;
  // Whether the smoothing must treat the noise as correlated on marks d apart: the
  // effective length reaches d, or the noise of neighbouring marks is correlated by
  // kCorrelatedAtSpacing or more (a length just under d, as DIC points a subset step
  // apart give). Independent noise on a grid has no pairs closer than d and fits as a
  // length of 0.5-0.7 d with a correlation at d of 0.08-0.16 (measured: the 21 x 21 grid
  // of gsa_accuracy_bench); noise correlated over one spacing, 0.5-0.6.
  bool correlated_over(double d) const;
  // Variance of the mean of the noise at `positions` (k x 3) per component, mm^2.
  double mean_variance(const Points3& positions) const;
  // Variogram bins used: mean distance, estimate, pairs.
  std::vector<double> lag, gamma;
  std::vector<int> count;
};

struct VariogramOptions {
  double max_lag = 0.0;          // mm; 0 = 12 spacings
  double bin_width = 0.0;        // mm; 0 = half a spacing
  int max_query_points = 3000;   // points whose neighbourhoods are sampled (a random subset, fixed seed)
  int max_pairs_per_bin = 6000;  // pairs kept per distance bin (a random subset, fixed seed)
};

// One realisation of Gaussian noise with covariance sigma^2 exp(-r^2 / (2 L^2)): a
// sum of random Fourier modes (3-D wave vectors drawn from the Gaussian spectral
// density), so its covariance is the Gaussian one of the 3-D distance in expectation,
// and it is smooth at every scale below L.
class CorrelatedField {
 public:
  CorrelatedField(double sigma, double correlation_length, unsigned seed, int modes = 512);
  // Three independent components at position p (mm).
  Vec3 at(const Vec3& p) const;
  // The same at the rows [first, first + count) of `positions` (count <= kBlock) into
  // out(i, c): bit for bit what at() gives, but the modes' cosines of kBlock points are
  // taken together, which the compiler vectorises (at() sums one point's modes in order,
  // a reduction it may not reorder).
  static constexpr int kBlock = 8;
  void at_rows(const Points3& positions, Index first, int count, Eigen::Matrix<double, kBlock, 3>& out) const;

 private:
  double amplitude_ = 0.0;
  std::array<Eigen::MatrixX3d, 3> k_;  // wave vectors (1/mm), modes x 3, per component
  std::array<VecX, 3> phase_;
};

// Point pairs of a variogram, sampled once (a random subset of query points and
// all their neighbours within max_lag), binned by distance.
class VariogramPairs {
 public:
  VariogramPairs(const Points3& positions, const std::vector<bool>& usable, double spacing,
                 const VariogramOptions& options = {});
  // Robust variogram of `values` (n x k, the first min(k, components) columns count):
  // per bin, the median of |v_p - v_q|^2 / 2 over chi-square's median.
  std::vector<double> gamma(const MatX& values, int components) const;
  // The points any pair uses, ascending: a variogram needs values there only (on a grid
  // of 1e6 points the pairs use about a sixth of them).
  const std::vector<Index>& rows() const { return rows_; }
  // The same variogram from the values at rows() only (rows().size() x k, in its order).
  std::vector<double> gamma_at_rows(const MatX& values, int components) const;
  const std::vector<double>& lag() const { return lag_; }
  const std::vector<int>& count() const { return count_; }
  double spacing() const { return spacing_; }

 private:
  // Pairs as positions in rows_.
  std::vector<std::vector<std::pair<int, int>>> bins_;
  std::vector<Index> rows_;
  std::vector<double> lag_;
  std::vector<int> count_;
  double spacing_ = 0.0;
};

// Unit probe fields at the points for fit_noise_model: one correlated field (three
// components) per trial correlation length, 13 lengths from 0.5 to 8 spacings (or the
// one fixed length), and three white columns last. Made once per set of points and
// used for every pilot smoother (the cosines are most of the cost).
struct ProbeBank {
  std::vector<double> lengths;  // mm
  MatX probes;                  // n x 3 (lengths + 1)
};
ProbeBank make_probe_bank(const Points3& positions, double spacing, double fixed_length = 0.0);

// The noise model whose residuals under a smoother match the residuals' variogram:
// `smooth_residual(w, rows)` returns (I - H) w for probe data w (n x k) at the points
// `rows` (pairs.rows(): rows.size() x k, in its order). Fits
//   gamma(r) = s_c V_L(r) + s_w V_w(r) + b r^2
// where V_L, V_w are the variograms of (I - H) applied to the bank's unit correlated
// (length L) and white probes; L the best of the bank's lengths. Accounts for the noise
// the smoother itself takes up.
NoiseEstimate fit_noise_model(const VariogramPairs& pairs, const std::vector<double>& observed, const ProbeBank& bank,
                              const std::function<MatX(const MatX&, const std::vector<Index>&)>& smooth_residual);

// Reference positions without noise (nominal: the subset centres of a 2-D DIC export, a
// grid placed by --pitch) give the blank's estimate no correlation length, and the
// deformed fit's pilots cannot tell correlated noise from the misfit of a smooth shape
// (docs/theory/strain.md, "A blank without noise"). This estimate uses the displacement
// u = deformed - undeformed at the points with weight > 0 instead: at up to 3000 of them
// (fixed seed) the residual at the point of a local quadratic least-squares fit of u, in
// the local tangent plane of the undeformed points within radius rho, for rho = 1.5 .. 7
// spacings. A smooth displacement leaves a residual growing like rho^4 (the quadratic's
// bias; squared rho^8), noise one that levels off at its variance once rho is well past
// its correlation length. Per radius the median squared residual (chi-square scaled,
// robust to a neck or an edge) is fitted as
//   R(rho) = s_c V_L(rho) + s_w V_w(rho) + a rho^8,
// V_L, V_w the same statistic of the bank's unit probes (correlated, length L; white), by
// non-negative least squares, L the best of the bank's lengths. Returns the model per
// coordinate (units of the points), bias_slope = a; lag/gamma = rho and R(rho).
NoiseEstimate displacement_noise(const Points3& undeformed, const Points3& deformed, const VecX& weight,
                                 double spacing);

// Probes for a trace estimate tr(H Sigma): `count` columns, each a draw of the
// noise at the points (n x count; three independent columns per random field,
// 64 Fourier modes each: unbiased, E[w w^T] = Sigma), fixed seed.
MatX noise_probes(const NoiseEstimate& noise, const Points3& positions, int count, unsigned seed = 99);

}  // namespace sf::gsa

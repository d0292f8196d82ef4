#include "gsa/noise_estimate.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "common/core/parallel.hpp"
#include "common/fe/surface_field.hpp"
#include "common/mesh/neighbours.hpp"
#include "gsa/deformed_fit.hpp"
#include "gsa/smoothing.hpp"

namespace sf::gsa {

namespace {

// Variogram lags: up to 15 spacings for the correlation length (the range is 1-5
// spacings: the variogram must reach its sill), 8 for the amplitudes.
constexpr double kUndeformedMaxLag = 15.0;
constexpr double kDeformedMaxLag = 8.0;
// A pilot's estimate is confirmed by the next lighter one when the total sigma agrees
// within this fraction and the effective length within kLengthAgreement of the longer
// one plus half a spacing.
constexpr double kSigmaAgreement = 0.15;
constexpr double kLengthAgreement = 0.35;
// A pilot shows no smooth bias when b r_max^2 < this fraction of the noise variance.
constexpr double kBiasFraction = 0.25;
// Points whose neighbourhood (3 spacings) mean square residual exceeds this multiple of
// the median are misfit, not noise, for the amplitude estimate.
constexpr double kMisfitFactor = 6.0;
// An undeformed estimate below this fraction of the mark spacing is round-off, not noise
// (a measurement quantised to 1 um at 1 mm spacing has 3e-4).
constexpr double kNoiseFloor = 1e-6;
// The deformed data's correlated amplitude is at least sqrt(2) x the blank's: the noise
// of the two states adds (the same measuring system), the blank's part entering through
// the marks' surface coordinates.
constexpr double kBothStatesFactor = 1.4142135623730951;  // sqrt(2)

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The lighter pilot's estimate confirms the heavier one's: the total sigma agrees and,
// when `length` counts (the blank's ladder fits the correlation length), the effective
// length too.
bool confirms(const NoiseEstimate& heavier, const NoiseEstimate& lighter, double d, bool length) {
  const double sh = heavier.sigma_total(), sl = lighter.sigma_total();
  const double lh = heavier.effective_length(), ll = lighter.effective_length();
  return std::abs(sh - sl) <= kSigmaAgreement * sl &&
         (!length || std::abs(lh - ll) <= kLengthAgreement * std::max(lh, ll) + 0.5 * d);
}

// No smooth bias in the pilot's residuals: b r_max^2 below a fraction of the noise variance.
bool unbiased(const NoiseEstimate& e, double max_lag) {
  return e.bias_slope * max_lag * max_lag < kBiasFraction * e.sigma_total() * e.sigma_total();
}

// The pilot ladder delta = 10^k d^6, k = heaviest .. lightest: `estimate(k)` (nothing
// when the pilot fit fails) is run lazily, heaviest first; taken is the first estimate
// without smooth bias that the next lighter one confirms, else (`unconfirmed`) the
// heaviest one without smooth bias or the lightest one run.
enum class Unconfirmed { kLightest, kHeaviestUnbiased };
template <class Estimate>
NoiseEstimate pilot_ladder(int heaviest, int lightest, double max_lag, double d, bool length, Unconfirmed unconfirmed,
                           const Estimate& estimate) {
  std::optional<NoiseEstimate> heavier, first_unbiased;
  for (int k = heaviest; k >= lightest; --k) {
    std::optional<NoiseEstimate> e = estimate(k);
    if (!e) break;
    if (heavier && unbiased(*heavier, max_lag) && confirms(*heavier, *e, d, length)) return *heavier;
    if (!first_unbiased && unbiased(*e, max_lag)) first_unbiased = e;
    heavier = std::move(e);
  }
  if (unconfirmed == Unconfirmed::kHeaviestUnbiased && first_unbiased) return *first_unbiased;
  return heavier ? *heavier : NoiseEstimate{};
}

}  // namespace

NoiseEstimate undeformed_noise(const FrameAndMesh& setup, const FitMarks& marks, const UndeformedFit& und) {
  const Index m = marks.size();
  const double d = setup.mark_spacing;
  const mesh::SurfaceMesh& mesh = setup.mesh;
  // Normals of the fitted undeformed surface at the marks.
  const fe::SurfaceField surface(mesh, und.parameters);
  Points3 normal(m, 3);
  for (Index k = 0; k < m; ++k) {
    const MeshLocation& loc = und.location[static_cast<std::size_t>(k)];
    const Mat32 t = surface.evaluate3(loc.element, loc.xi, basis::kFirst).dx;
    normal.row(k) = t.col(0).cross(t.col(1)).normalized().transpose();
  }
  FitSystem system(mesh, setup.penalties, und.location, und.weight);
  std::vector<bool> usable(static_cast<std::size_t>(m));
  for (Index k = 0; k < m; ++k) usable[static_cast<std::size_t>(k)] = und.weight[k] > 0;
  VariogramOptions vo;
  vo.max_lag = kUndeformedMaxLag * d;
  const VariogramPairs pairs(marks.undeformed, usable, d, vo);
  const ProbeBank bank = make_probe_bank(marks.undeformed, d);
  system.set_values(marks.undeformed);
  // Phi^T W of the probe fields: the same for every pilot, formed once.
  const MatX bank_weighted = system.weighted_values(bank.probes);
  // One pilot's estimate, fitted in the system's workspace `slot`.
  auto estimate = [&](int k, int slot) -> std::optional<NoiseEstimate> {
    const Penalty pilot = jumps_penalty(k, d);
    const FitResult f = system.solve(pilot, mesh.geometry(), 0, 1, slot);
    if (!f.ok) return std::nullopt;
    MatX residual(m, 1);
    for (Index i = 0; i < m; ++i) residual(i, 0) = (marks.undeformed.row(i) - f.fitted.row(i)).dot(normal.row(i));
    // The probes' residuals without copies of them (the same factorisation as the data's).
    // (The data's fit with the same matrix succeeded: so does theirs.) fit_noise_model
    // smooths the bank's probes, whose Phi^T W is bank_weighted.
    auto shrink = [&](const MatX& probes, const std::vector<Index>& rows) {
      return *system.smoothing_residual(probes, bank_weighted, pilot, 1, slot, &rows);
    };
    return fit_noise_model(pairs, pairs.gamma(residual, 1), bank, shrink);
  };
  // With two cores the next lighter pilot is fitted beside each one the ladder asks for
  // (it asks for it next unless it stops there), in the system's second workspace (its
  // own factorisation): the ladder's wall time about halves and it takes the same
  // estimates in the same order, each the same bits in either workspace.
  const bool two = default_threads() >= 2;
  std::map<int, std::optional<NoiseEstimate>> ahead;
  const Unconfirmed lightest = Unconfirmed::kLightest;
  NoiseEstimate e = pilot_ladder(8, 1, vo.max_lag, d, true, lightest, [&](int k) -> std::optional<NoiseEstimate> {
    if (const auto it = ahead.find(k); it != ahead.end()) return it->second;
    if (!two || k - 1 < 1) return estimate(k, 0);
    std::optional<NoiseEstimate> lighter;
    std::exception_ptr error;
    std::thread other([&] {
      try {
        lighter = estimate(k - 1, 1);
      } catch (...) {
        error = std::current_exception();
      }
    });
    std::optional<NoiseEstimate> out;
    try {
      out = estimate(k, 0);
    } catch (...) {
      other.join();
      throw;
    }
    other.join();
    if (error) std::rethrow_exception(error);
    ahead.emplace(k - 1, std::move(lighter));
    return out;
  });
  // Noise-free data (synthetic or computed marks): the residuals are round-off, and a
  // model fitted to them has no meaning, least of all its correlation length (measured:
  // a noise-free isometric bend, 15 x 15 marks at 7 mm, gave sigma 1e-13 mm correlated
  // over 33 mm; the deformed estimate then took the bend for noise correlated over that
  // length, 0.19 mm, and smoothed the face strain 0.009 off at the edges). No noise: the
  // deformed smoothing is chosen by cross-validation.
  if (e.sigma_total() <= kNoiseFloor * d)
    e.sigma_correlated = e.sigma_white = e.correlation_length = e.bias_slope = 0.0;
  return e;
}

namespace {

// The deformed pilots' estimate (deformed_noise below adds the blank's floor).
NoiseEstimate deformed_ladder(DeformedProblem& problem, const FitMarks& marks, const FrameAndMesh& setup,
                              const NoiseEstimate& undeformed) {
  const Index m = marks.size();
  const double d = setup.mark_spacing;
  const double length = undeformed.effective_length();
  const VecX& w = problem.weight();
  const std::vector<std::vector<Index>> around = mesh::neighbours_within(marks.undeformed, 3.0 * d);
  VariogramOptions vo;
  vo.max_lag = kDeformedMaxLag * d;
  // The same ladder as the undeformed estimate, lighter: the heaviest pilot without
  // smooth bias whose estimate the next lighter one confirms. A deformation the pilot
  // cannot follow leaves bias that looks like noise; lighter pilots leave less of it,
  // while true noise gives the same estimate at every pilot (the shrinkage correction).
  // Independent noise is a correlated one with a length far below the spacing.
  const ProbeBank bank = make_probe_bank(marks.undeformed, d, length > 0 ? length : 0.01 * d);
  // The pairs depend on the points left out only: kept while the same points are usable.
  std::vector<bool> paired;
  std::optional<VariogramPairs> pairs;
  // Unconfirmed: the heaviest pilot without smooth bias. A misfit no pilot removes (a neck
  // 2-3 elements wide that the mesh cannot follow) stays in every pilot's residuals while
  // the lighter pilots take up the noise themselves, so the shrinkage correction inflates
  // it there (measured: a 1 mm neck under noise correlated over 5 spacings, 1.07 x the
  // noise at k = 4, 23 x at k = -1, the lightest, which was taken); true noise gives the
  // same estimate at every pilot, the heaviest one with the least correction.
  const Unconfirmed heaviest_unbiased = Unconfirmed::kHeaviestUnbiased;
  // A pilot's fits: the data's and the probe fields' residuals, from one factorisation in
  // the problem's workspace `slot`. Phi^T W of the probe fields is the same for every
  // pilot (the weights do not change here), formed once; forming it builds the system.
  const MatX bank_weighted = problem.weighted_values(bank.probes);
  struct PilotFits {
    FitResult fit;
    MatX shrunk;  // (I - H) of the bank's probes
    std::exception_ptr error;
  };
  auto pilot_fits = [&](int k, int slot) {
    PilotFits p;
    try {
      const Penalty pilot = jumps_penalty(k, d);
      p.fit = problem.fit(pilot, 1, slot);
      // (The data's fit with the same matrix succeeded: so does theirs.)
      p.shrunk = problem.smoothing_residual(bank.probes, bank_weighted, pilot, 1, slot);
    } catch (...) {
      p.error = std::current_exception();
    }
    return p;
  };
  // With two cores the next lighter pilot's fits run beside each one the ladder asks for,
  // in the second workspace, as in the blank's ladder; the estimates themselves (the
  // variogram pairs are kept from one pilot to the next) are taken in the ladder's order.
  // A failure of the pilot beside counts only if the ladder asks for it.
  const bool two = default_threads() >= 2;
  std::map<int, PilotFits> ahead;
  auto fits_of = [&](int k) {
    if (const auto it = ahead.find(k); it != ahead.end()) {
      PilotFits p = std::move(it->second);
      ahead.erase(it);
      return p;
    }
    if (!two || k - 1 < -1) return pilot_fits(k, 0);
    PilotFits lighter;
    std::thread other([&] { lighter = pilot_fits(k - 1, 1); });
    PilotFits p = pilot_fits(k, 0);
    other.join();
    ahead.emplace(k - 1, std::move(lighter));
    return p;
  };
  return pilot_ladder(4, -1, vo.max_lag, d, false, heaviest_unbiased, [&](int k) -> std::optional<NoiseEstimate> {
    PilotFits p = fits_of(k);
    if (p.error) std::rethrow_exception(p.error);
    const FitResult& f = p.fit;
    if (!f.ok) return std::nullopt;
    const MatX residual = MatX(problem.data()) - f.fitted;
    // Misfit exclusion: neighbourhood mean square residual far above the median.
    const VecX square = residual.rowwise().squaredNorm();
    std::vector<double> ms(static_cast<std::size_t>(m), 0.0), all;
    for (Index i = 0; i < m; ++i) {
      if (!(w[i] > 0)) continue;
      double sum = square[i];
      int count = 1;
      for (Index q : around[static_cast<std::size_t>(i)])
        if (w[q] > 0) sum += square[q], ++count;
      ms[static_cast<std::size_t>(i)] = sum / count;
      all.push_back(sum / count);
    }
    const double typical = median(all);
    std::vector<bool> usable(static_cast<std::size_t>(m));
    for (Index i = 0; i < m; ++i)
      usable[static_cast<std::size_t>(i)] = w[i] > 0 && ms[static_cast<std::size_t>(i)] <= kMisfitFactor * typical;
    if (!pairs || usable != paired) {
      pairs.emplace(marks.undeformed, usable, d, vo);
      paired = usable;
    }
    // fit_noise_model smooths the bank's probes: their residuals are p.shrunk (at every
    // point: the pairs are only known after the pilot's fit; the bank has 6 columns).
    auto shrink = [&](const MatX&, const std::vector<Index>& rows) {
      MatX at(static_cast<Index>(rows.size()), p.shrunk.cols());
      for (std::size_t i = 0; i < rows.size(); ++i) at.row(static_cast<Index>(i)) = p.shrunk.row(rows[i]);
      return at;
    };
    NoiseEstimate e = fit_noise_model(*pairs, pairs->gamma(residual, 3), bank, shrink);
    if (length <= 0) e.sigma_white = e.sigma_total(), e.sigma_correlated = 0.0;
    e.correlation_length = length;
    return e;
  });
}

}  // namespace

NoiseEstimate deformed_noise(DeformedProblem& problem, const FitMarks& marks, const FrameAndMesh& setup,
                             const NoiseEstimate& undeformed, const NoiseEstimate* displacement) {
  if (displacement) {
    // An exact blank: the displacement's length, and its correlated amplitude (of the
    // deformed noise alone) as the floor. Light pilots take up noise correlated over a
    // few spacings themselves (below); measured: rubber strip, noise over one spacing,
    // the displacement's model alone 1.34 x the best fixed smoothing's error, with the
    // pilots' amplitudes 1.00 x (docs/theory/strain.md, "A blank without noise").
    NoiseEstimate e = deformed_ladder(problem, marks, setup, *displacement);
    if (e.correlation_length > 0) e.sigma_correlated = std::max(e.sigma_correlated, displacement->sigma_correlated);
    return e;
  }
  NoiseEstimate e = deformed_ladder(problem, marks, setup, undeformed);
  // The blank's correlated amplitude as a floor: the deformed data hold both states'
  // noise, and the blank's heavy pilots see noise correlated over several spacings, where
  // the light deformed pilots take most of it up themselves and the shrinkage correction
  // cannot give it back (measured: noise over 5 spacings on the 100 mm plate, deformed
  // estimate 0.0-0.15 x the truth, the blank's 0.8-1.5 x; docs/theory/strain.md).
  if (e.correlation_length > 0)
    e.sigma_correlated = std::max(e.sigma_correlated, kBothStatesFactor * undeformed.sigma_correlated);
  return e;
}

void estimate_two_levels(NoiseEstimate& into, const FrameAndMesh& setup, const UndeformedFit& undeformed,
                         const MatX& parameters, const MatX& residual, const VecX& weight) {
  const Index m = residual.rows();
  const fe::SurfaceField surface(setup.mesh, parameters);
  std::vector<double> rn, rt;
  for (Index k = 0; k < m; ++k) {
    if (!(weight[k] > 0) || !residual.row(k).allFinite()) continue;
    const MeshLocation& loc = undeformed.location[static_cast<std::size_t>(k)];
    const Mat32 t = surface.evaluate3(loc.element, loc.xi, basis::kFirst).dx;
    const Vec3 n = t.col(0).cross(t.col(1));
    if (!(n.norm() > 0)) continue;
    const Vec3 r = residual.row(k).transpose();
    const double a = r.dot(n.normalized());
    rn.push_back(std::abs(a));
    rt.push_back((r - a * n.normalized()).norm());
  }
  if (rn.size() < 10) return;
  const double sn = median(rn) / 0.674490, st = median(rt) / 1.177410;
  into.sigma_normal = sn;
  into.sigma_tangent = st;
  const double mean = (2.0 * st * st + sn * sn) / 3.0;
  const double total = into.sigma_total();
  if (total > 0 && mean > 0) {
    const double scale = total / std::sqrt(mean);
    into.sigma_normal *= scale;
    into.sigma_tangent *= scale;
  }
}

}  // namespace sf::gsa

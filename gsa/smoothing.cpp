#include "gsa/smoothing.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "gsa/deformed_fit.hpp"
#include "gsa/noise_model.hpp"

namespace sf::gsa {

namespace {

// Calibration constants of the automatic smoothing (docs/theory/strain.md).
// (Calibrated against a noise estimate that was sigma/sqrt(3); rescaled when the
// estimate was corrected to sigma, so the weights did not change.)
constexpr double kAutoGamma = 258.7;    // 500 / 3^0.6
constexpr double kAutoBeta = 115.47;    // 200 / sqrt(3)
constexpr double kAutoDelta = 11547.0;  // 2e4 / sqrt(3)
// A whisper of third-order smoothing holds elements the edge jumps alone cannot
// (a single element, or elements with fewer marks than parameters).
constexpr double kJumpsGammaFloor = 1e-6;
constexpr double kGcvStrainFactor = 2.0;
// The boundary elements' third-order term is taken when GCV falls by this over N, the
// number of marks (about two degrees of freedom per coordinate). Measured ratios of GCV
// with the term to without: 0.97-0.98 on homogeneous and nearly homogeneous parts
// (N (1 - ratio) = 6-14 at N = 441-1681, 90 on a 4141-point strip), 1.01-1.03 on bent
// and domed ones, 0.990-1.000 on the trellis map with 0.03 mm noise (N (1 - ratio) <= 4.6
// at N = 441), where the term biased the strain 1.3 x.
constexpr double kBoundaryGcvGain = 6.0;
// The automatic deformed fit is iterated once (two passes, iterated Tikhonov): the
// second pass smooths towards the first one, which squares the smoothing bias.
constexpr int kAutoFitPasses = 2;

}  // namespace

Penalty explicit_penalty(const SmoothingOptions& options) {
  Penalty p;
  if (options.alpha) p.alpha = *options.alpha;
  if (options.beta) p.beta = *options.beta;
  if (options.gamma) p.gamma = *options.gamma;
  if (options.delta) p.delta = *options.delta;
  return p;
}

Penalty noise_rule_penalty(const SmoothingOptions& options, double sigma, double mark_spacing) {
  const double d = mark_spacing;
  Penalty p;
  const double ratio = std::max(sigma / d, 1e-6);
  if (options.penalty == PenaltyKind::kJumps) {
    p.delta = options.scale * kAutoDelta * std::pow(d, 6) * std::pow(ratio, 1.0) + 1e-8 * std::pow(d, 6);
    p.gamma = kJumpsGammaFloor * std::pow(d, 4);
  } else if (options.penalty == PenaltyKind::kThirdOrder) {
    p.gamma = options.scale * kAutoGamma * std::pow(d, 4) * std::pow(ratio, 1.2) + 1e-8 * std::pow(d, 4);
    p.beta = 0.0;
  } else {
    p.beta = options.scale * kAutoBeta * std::pow(d, 2) * ratio + 1e-8 * d * d;
  }
  return p;
}

Penalty penalty_for_noise(const SmoothingOptions& options, double sigma, double mark_spacing) {
  return options.automatic() ? noise_rule_penalty(options, sigma, mark_spacing) : explicit_penalty(options);
}

double gauge_length(const Penalty& p, double mark_spacing) {
  const double rho = 1.0 / (mark_spacing * mark_spacing);
  return std::max({std::pow(std::max(p.gamma, 0.0) / rho, 1.0 / 6.0), std::pow(std::max(p.beta, 0.0) / rho, 0.25),
                   std::pow(std::max(p.delta, 0.0) / rho, 0.125)});
}

Penalty jumps_penalty(double log10_delta, double mark_spacing, double boundary_factor) {
  Penalty p;
  p.gamma = kJumpsGammaFloor * std::pow(mark_spacing, 4);
  p.delta = std::pow(10.0, log10_delta) * std::pow(mark_spacing, 6);
  p.boundary = boundary_factor * p.delta;
  return p;
}

namespace {

// Minimises `score` over log10(delta / d^6) in [-6, 6], two candidates at a time (fitted
// on two threads): the bracket keeps the best point in its middle and halves each round
// until it is `tolerance` wide.
struct BracketMinimum {
  double at = 0.0, value = 0.0;
};

// [lo, hi] = [-6, 6] by default; the first pair at its thirds.
template <class PairScore>
BracketMinimum bracket_search(const PairScore& score_pair, double tolerance, double lo = -6.0, double hi = 6.0) {
  const double a = lo + (hi - lo) / 3.0, b = hi - (hi - lo) / 3.0;
  double left = lo, right = hi, best = a;
  const std::array<double, 2> g0 = score_pair(a, b);
  double g_best = g0[0];
  if (g0[0] <= g0[1]) {
    right = b;
  } else {
    left = a, best = b, g_best = g0[1];
  }
  while (right - left > tolerance) {
    const double p1 = 0.5 * (left + best), p2 = 0.5 * (best + right);
    const std::array<double, 2> g = score_pair(p1, p2);
    if (g[0] < g_best && g[0] <= g[1]) {
      right = best, best = p1, g_best = g[0];
    } else if (g[1] < g_best) {
      left = best, best = p2, g_best = g[1];
    } else {
      left = p1, right = p2;
    }
  }
  return {best, g_best};
}

double weighted_rss(const FitResult& f, const VecX& w) {
  double rss = 0.0;
  for (Index k = 0; k < w.size(); ++k)
    if (w[k] > 0) rss += w[k] * f.residual[k] * f.residual[k];  // weights 1 without sigmas
  return rss;
}

SmoothingChoice strain_choice(const BracketMinimum& best, const char* criterion, const SmoothingOptions& options,
                              double d, double boundary_factor = 0.0) {
  SmoothingChoice choice;
  choice.log10_delta_optimum = best.at;
  choice.criterion = criterion;
  choice.criterion_value = best.value;
  choice.penalty = jumps_penalty(best.at, d, boundary_factor);
  choice.penalty.delta *= options.scale * kGcvStrainFactor;
  choice.penalty.boundary *= options.scale * kGcvStrainFactor;
  choice.passes = kAutoFitPasses;
  return choice;
}

}  // namespace

SmoothingChoice choose_smoothing_gcv(DeformedProblem& problem, const SmoothingOptions& options, double mark_spacing) {
  const double d = mark_spacing;
  const VecX& w = problem.weight();
  const double n_used = w.sum();
  // Hutchinson probes: the trace estimate's relative error falls as 1/sqrt(probes * N),
  // so large grids need fewer probes for the same GCV curve.
  const int probes = n_used > 20000 ? 6 : 12;
  const double tolerance = n_used > 20000 ? 0.3 : 0.2;
  auto gcv = [&](const FitResult& f) {
    if (!f.ok || !(f.edf < 0.95 * n_used)) return std::numeric_limits<double>::infinity();
    const double a = 1.0 - f.edf / n_used;
    return weighted_rss(f, w) / (3.0 * n_used) / (a * a);
  };
  double factor = 0.0;
  auto pair = [&](double a, double b) {
    const std::array<FitResult, 2> f =
        problem.fit_pair({jumps_penalty(a, d, factor), jumps_penalty(b, d, factor)}, probes, kAutoFitPasses);
    return std::array<double, 2>{gcv(f[0]), gcv(f[1])};
  };
  const BracketMinimum plain = bracket_search(pair, tolerance);
  // With the term the optimum lies at or below the plain one (by up to 1.2 measured): the
  // second search brackets [plain - 3, plain + 0.6], 5 pairs instead of 7.
  factor = kBoundaryThirdFactor;
  const BracketMinimum edged =
      bracket_search(pair, tolerance, std::max(-6.0, plain.at - 3.0), std::min(6.0, plain.at + 0.6));
  // The boundary term must earn its place: GCV lower by kBoundaryGcvGain / N or more.
  if (edged.value < (1.0 - kBoundaryGcvGain / n_used) * plain.value)
    return strain_choice(edged, "GCV", options, d, factor);
  return strain_choice(plain, "GCV", options, d);
}

SmoothingChoice choose_smoothing_noise_model(DeformedProblem& problem, const SmoothingOptions& options,
                                             const MatX& probes_of_noise, double mark_spacing) {
  const double d = mark_spacing;
  const VecX& w = problem.weight();
  const double n_used = w.sum();
  const int probes = static_cast<int>(probes_of_noise.cols());
  const double tolerance = n_used > 20000 ? 0.3 : 0.2;
  problem.set_probes(probes_of_noise);
  // Cp with correlated noise: E|H z - f|^2 = |z - H z|^2 - tr(Sigma) + 2 tr(H Sigma) per
  // component; the trace from probes drawn from the noise model.
  auto cp = [&](const FitResult& f) {
    if (!f.ok || !(f.edf < 0.95 * n_used)) return std::numeric_limits<double>::infinity();
    return weighted_rss(f, w) + 6.0 * f.edf;
  };
  auto pair = [&](double a, double b) {
    const std::array<FitResult, 2> f =
        problem.fit_pair({jumps_penalty(a, d), jumps_penalty(b, d)}, probes, kAutoFitPasses);
    return std::array<double, 2>{cp(f[0]), cp(f[1])};
  };
  return strain_choice(bracket_search(pair, tolerance), "Cp", options, d);
}

}  // namespace sf::gsa

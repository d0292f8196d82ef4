#include "gsa/smoothing.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "gsa/deformed_fit.hpp"

namespace sf::gsa {

namespace {

// Calibration constants of the automatic smoothing (docs/theory/strain.md).
// (Calibrated against a noise estimate that was sigma/sqrt(3); rescaled when the
// estimate was corrected to sigma, so the weights did not change.)
constexpr double kAutoGamma = 258.7;   // 500 / 3^0.6
constexpr double kAutoBeta = 115.47;   // 200 / sqrt(3)
constexpr double kAutoDelta = 11547.0;  // 2e4 / sqrt(3)
// A whisper of third-order smoothing holds elements the edge jumps alone cannot
// (a single element, or elements with fewer marks than parameters).
constexpr double kJumpsGammaFloor = 1e-6;
constexpr double kGcvStrainFactor = 2.0;
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

SmoothingChoice choose_smoothing_gcv(DeformedProblem& problem, const SmoothingOptions& options, double mark_spacing) {
  const double d = mark_spacing;
  const VecX& w = problem.weight();
  const double n_used = w.sum();
  // Hutchinson probes: the trace estimate's relative error falls as 1/sqrt(probes * N),
  // so large grids need fewer probes for the same GCV curve.
  const int probes = n_used > 20000 ? 6 : 12;
  const double tolerance = n_used > 20000 ? 0.3 : 0.2;
  auto penalty_at = [&](double log_delta) {
    Penalty p;
    p.gamma = kJumpsGammaFloor * std::pow(d, 4);
    p.delta = std::pow(10.0, log_delta) * std::pow(d, 6);
    return p;
  };
  auto gcv = [&](const FitResult& f) {
    if (!f.ok || !(f.edf < 0.95 * n_used)) return std::numeric_limits<double>::infinity();
    double rss = 0.0;
    for (Index k = 0; k < w.size(); ++k)
      if (w[k] > 0) rss += f.residual[k] * f.residual[k];
    const double a = 1.0 - f.edf / n_used;
    return rss / (3.0 * n_used) / (a * a);
  };
  auto gcv_pair = [&](double a, double b) {
    const std::array<FitResult, 2> f = problem.fit_pair({penalty_at(a), penalty_at(b)}, probes, kAutoFitPasses);
    return std::array<double, 2>{gcv(f[0]), gcv(f[1])};
  };
  // The bracket keeps the best point in its middle and halves each round.
  double left = -6.0, right = 6.0, best = -2.0;
  const std::array<double, 2> g0 = gcv_pair(-2.0, 2.0);
  double g_best = g0[0];
  if (g0[0] <= g0[1]) {
    right = 2.0;
  } else {
    left = -2.0, best = 2.0, g_best = g0[1];
  }
  while (right - left > tolerance) {
    const double p1 = 0.5 * (left + best), p2 = 0.5 * (best + right);
    const std::array<double, 2> g = gcv_pair(p1, p2);
    if (g[0] < g_best && g[0] <= g[1]) {
      right = best, best = p1, g_best = g[0];
    } else if (g[1] < g_best) {
      left = best, best = p2, g_best = g[1];
    } else {
      left = p1, right = p2;
    }
  }
  SmoothingChoice choice;
  choice.gcv_log10_delta = best;
  choice.penalty.gamma = kJumpsGammaFloor * std::pow(d, 4);
  choice.penalty.delta = options.scale * kGcvStrainFactor * std::pow(10.0, best) * std::pow(d, 6);
  choice.passes = kAutoFitPasses;
  return choice;
}

}  // namespace sf::gsa

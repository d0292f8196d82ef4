#pragma once
// The smoothing weights of `gsa analyse` (docs/theory/strain.md, "Automatic smoothing"):
// explicit weights, the noise rule, and the choice of the deformed fit's weight by
// generalised cross-validation (GCV).
//
// A smoothing choice is a replaceable step: any function that takes the deformed fit's
// problem (its data, weights and least-squares system, gsa/deformed_fit.hpp) and returns
// a SmoothingChoice can stand where choose_smoothing_gcv() stands in analyse().

#include <limits>
#include <optional>

#include "common/core/types.hpp"
#include "gsa/fit.hpp"

namespace sf::gsa {

class DeformedProblem;
struct NoiseEstimate;

enum class PenaltyKind {
  kThirdOrder,  // gamma: third derivatives with edge jumps of the second (--penalty third)
  kSobolev,     // alpha, beta: the brief's first and second derivatives (--penalty sobolev)
  kJumps,       // delta: fourth-order edge jumps, weight by GCV (--penalty jumps, the default)
};

// How the automatic deformed weight is chosen (jumps penalty).
enum class SmoothingRule {
  kNoiseModel,  // the noise model; Cp where it finds noise correlated over a spacing or more, GCV where
                // the noise is independent (--smoothing-rule noise-model, the default)
  kGcv,         // generalised cross-validation, which assumes independent errors (--smoothing-rule gcv)
};

struct SmoothingOptions {
  PenaltyKind penalty = PenaltyKind::kJumps;
  SmoothingRule rule = SmoothingRule::kNoiseModel;
  bool local =
      true;  // relax the smoothing, and refine the automatic mesh, where the fit cannot follow a localised feature
  // Explicit weights: giving any switches the automatic choice off; these are used for
  // both fits and the unset ones are 0. Units: alpha 1, beta units^2, gamma units^4,
  // delta units^6 (each >= 0).
  std::optional<double> alpha, beta, gamma, delta;
  double scale = 1.0;  // multiplies the automatic weights (> 0; > 1 smoother)

  bool automatic() const { return !alpha && !beta && !gamma && !delta; }
  // Automatic jumps: the deformed weight is chosen by cross-validation.
  bool chooses_by_gcv() const { return automatic() && penalty == PenaltyKind::kJumps; }
};

// The explicit weights (unset ones 0).
Penalty explicit_penalty(const SmoothingOptions& options);
// The noise rule: weights of the options' penalty kind from the digitisation noise sigma
// (per coordinate, units) and the mark spacing d (units).
Penalty noise_rule_penalty(const SmoothingOptions& options, double sigma, double mark_spacing);
// Explicit weights, or the noise rule when automatic.
Penalty penalty_for_noise(const SmoothingOptions& options, double sigma, double mark_spacing);

// The jumps penalty with delta = 10^log10_delta d^6 (and the small third-order floor);
// the boundary elements' third-order weight is boundary_factor x delta.
Penalty jumps_penalty(double log10_delta, double mark_spacing, double boundary_factor = 0.0);

// Effective smoothing length (units) of a penalty: the largest of (gamma/rho)^(1/6),
// (beta/rho)^(1/4), (delta/rho)^(1/8), rho = 1/d^2.
double gauge_length(const Penalty& penalty, double mark_spacing);

struct SmoothingChoice {
  Penalty penalty;
  int passes = 1;                                                         // of the fit (iterated Tikhonov, gsa/fit.hpp)
  double log10_delta_optimum = std::numeric_limits<double>::quiet_NaN();  // the criterion's optimum, log10(delta / d^6)
  const char* criterion = "";  // "GCV" or "Cp" (noise model); empty for explicit weights
  double criterion_value = std::numeric_limits<double>::quiet_NaN();  // at the optimum (GCV: mm^2; Cp: mm^2 summed)
};

// Generalised cross-validation of the deformed positions over log10(delta / d^6) in
// [-6, 6], two candidates at a time (solved in parallel), each candidate fitted with two
// passes; the weight used is 2 x the optimum (strains want more smoothing than
// positions) times options.scale. The search runs twice, without and with the boundary
// elements' third-order term (Penalty::boundary = kBoundaryThirdFactor x delta), and the
// term is kept where it lowers GCV clearly (by 6 / N): the term cuts the strain error at the outline of nearly homogeneous
// parts 2-5 x and GCV turns it down on curved ones, where it would bias the edge
// (bench/gsa_edge_bench). Fits the problem's current data with its current weights;
// leaves its data and weights as they are.
inline constexpr double kBoundaryThirdFactor = 10.0;
SmoothingChoice choose_smoothing_gcv(DeformedProblem& problem, const SmoothingOptions& options, double mark_spacing);

// The same search minimising Mallows' Cp with correlated noise,
//   Cp = |z - H z|^2 + 2 x 3 tr(H Sigma)   (3 components, Sigma per component),
// an unbiased estimate of the position error |H z - f|^2 up to a constant, with
// tr(H Sigma) estimated from `probes` drawn from the noise model at the marks
// (noise_probes(noise, undeformed positions, kCpNoiseProbes): made once, used for every
// choice of one analysis). Where the noise is independent this is close to GCV; where it
// is correlated, GCV takes the correlated part for signal and under-smooths, Cp does not.
// The weight used is 2 x the optimum (as for GCV) times options.scale. Leaves the
// problem's probes set to the noise probes.
inline constexpr int kCpNoiseProbes = 12;  // four random fields, three components each
SmoothingChoice choose_smoothing_noise_model(DeformedProblem& problem, const SmoothingOptions& options,
                                             const MatX& probes, double mark_spacing);

}  // namespace sf::gsa

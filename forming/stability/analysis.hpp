#pragma once
// What `simform stability` computes from a trellis flow: the growth rate over wavelength and
// buckle direction, the most unstable mode, a verdict, the two stability maps (thickening and
// thinning flows) and an independent numerical check of the closed form at the most unstable
// mode (spectral.hpp). Plain data; writing it is output.hpp's job.

#include <string>
#include <vector>

#include "forming/stability/spectral.hpp"
#include "forming/stability/trellis.hpp"

namespace sf::forming::stability {

struct ScanOptions {
  double min_wavelength = 0.0;  // mm; 0: half the thickness
  double max_wavelength = 0.0;  // mm; 0: 200 thicknesses
  int n_wavelengths = 41;       // log-spaced, >= 2
  int n_directions = 180;       // wave directions theta = 0, 180/n, ... < 180 deg, >= 4
  int spectral_degree = 16;     // N of the numerical check, 2..29
  void validate() const;        // throws std::invalid_argument
};

// One row of growth_rate.csv.
struct ModeRow {
  double theta_deg = 0.0;          // wave direction n, degrees from x1
  double crest_deg = 0.0;          // crests run along theta + 90 deg
  double wavelength = 0.0;         // mm
  double wave_number = 0.0;        // K = 2 pi / wavelength, 1/mm
  double kappa = 0.0;              // (K h)^2
  double resolved_tension = 0.0;   // T_n, MPa
  double growth_rate = 0.0;        // G, 1/s
  double growth_rate_rel = 0.0;    // G - D33, 1/s
  double newtonian_sinuous = 0.0;  // G of the same sheet without fibres (same rates), 1/s
  bool normal_to_fibre = false;    // an exceptional direction (sheet.hpp)
};

enum class Verdict {
  kStable,   // every resolved fibre tension > 0: buckles shrink relative to the thickness
  kNeutral,  // the smallest resolved tension is 0 (a slack family)
  kBuckles,  // some resolved fibre tension < 0: buckles grow relative to the thickness
};
std::string to_string(Verdict v);

struct MostUnstableMode {
  double theta_deg = 0.0;         // wave direction, degrees from x1, in [0, 180)
  double crest_deg = 0.0;         // crest direction
  double resolved_tension = 0.0;  // smallest eigenvalue of the fibre stress tensor, MPa
  double growth_rate = 0.0;       // G, 1/s (every wavelength)
  double growth_rate_rel = 0.0;   // G - D33, 1/s
  double tau = 0.0;               // T_n / (mu |gamma_dot|) (NaN when gamma_dot = 0)
  bool normal_to_fibre = false;
};

struct StabilityMap {
  FlowKind kind = FlowKind::kThickening;
  double fibre_angle = 0.0;         // chi, rad
  std::vector<double> log10_kappa;  // grid, ascending
  std::vector<double> tau;          // grid, ascending
  std::vector<double> growth;       // Gamma = G / |gamma_dot|, tau-major: [i_tau * n_kappa + i_kappa]
  double boundary_tau = 0.0;        // Gamma = 0 at tau = s |cot chi|
};

struct StabilityResult {
  TrellisFlow flow;
  ScanOptions scan;
  std::vector<ModeRow> rows;  // direction-major
  MostUnstableMode mode;
  Verdict verdict = Verdict::kStable;
  std::string verdict_line;  // one line for stdout
  std::string mode_line;     // one line for stdout
  StabilityMap thickening_map, thinning_map;
  // The two wave directions normal to a family (crests along it): the closed form's limit
  // there and the buckle's instantaneous growth rate from the numerical solution (no normal
  // mode exists there in the ideal model; docs/theory/stability.md, section 4.3).
  struct Exceptional {
    double theta_deg = 0.0;
    double closed_form_limit = 0.0;  // 1/s
    double instantaneous = 0.0;      // 1/s
  };
  std::vector<Exceptional> exceptional;
  // Numerical check at the most unstable direction and the middle wavelength.
  double check_wave_number = 0.0;
  double check_closed_form = 0.0;
  SpectralReport check;
};

StabilityResult analyse_stability(const TrellisFlow& flow, const ScanOptions& scan);

// Map grid over log10 kappa in [lo, hi] and tau in [tau_lo, tau_hi].
StabilityMap stability_map(FlowKind kind, double fibre_angle, double log10_kappa_lo, double log10_kappa_hi,
                           double tau_lo, double tau_hi, int n_kappa, int n_tau);

}  // namespace sf::forming::stability

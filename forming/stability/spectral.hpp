#pragma once
// Independent numerical solution of the linearised buckling problem (docs/theory/stability.md,
// section 7): a Legendre-Galerkin discretisation through the thickness of the full
// linearised equations, with none of the reductions the closed forms use.
//
//   unknowns     velocity u(z) and displacement xi(z) of the perturbation, three components
//                each (wave frame s = n, t = crest, z = normal), polynomials in zeta = 2 z / h
//                of degree N + 1 (u) and N (xi); the Fourier factor exp(i K s) is implied;
//   constraints  incompressibility and (with fibres) inextensibility of each family, of both
//                u and xi, imposed at the N + 1 Chebyshev-Lobatto points (so they hold as
//                polynomial identities); their null spaces come from an SVD;
//   weak form    virtual power over admissible virtual velocities (the reactions p, T_a, T_b
//                and the concentrated forces of surface fibres do no work on them):
//                  integral 2 mu D(u) : D(du)* + sum_f T_f (f1 (x) f + f (x) f1) : grad(du)* dz
//                  - [du_beta* sigma0_beta,alpha i K n_alpha xi_3] at z = h/2, + the same at -h/2
//                  = 0,   f1 = grad(xi) f - (f.grad(xi).f) f  (fibre direction perturbation);
//   evolution    G xi = u + D0 xi (convected derivative): a small eigenproblem on the
//                admissible displacements; G are its eigenvalues.
//
// Without fibres the displacement inside the sheet does not enter the stress, so the state
// is the pair of surface displacements (top, bottom): one sinuous and one varicose mode.
//
// Error channels: options out of range -> std::invalid_argument (programming error);
// numerical outcomes (an inconsistent constraint system, a mode space that the flow does not
// map into itself, as at wave directions normal to a fibre family) -> SpectralReport.

#include <complex>
#include <limits>
#include <string>
#include <vector>

#include "forming/stability/sheet.hpp"

namespace sf::forming::stability {

struct SpectralOptions {
  int degree = 24;                     // N, polynomial degree through the thickness, 2..29
  bool with_fibres = true;             // false: ignore the sheet's fibres (Newtonian sheet)
  double rank_tolerance = 1e-10;       // relative singular value counted as zero
  double invariance_tolerance = 1e-8;  // relative; above it the state is no normal mode
  void validate() const;               // throws std::invalid_argument
};

struct SpectralReport {
  enum class Status {
    kOk,             // eigenvalues found; growth_rate is the largest real part
    kNotNormalMode,  // the flow carries admissible states out of the admissible space (at a wave
                     // direction normal to a family); growth_rate = buckle_growth_rate
    kFailed,         // inconsistent constraints or a singular viscous system
  };
  Status status = Status::kFailed;
  std::string message;
  double growth_rate = std::numeric_limits<double>::quiet_NaN();  // 1/s
  std::vector<std::complex<double>> eigenvalues;                  // all modes, largest real part first, 1/s
  // Instantaneous growth rate of the buckle state xi = e3 (uniform through the thickness), 1/s;
  // growth_rate when the status is kNotNormalMode.
  double buckle_growth_rate = std::numeric_limits<double>::quiet_NaN();
  double sinuous = std::numeric_limits<double>::quiet_NaN();   // Newtonian sheet only, 1/s
  double varicose = std::numeric_limits<double>::quiet_NaN();  // Newtonian sheet only, 1/s
  int n_state = 0;                                             // dimension of the admissible displacement space
  int n_velocity = 0;                                          // dimension of the admissible velocity space
  double constraint_residual = 0.0;  // |C u - E xi| / |E| of the velocity constraints (consistency)
  double invariance_residual = 0.0;  // relative part of d(xi)/dt outside the admissible states

  bool ok() const { return status == Status::kOk; }
  std::string brief() const;
};

// Growth rates of the perturbation with wave direction theta (rad) and wave number K (1/mm).
// The sheet must satisfy SheetState::validate(); K > 0.
SpectralReport solve_spectral(const SheetState& sheet, double theta, double wave_number,
                              const SpectralOptions& options = {});

}  // namespace sf::forming::stability

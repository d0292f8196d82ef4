#pragma once
// The input file of `simform stability` (YAML; docs/forming.md, "Buckling stability"):
//
//   units: "mm, s, MPa"                  # optional note
//   fibres: [30, -30]                    # families a and b, degrees from x1
//   viscosity: 1.0e-3                    # mu, MPa s
//   thickness: 2.0                       # h, mm
//   shear_rate: 0.5                      # trellis shear rate, 1/s ...
//   rates: {D11: 0.14, D22: -0.43, D12: 0}   # ... or the in-plane rates, 1/s (D33 optional)
//   tensions: {T_a: 0.02, T_b: -0.01}    # MPa; with the rates or shear rate
//   tractions: {sigma11: 0.1, sigma22: -0.05, sigma12: 0}   # MPa; instead of all three above
//   scan: {wavelengths: [1, 400], n_wavelengths: 41, n_directions: 180}   # optional, mm
//
// Every key is checked (an unknown key is an error); problems are sf::InputError
// "FILE:LINE:COLUMN: what was expected, what was found". Values are checked for physical
// consistency later, by build_trellis_flow(), with the same positions.

#include <string>

#include "forming/stability/analysis.hpp"
#include "forming/stability/trellis.hpp"

namespace sf::forming::stability {

struct StabilityInput {
  TrellisSpec spec;  // the *_at fields hold FILE:LINE:COLUMN of each value read
  ScanOptions scan;
  bool has_fibres = false, has_viscosity = false, has_thickness = false;
  std::string units;  // the optional note
  // FILE:LINE:COLUMN of the file's top-level mapping: where a missing key is reported (the
  // *_at fields of a key the file does not give read "FILE:LINE:COLUMN: key 'NAME'").
  std::string at;
};

// Reads and checks the structure of the file. Throws sf::InputError.
StabilityInput read_stability_input(const std::string& path);

}  // namespace sf::forming::stability

#pragma once
// Analytic deformations of a flat blank with exact strains: the sample data in
// data/ and the accuracy tests are generated from these (`gsa synth`).
//
// Every map takes undeformed points (X, Y, 0) of a flat blank and returns the
// deformed position and the exact principal stretches (lambda1 >= lambda2).

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/grid.hpp"

namespace sf::gsa {

struct ExactStrain {
  double lambda1 = 1.0, lambda2 = 1.0;
  double shear_angle_deg = 0.0;  // trellis case only (fibres 0,90)
};

struct SyntheticCase {
  std::string name;  // dome, cylinder, trellis, wavy, rigid, stretch, shear
  std::string description;
  Vec3 (*map)(const Vec3& X) = nullptr;
  ExactStrain (*exact)(const Vec3& X) = nullptr;
};

// Known names: rigid, stretch, shear, cylinder, dome, wavy, trellis.
const SyntheticCase& synthetic_case(const std::string& name);
std::vector<std::string> synthetic_case_names();

struct SyntheticGridOptions {
  int n = 21;                     // marks per side
  double spacing = 5.0;           // mm
  double noise = 0.0;             // standard deviation per coordinate, both states (mm)
  double missing_deformed = 0.0;  // fraction of marks without a deformed position
  int outliers = 0;               // marks moved by 2 mm in the deformed state
  bool round = false;             // only the marks inside the grid's inscribed circle (a round blank)
  unsigned seed = 1;
};

// Grid of n x n marks centred on the origin, mapped by the case; exact strains per mark.
GridData make_synthetic_grid(const SyntheticCase& c, const SyntheticGridOptions& o,
                             std::vector<ExactStrain>* exact = nullptr);

}  // namespace sf::gsa

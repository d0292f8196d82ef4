#pragma once
// A problem as the steppers solve it (forming/solve/stepper.hpp): the model (bodies and
// interactions), the loads with their ramps, the prescribed unknowns with theirs, and
// the bodies' densities for inertia. Built once from a case (forming/case/build.hpp) or
// by hand in tests.
#include <vector>

#include "forming/model/loads.hpp"
#include "forming/model/model.hpp"
#include "forming/model/prescriptions.hpp"

namespace sf::forming {

struct Problem {
  Model model;
  RampedLoads loads;            // f_ext(lambda, x)
  Prescriptions prescriptions;  // x_d(lambda) on the prescribed dofs
  std::vector<double> density;  // one per body, t/mm^3 (0 = not given; dynamics needs > 0)
};

}  // namespace sf::forming

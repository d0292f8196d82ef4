// Ideal fibre-reinforced strip (incompressible, inextensible fibres along it) under an
// end load (notes/forming-verification.md §1.4, Spencer; Everstine & Pipkin): with
// inextensible fibres the strip cannot bend by fibre stretch and deflects by uniform
// longitudinal shear, delta = P L / (G_L b h); with a finite fibre modulus the bending
// term adds, delta = P L^3 / (3 E_f I) + P L / (G_L b h). Both plies run through the
// case file with exact (augmented-Lagrangian) element-mean constraints.
//
// Not resolved here: the fibre-stress boundary layers at the surfaces (thickness
// ~ h sqrt(G_L/E_f)); one linear brick through the thickness carries the end moment as
// a linear fibre-stress distribution, whose stiffness comes from E_f.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "forming/case/reader.hpp"
#include "forming/run/run.hpp"

namespace sf::forming {
namespace {

double tip_deflection(double e_f) {
  const std::string text = R"(
materials:
  ideal:
    transversely_isotropic: {E_f: )" +
                           std::to_string(e_f) + R"(, E_T: 1, G_L: 0.5, G_T: 0.4}
    incompressible: true
    inextensible: true
plies:
  - {name: strip, size: [100, 10], thickness: 2, elements: [20, 1], angle: 0, material: ideal}
boundary_conditions:
  - clamp: {ply: strip, edge: x0}
loads:
  - edge_force: {ply: strip, edge: x1, force: [0, 0, -0.01]}
solver: {steps: 1, tolerance: 1.0e-8}
)";
  const CaseCheck c = check_case_text(text, "ideal_strip.yaml");
  EXPECT_TRUE(c.ok()) << (c.ok() ? "" : c.located(0));
  RunOptions o;
  o.quiet = true;
  o.out_dir = (std::filesystem::temp_directory_path() / "sf_ideal_fibre_strip").string();
  const RunReport r = run_case(c.spec, o);
  EXPECT_TRUE(r.ok()) << r.message;
  std::filesystem::remove_all(o.out_dir);
  return -r.max_displacement.z();
}

TEST(IdealFibreStrip, EndLoadDeflectionIsShearPlusFibreBending) {
  const double P = 0.01, L = 100.0, b = 10.0, h = 2.0, G_L = 0.5, I = b * h * h * h / 12.0;
  const double shear = P * L / (G_L * b * h);  // 0.1 mm
  for (double e_f : {25000.0, 2.5e6}) {
    const double expected = P * L * L * L / (3.0 * e_f * I) + shear;
    const double got = tip_deflection(e_f);
    EXPECT_NEAR(got, expected, 0.02 * expected) << "E_f " << e_f;
    std::printf(
        "ideal-fibre strip, E_f/G_L = %.0f: tip %.5f mm, P L^3/(3 E_f I) + P L/(G_L b h) = %.5f mm (%.2f %%); "
        "shear-beam limit %.5f mm\n",
        e_f / G_L, got, expected, 100.0 * (got - expected) / expected, shear);
  }
}

}  // namespace
}  // namespace sf::forming

// Dynamic analysis through the case file (solver analysis: dynamic).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "forming/case/reader.hpp"
#include "forming/run/run.hpp"

namespace sf::forming {
namespace {

// The dynamic free-bending sample ramps gravity up smoothly over about five periods of
// the strip's first mode: it ends near the static sag of free_bending.yaml (the same
// strip loaded quasi-statically), the clamp carrying the weight.
TEST(DynamicCase, SlowlyLoadedStripEndsNearTheStaticSag) {
  const std::string dir = std::string(SF_SOURCE_DIR) + "/data/forming/";
  RunOptions o;
  o.quiet = true;
  o.out_dir = (std::filesystem::temp_directory_path() / "sf_dynamic_case_static").string();
  const RunReport s = run_case(load_case(dir + "free_bending.yaml"), o);
  ASSERT_TRUE(s.ok()) << s.message;
  o.out_dir = (std::filesystem::temp_directory_path() / "sf_dynamic_case_dynamic").string();
  const RunReport d = run_case(load_case(dir + "free_bending_dynamic.yaml"), o);
  ASSERT_TRUE(d.ok()) << d.message;
  const double tip_s = -s.max_displacement.z(), tip_d = -d.max_displacement.z();
  EXPECT_NEAR(tip_d, tip_s, 0.05 * tip_s);
  EXPECT_NEAR(d.tool_force.z(), s.tool_force.z(), 0.1 * s.tool_force.z());
  std::printf(
      "free bending: static tip %.4f mm, dynamic (end of smooth ramp) %.4f mm (%.2f %%); clamp %.5f vs %.5f N\n", tip_s,
      tip_d, 100.0 * (tip_d - tip_s) / tip_s, d.tool_force.z(), s.tool_force.z());
  std::filesystem::remove_all(o.out_dir);
}

TEST(DynamicCase, DynamicAnalysisNeedsDensityAndRejectsConstraints) {
  const std::string text = R"(
materials:
  m:
    neo_hookean: {mu: 1, lambda: 2}
    incompressible: true
plies:
  - {name: p, size: [1, 1], thickness: 1, elements: [1, 1], material: m}
boundary_conditions:
  - clamp: {ply: p, edge: x0}
solver: {analysis: dynamic, end_time: 1}
)";
  const CaseCheck c = check_case_text(text, "dyn.yaml");
  ASSERT_EQ(c.problems.size(), 2u);
  EXPECT_NE(c.located(0).find("has no density"), std::string::npos) << c.located(0);
  EXPECT_NE(c.located(1).find("quasi-static only"), std::string::npos) << c.located(1);
  const CaseCheck wrong = check_case_text(R"(
materials: {m: {neo_hookean: {mu: 1, lambda: 2}}}
plies: [{name: p, size: [1, 1], thickness: 1, elements: [1, 1], material: m}]
boundary_conditions: [{clamp: {ply: p, edge: x0}}]
solver: {end_time: 1, integrator: leapfrog}
)",
                                          "static.yaml");
  // The unknown integrator, and both keys outside a dynamic analysis.
  ASSERT_EQ(wrong.problems.size(), 3u);
  std::string all;
  for (std::size_t i = 0; i < wrong.problems.size(); ++i) all += wrong.located(i) + "\n";
  EXPECT_NE(all.find("expected generalized-alpha, hht-alpha or newmark, found 'leapfrog'"), std::string::npos) << all;
  EXPECT_NE(all.find("solver end_time: only used with analysis: dynamic"), std::string::npos) << all;
}

}  // namespace
}  // namespace sf::forming

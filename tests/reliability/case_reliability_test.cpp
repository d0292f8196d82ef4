// Issue 20, simform case files: every bad input named with its place, and check goes on
// listing problems; plies nothing holds, impossible geometry, absurd durations and models
// beyond the machine's memory are refused by `simform check` (forming/case/model_checks.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "forming/case/model_checks.hpp"
#include "forming/case/reader.hpp"

namespace sf::forming {
namespace {

using ::testing::HasSubstr;

// A clean two-ply case; `replace` swaps a piece of it for a defect.
std::string two_plies(const std::string& from = "", const std::string& to = "") {
  std::string t =
      "materials:\n"                                                            // 1
      "  m:\n"                                                                  // 2
      "    transversely_isotropic: {E_f: 25000, E_T: 1, G_L: 0.5, G_T: 0.4}\n"  // 3
      "plies:\n"                                                                // 4
      "  - name: a\n"                                                           // 5
      "    size: [100, 20]\n"                                                   // 6
      "    thickness: 1\n"                                                      // 7
      "    elements: [4, 2]\n"                                                  // 8
      "    material: m\n"                                                       // 9
      "  - name: b\n"                                                           // 10
      "    size: [100, 20]\n"                                                   // 11
      "    origin: [0, 40, 0]\n"                                                // 12
      "    thickness: 1\n"                                                      // 13
      "    elements: [4, 2]\n"                                                  // 14
      "    material: m\n"                                                       // 15
      "boundary_conditions:\n"                                                  // 16
      "  - clamp: {ply: a, edge: x0}\n"                                         // 17
      "  - clamp: {ply: b, edge: x0}\n"                                         // 18
      "loads:\n"                                                                // 19
      "  - pressure: {ply: b, face: top, value: 0.001}\n"                       // 20
      "solver: {steps: 2}\n";                                                   // 21
  if (!from.empty()) {
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) t.replace(at, from.size(), to);
  }
  return t;
}

std::string all(const CaseCheck& c) {
  std::string s;
  for (std::size_t i = 0; i < c.problems.size(); ++i) s += c.located(i) + "\n";
  return s;
}

TEST(CaseReliability, CleanCaseChecksClean) {
  const CaseCheck c = check_case_text(two_plies(), "two.yaml");
  EXPECT_TRUE(c.ok()) << all(c);
}

// Before: "cannot read: invalid node" with no line and column, and nothing after it.
TEST(CaseReliability, MissingRequiredKeysAreNamedWithTheirPlaceAndCheckGoesOn) {
  const CaseCheck no_et = check_case_text(two_plies("E_T: 1, ", ""), "c.yaml");
  EXPECT_THAT(all(no_et), HasSubstr("c.yaml:3:"));
  EXPECT_THAT(all(no_et), HasSubstr("missing required key 'E_T'"));
  EXPECT_THAT(all(no_et), ::testing::Not(HasSubstr("invalid node")));

  // A ply without a name, and a later problem (a typo in output) still listed.
  const CaseCheck both = check_case_text(
      two_plies("  - name: b\n    size: [100, 20]\n", "  - size: [100, 20]\n").append("output: {evry: 2}\n"), "c.yaml");
  EXPECT_THAT(all(both), HasSubstr("missing required key 'name'"));
  EXPECT_THAT(all(both), HasSubstr("evry"));
  EXPECT_THAT(all(both), ::testing::Not(HasSubstr("invalid node")));

  // No materials section at all: named, and the plies' problems still listed.
  std::string no_materials = two_plies();
  no_materials.erase(0, no_materials.find("plies:"));
  const CaseCheck nm = check_case_text(no_materials + "solver2: 1\n", "c.yaml");
  EXPECT_THAT(all(nm), HasSubstr("missing required key 'materials'"));
  EXPECT_THAT(all(nm), HasSubstr("solver2"));
  EXPECT_THAT(all(nm), ::testing::Not(HasSubstr("invalid node")));
}

// Before: check passed, and run blamed convergence.
TEST(CaseReliability, LoadedPlyNothingHoldsIsRefused) {
  const CaseCheck c = check_case_text(two_plies("  - clamp: {ply: b, edge: x0}\n", ""), "c.yaml");
  ASSERT_FALSE(c.ok());
  EXPECT_THAT(all(c), HasSubstr("c.yaml:10:"));
  EXPECT_THAT(all(c), HasSubstr("ply 'b' is not held"));
  EXPECT_THAT(all(c), HasSubstr("all six rigid-body motions"));
  // Symmetry planes on one side only leave motions free; they are named.
  const CaseCheck s = check_case_text(
      two_plies("  - clamp: {ply: b, edge: x0}\n", "  - symmetry: {ply: b, plane: bottom}\n"), "c.yaml");
  EXPECT_THAT(all(s), HasSubstr("translation along x, translation along y, rotation about z"));
  // The uniaxial sample (three symmetry planes and a displaced edge) is held.
  const CaseCheck u = check_case_file(std::string(SF_SOURCE_DIR) + "/data/forming/uniaxial_0.yaml");
  EXPECT_TRUE(u.ok()) << all(u);
  // Dynamics: inertia holds a free ply.
  std::string dynamic_free = two_plies("  - clamp: {ply: b, edge: x0}\n", "");
  dynamic_free.insert(dynamic_free.find("    transversely"), "    density: 1.5e-9\n");
  dynamic_free.replace(dynamic_free.find("solver: {steps: 2}"), 18, "solver: {analysis: dynamic, steps: 2}");
  const CaseCheck d = check_case_text(dynamic_free, "c.yaml");
  EXPECT_THAT(all(d), ::testing::Not(HasSubstr("not held")));
}

TEST(CaseReliability, ImpossibleGeometryIsRefused) {
  EXPECT_THAT(all(check_case_text(two_plies("    thickness: 1\n    elements: [4, 2]\n    material: m\n  - name: b",
                                            "    thickness: 50\n    elements: [4, 2]\n    material: m\n  - name: b"),
                                  "c.yaml")),
              HasSubstr("thickness 50 mm exceeds its width 20 mm"));
  EXPECT_THAT(all(check_case_text(two_plies("origin: [0, 40, 0]", "origin: [0, 4e9, 0]"), "c.yaml")),
              HasSubstr("beyond +-1e6 mm"));
}

TEST(CaseReliability, AbsurdDurationsAreRefused) {
  const std::string dyn = two_plies("solver: {steps: 2}", "solver: {analysis: dynamic, end_time: 1e300, steps: 2}");
  const std::string with_density = std::string(dyn).insert(dyn.find("    transversely"), "    density: 1.5e-9\n");
  EXPECT_THAT(all(check_case_text(with_density, "c.yaml")), HasSubstr("end_time: 1e300 s is beyond"));
  const std::string tiny_step =
      two_plies("solver: {steps: 2}", "solver: {analysis: dynamic, end_time: 10, time_step: 1e-9, steps: 2}");
  EXPECT_THAT(
      all(check_case_text(std::string(tiny_step).insert(tiny_step.find("    transversely"), "    density: 1.5e-9\n"),
                          "c.yaml")),
      HasSubstr("time steps over end_time"));
}

TEST(CaseReliability, ModelBeyondTheMachinesMemoryIsRefusedWithTheFigures) {
  const std::string big = two_plies("elements: [4, 2]\n    material: m\n  - name: b",
                                    "elements: [1000, 1000]\n    material: m\n  - name: b");
  const CaseCheck c = check_case_text(big, "c.yaml");
  EXPECT_THAT(all(c), HasSubstr("too large for this machine"));
  EXPECT_THAT(all(c), HasSubstr("24048384 unknowns"));  // 24 (1001^2) + 24 (5 x 3)
  // The estimate grows with the model and is small for the samples.
  const ModelEstimate small = estimate_model(check_case_text(two_plies(), "c.yaml").spec);
  EXPECT_EQ(small.unknowns, 2 * 24 * 15);
  EXPECT_LT(small.total_bytes(), 50e6);
  EXPECT_GT(estimate_model(c.spec).total_bytes(), 100e9);
}

}  // namespace
}  // namespace sf::forming

// Double-diaphragm set-ups in case files (forming/case/diaphragm_reader.hpp) and the
// Mooney-Rivlin law in a case:
//  * `diaphragms:` becomes two isotropic plies around the laminate (the lower one's top
//    face at the laminate's bottom, the upper one's bottom face at its top), clamps (or
//    symmetry) on the frame edges, the forming pressure on one outer face and the vacuum
//    on both, and contact pairs laminate/diaphragm, upper/lower diaphragm and
//    diaphragm/tool;
//  * bad diaphragm input is reported with its line and column (unknown key, unknown
//    laminate, tool or material, an anisotropic diaphragm, a frame that does not hold the
//    laminate, a bad symmetry edge or face, a vacuum without its pressure);
//  * a coarse plane-strain double-diaphragm bend runs: the pack sinks into the die slot
//    under the forming pressure, the diaphragms stay clamped at the frame and the plies
//    do not pass through one another or through the diaphragms;
//  * the process file diaphragm_bend_without_friction.yaml (molten plies nearly free to
//    slide, Coulomb grip of the diaphragms), meshed at half its elements, takes its
//    first two steps: the vacuum pulls the upper diaphragm down onto the lower one
//    outside the laminate. With the grip's stick velocity at 0.1 mm/s Newton cycled
//    between stick and slip (2.5e-4 mm of elastic slip a step) and step 1 did not
//    converge; the file's 5 mm/s takes them in about 100 iterations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>

#include "common/io/csv.hpp"
#include "common/io/vtk_xml.hpp"
#include "forming/run/run.hpp"
#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

// Largest penetration accepted in the run below, mm: the penalty's own p / S_n with
// p up to ~0.5 MPa and S_n = 50 N/mm^3 is 0.01 mm; twice that.
constexpr double kPenetrationTol = 0.02;

// The coarse plane-strain double-diaphragm bend (tests/forming/fixtures.hpp).
const char* const kBend = fixtures::kDiaphragmBend;

TEST(DiaphragmCase, BuildsTwoSheetsTheirFrameLoadsAndContacts) {
  const CaseCheck c = check_case_text(kBend, "bend.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  ASSERT_EQ(c.spec.plies.size(), 4u);
  const CasePly& lower = c.spec.plies[2];
  const CasePly& upper = c.spec.plies[3];
  EXPECT_EQ(lower.name, "dd.lower");
  EXPECT_EQ(upper.name, "dd.upper");
  EXPECT_DOUBLE_EQ(lower.origin.z(), 0.0);  // top face at the laminate's bottom (z = 1)
  EXPECT_DOUBLE_EQ(upper.origin.z(), 2.0);  // bottom face at the laminate's top
  EXPECT_DOUBLE_EQ(lower.length_x, 30.0);
  EXPECT_TRUE(lower.plane_strain);
  EXPECT_EQ(c.spec.materials[1].kind, CaseMaterial::Kind::kMooneyRivlin);
  // Frame: x0 on the symmetry plane, x1 clamped (plane strain: no y edges), both sheets.
  int clamps = 0, symmetries = 0;
  for (const CaseBoundary& b : c.spec.boundaries) {
    if (b.ply_index < 2) continue;
    (b.kind == CaseBoundary::Kind::kClamp ? clamps : symmetries) += 1;
    EXPECT_EQ(b.side, b.kind == CaseBoundary::Kind::kClamp ? PlySide::kX1 : PlySide::kX0);
  }
  EXPECT_EQ(clamps, 2);
  EXPECT_EQ(symmetries, 2);
  // Loads: forming pressure on the upper top, vacuum on both outer faces.
  ASSERT_EQ(c.spec.loads.size(), 3u);
  EXPECT_EQ(c.spec.loads[0].ply, "dd.upper");
  EXPECT_TRUE(c.spec.loads[0].top);
  EXPECT_DOUBLE_EQ(c.spec.loads[0].value, 0.02);
  EXPECT_EQ(c.spec.loads[1].ramp, Ramp::kLinear);
  EXPECT_EQ(c.spec.loads[2].ply, "dd.lower");
  EXPECT_FALSE(c.spec.loads[2].top);
  // Contacts: the laminate's interface, lam.1/lower, lam.2/upper, upper/lower, lower/die.
  ASSERT_EQ(c.spec.contacts.size(), 5u);
  EXPECT_EQ(c.spec.contacts[1].label, "lam.1/dd.lower");
  EXPECT_EQ(c.spec.contacts[2].label, "lam.2/dd.upper");
  EXPECT_EQ(c.spec.contacts[3].label, "dd.upper/dd.lower");
  EXPECT_EQ(c.spec.contacts[4].label, "dd.lower/die");
  EXPECT_DOUBLE_EQ(c.spec.contacts[1].law.friction.viscous, 0.05);
  const Problem problem = build_problem(c.spec);
  EXPECT_EQ(problem.model.n_bodies(), 4);
  EXPECT_EQ(problem.model.n_interactions(), 5);
}

// The one problem of kBend with `from` replaced by `to`.
CaseProblem only_problem(const std::string& from, const std::string& to) {
  std::string text = kBend;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  const CaseCheck c = check_case_text(text, "bad.yaml");
  EXPECT_EQ(c.problems.size(), 1u) << (c.problems.empty() ? "no problem" : c.located(0) + " ...");
  return c.problems.empty() ? CaseProblem{} : c.problems[0];
}

TEST(DiaphragmCase, BadInputIsReportedWithItsPlace) {
  struct Bad {
    const char* from;
    const char* to;
    int line;
    const char* words;
  };
  const Bad bad[] = {
      {"  symmetry: [x0]\n", "  symetry: [x0]\n", 26, "symetry"},
      {"  laminate: lam\n", "  laminate: lum\n", 21, "unknown laminate 'lum'"},
      {"material: rubber", "material: ply_law2", 25, "unknown material 'ply_law2'"},
      {"{tool: die, stiffness", "{tool: dye, stiffness", 30, "unknown tool 'dye'"},
      {"size: [30, 5]}", "size: [15, 5]}", 22, "inside the frame"},
      {"symmetry: [x0]", "symmetry: [z0]", 26, "expected x0, x1, y0 or y1"},
      {"face: top, ramp", "face: side, ramp", 27, "expected top"},
      {"vacuum: {pressure: 0.02, ramp: linear}", "vacuum: 0.02", 28, "vacuum"},
      {"contact: {stiffness: 50, viscous", "contact: {stiffness: -5, viscous", 29, "stiffness"},
      {"rubber: {mooney_rivlin: {c10: 0.3, c01: 0.05, nu: 0.45}}",
       "rubber: {mooney_rivlin: {c10: 0.3, c01: -1, nu: 0.45}}", 4, "c01"},
      {"rubber: {mooney_rivlin: {c10: 0.3, c01: 0.05, nu: 0.45}}", "rubber: {mooney_rivlin: {c10: 0.3, c01: 0.05}}", 4,
       "either nu or kappa"},
  };
  for (const Bad& b : bad) {
    const CaseProblem p = only_problem(b.from, b.to);
    EXPECT_EQ(p.place.line, b.line) << b.to << ": " << p.message;
    EXPECT_GT(p.place.column, 0) << b.to;
    EXPECT_NE(p.message.find(b.words), std::string::npos) << b.to << ": " << p.message;
  }
  // An anisotropic diaphragm.
  std::string text = kBend;
  text.replace(text.find("material: rubber"), 16, "material: fibre");
  text.replace(text.find("  rubber:"), 9,
               "  fibre: {transversely_isotropic: {E_f: 100, E_T: 1, G_L: 0.5, G_T: 0.4}}\n  rubber:");
  const CaseCheck c = check_case_text(text, "aniso.yaml");
  ASSERT_EQ(c.problems.size(), 1u) << c.located(0);
  EXPECT_NE(c.problems[0].message.find("isotropic"), std::string::npos) << c.problems[0].message;
}

// A forming pressure (and a vacuum) given as a time table (t s, p MPa): read, checked
// with its place, and followed by the assembled load: the upper diaphragm's top face
// (30 x 5 mm, flat at the reference) carries p(t) x 150 mm^2 at t = lambda x process_time.
TEST(DiaphragmCase, PressureTimeTableIsCheckedAndFollowedLinearlyBetweenItsPoints) {
  std::string text = kBend;
  const std::string from = "pressure: {value: 0.02, face: top, ramp: linear}";
  text.replace(text.find(from), from.size(), "pressure: {table: [[0, 0], [0.025, 0.01], [0.05, 0.03]], face: top}");
  const CaseCheck c = check_case_text(text, "table.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  ASSERT_EQ(c.spec.loads[0].table.size(), 3u);
  EXPECT_DOUBLE_EQ(c.spec.loads[0].value, 0.03);  // the largest, for the summary
  Model model = build_model(c.spec);
  const RampedLoads loads = build_loads(c.spec, model);
  ASSERT_EQ(loads.tabled.size(), 1u);
  const VecX X = model.reference_positions();
  // process_time 0.1 s: lambda 0.125 -> t = 0.0125 s (p = 0.005), 0.375 -> 0.0375 s
  // (0.02), 0.8 -> beyond the table (0.03 held). The vacuum (0.02 MPa, linear) acts on
  // both outer faces and cancels in the total; the forming pressure pushes down.
  for (const auto& [lambda, p] : {std::pair{0.125, 0.005}, {0.375, 0.02}, {0.8, 0.03}, {0.0, 0.0}}) {
    const ExternalLoad f = loads.at(model, lambda, X, false);
    double fz = 0.0;
    for (Index k = 2; k < f.force.size(); k += 3) fz += f.force(k);
    EXPECT_NEAR(fz, -p * 30.0 * 5.0, 1e-9) << "lambda " << lambda;
  }
  // Bad tables, each reported at its place.
  struct Bad {
    const char* to;
    int line;
    const char* words;
  };
  const Bad bad[] = {
      {"pressure: {table: [[0, 0], [0.05, 0.01], [0.02, 0.03]], face: top}", 27, "increasing order"},
      {"pressure: {table: [[0.01, 0], [0.05, 0.01]], face: top}", 27, "start at t = 0"},
      {"pressure: {table: [[0, 0], [0.05, -0.01]], face: top}", 27, "pressure >= 0"},
      {"pressure: {table: [[0, 0]], face: top}", 27, "at least two"},
      {"pressure: {table: [[0, 0], [0.05]], face: top}", 27, "[t, p]"},
      {"pressure: {value: 0.02, table: [[0, 0], [0.05, 0.01]], face: top}", 27, "not both"},
  };
  for (const Bad& b : bad) {
    const CaseProblem p = only_problem(from, b.to);
    EXPECT_EQ(p.place.line, b.line) << b.to << ": " << p.message;
    EXPECT_GT(p.place.column, 0) << b.to;
    EXPECT_NE(p.message.find(b.words), std::string::npos) << b.to << ": " << p.message;
  }
  // The vacuum as a table too.
  std::string v = kBend;
  const std::string vac = "vacuum: {pressure: 0.02, ramp: linear}";
  v.replace(v.find(vac), vac.size(), "vacuum: {table: [[0, 0], [0.01, 0.09]]}");
  const CaseCheck cv = check_case_text(v, "vacuum.yaml");
  ASSERT_TRUE(cv.ok()) << cv.located(0);
  EXPECT_EQ(cv.spec.loads[1].table.size(), 2u);
  EXPECT_EQ(cv.spec.loads[2].table.size(), 2u);
  // Arc length cannot scale a table.
  std::string arc = text;
  arc.replace(arc.find("solver: {steps: 3,"), 18, "solver: {control: arc_length, arc_length: 1, steps: 3,");
  const CaseCheck ca = check_case_text(arc, "arc.yaml");
  bool said = false;
  for (const CaseProblem& p : ca.problems) said = said || p.message.find("no time table") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(DiaphragmCase, CoarseBendSinksIntoTheDieWithoutPenetration) {
  const CaseCheck c = check_case_text(kBend, "bend.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_diaphragm_case_test";
  const fixtures::RunOutput out = fixtures::run_into(c.spec, dir);
  ASSERT_TRUE(out.report.ok()) << out.report.message;
  // The pack sinks into the slot (x < 10): the largest displacement is downwards.
  EXPECT_LT(out.report.max_displacement.z(), -0.5);
  // Ply frame of the last step: every point of the laminate plies above the lower
  // diaphragm's points at about the same x (no ply went through the sheet below it).
  const io::VolumeMesh contact = io::read_vtu((dir / "steps/contact_0003.vtu").string());
  const io::FieldArray* gap = nullptr;
  for (const io::FieldArray& f : contact.point_data)
    if (f.name == "gap") gap = &f;
  ASSERT_NE(gap, nullptr);
  double min_gap = 1e30;
  for (double g : gap->values)
    if (std::isfinite(g)) min_gap = std::min(min_gap, g);
  std::printf("[ measured ] largest penetration of the coarse diaphragm bend: %.3e mm\n", -min_gap);
  EXPECT_GT(min_gap, -kPenetrationTol);
  std::filesystem::remove_all(dir);
}

// The process case of the double-diaphragm bend without inter-ply friction, at half its
// elements (10 laminate and 15 diaphragm bricks), its first two load steps. Cut-backs
// are limited to 1/16 of a step so that a grip that makes Newton cycle fails here in
// seconds instead of grinding through sub-steps of 1e-4.
TEST(DiaphragmCase, ProcessBendWithCoulombGripTakesItsFirstSteps) {
  std::string text =
      fixtures::read_text(std::filesystem::path(SF_SOURCE_DIR) / "data/forming/processes/diaphragm_bend_without_friction.yaml");
  ASSERT_FALSE(text.empty());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("    elements: [20, 1]", "    elements: [10, 1]");
  replace("  elements: [30, 1]", "  elements: [15, 1]");
  replace("solver: {", "solver: {min_increment: 0.0625, ");
  const CaseCheck c = check_case_text(text, "diaphragm_bend_without_friction.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_diaphragm_process_bend_test";
  std::filesystem::remove_all(dir);
  RunOptions o;
  o.out_dir = dir.string();
  o.quiet = true;
  o.stop_after = 2;
  const RunReport r = run_case(c.spec, o);
  std::printf("[ measured ] coarse process bend, 2 steps: %d Newton iterations, max |u| %.3f mm\n",
              r.total_iterations, r.max_displacement.norm());
  ASSERT_EQ(r.status, RunReport::Status::kStopped) << r.message;
  EXPECT_EQ(r.steps_converged, 2);
  // 94 measured (103 without the predictor: extrapolate of the file); a ceiling with a
  // margin.
  EXPECT_LE(r.total_iterations, 160);
  // The upper diaphragm (bottom face at z = 3 outside the laminate) came down about the
  // laminate's 2 mm onto the lower one, which rests on the die.
  EXPECT_NEAR(r.max_displacement.z(), -2.0, 0.1);
  std::filesystem::remove_all(dir);
}

// The same file at half its elements, its first eight steps (to t = 0.02 s), with the
// viscous stabilisation the file adds to pass its critical points (at its own mesh an
// eigenvalue passes zero at t = 0.0146 s and the unstabilised run stops in step 6): the
// damping must stay small beside what the pressure does. The vacuum's first step pulls
// the upper diaphragm 2 mm down onto the lower one while storing little strain energy
// (the damping takes 40 % of it there), so the measure is the energy the damping took
// over steps 5-8 against the strain energy stored over them (measured 2.2 %), and its
// running ratio at step 8 (4.4 %), below the run's warning ratio of 5 %.
TEST(DiaphragmCase, ProcessBendWithoutFrictionIsStabilisedLightly) {
  std::string text =
      fixtures::read_text(std::filesystem::path(SF_SOURCE_DIR) / "data/forming/processes/diaphragm_bend_without_friction.yaml");
  ASSERT_FALSE(text.empty());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("    elements: [20, 1]", "    elements: [10, 1]");
  replace("  elements: [30, 1]", "  elements: [15, 1]");
  const CaseCheck c = check_case_text(text, "diaphragm_bend_without_friction.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_diaphragm_stabilised_bend_test";
  std::filesystem::remove_all(dir);
  RunOptions o;
  o.out_dir = dir.string();
  o.quiet = true;
  o.stop_after = 8;
  const RunReport r = run_case(c.spec, o);
  ASSERT_EQ(r.status, RunReport::Status::kStopped) << r.message;
  EXPECT_EQ(r.steps_converged, 8);
  const io::CsvTable h = io::read_csv((dir / "history.csv").string());
  ASSERT_TRUE(h.has_column("stabilisation_energy")) << "the file is not stabilised";
  const auto at = [&](std::size_t step, const std::string& column) { return h.number(step, h.column_index(column)); };
  ASSERT_EQ(h.n_rows(), 9u);  // the start and 8 steps
  const double dissipated = at(8, "stabilisation_energy") - at(4, "stabilisation_energy");
  const double stored = at(8, "strain_energy") - at(4, "strain_energy");
  std::printf("[ measured ] stabilised process bend, steps 5-8: damping took %.4g N mm, strain energy +%.4g N mm "
              "(%.2f %%); ratio at step 8 %.2f %%; %d Newton iterations\n",
              dissipated, stored, 100.0 * dissipated / stored, 100.0 * at(8, "stabilisation_ratio"),
              r.total_iterations);
  EXPECT_GT(dissipated, 0.0);
  EXPECT_LT(dissipated, 0.04 * stored);
  EXPECT_LT(at(8, "stabilisation_ratio"), 0.05);
  // 146 measured; a ceiling with a margin.
  EXPECT_LE(r.total_iterations, 220);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sf::forming

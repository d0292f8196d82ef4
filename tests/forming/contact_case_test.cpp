// Laminates, tools and contact in case files (forming/case/contact_reader.hpp):
//  * the layup grammar: [0,90]s, [0_4], [+45,-45]s, [0/90]2s, and where it fails;
//  * a laminate becomes plies "<name>.<k>" stacked through the thickness with contact
//    between neighbours, each with its angle; an explicit list works the same;
//  * bad contact input is reported with its line and column: an unparsable layup (the
//    column of the offending character), an unknown tool shape key, a contact naming a
//    tool or ply that does not exist, S_n <= 0, Coulomb without a stick velocity, an
//    STL that is missing or malformed (with the STL's own place);
//  * a built laminate case holds one body per ply and one interaction per contact;
//  * outputs: history.csv has the tool's displacement and reaction per step (the
//    punch's force balances the table's when nothing else holds the ply), result.pvd
//    the tool and the contact points as parts of every written step.
#include <gtest/gtest.h>

#include <cmath>

#include <filesystem>
#include <fstream>
#include <string>

#include "forming/case/build.hpp"
#include "forming/case/contact_reader.hpp"
#include "forming/case/reader.hpp"
#include "common/io/vtk_xml.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

std::vector<double> layup(const std::string& s) {
  std::string error;
  std::size_t offset = 0;
  const auto a = parse_layup(s, error, offset);
  EXPECT_TRUE(a.has_value()) << s << ": " << error;
  return a ? *a : std::vector<double>{};
}

TEST(Layup, ParsesTheUsualNotations) {
  EXPECT_EQ(layup("[0,90]s"), (std::vector<double>{0, 90, 90, 0}));
  EXPECT_EQ(layup("[0_4]"), (std::vector<double>{0, 0, 0, 0}));
  EXPECT_EQ(layup("[+45,-45]s"), (std::vector<double>{45, -45, -45, 45}));
  EXPECT_EQ(layup("[0/90]2s"), (std::vector<double>{0, 90, 0, 90, 90, 0, 90, 0}));
  EXPECT_EQ(layup(" [ 30 , -60.5 ] "), (std::vector<double>{30, -60.5}));
}

TEST(Layup, ReportsWhereItFails) {
  for (const auto& [text, at] : std::vector<std::pair<std::string, std::size_t>>{
           {"0,90]", 0}, {"[0,,90]", 3}, {"[0,90", 5}, {"[0_x]", 3}, {"[0,90]t", 6}, {"[0;90]", 2}}) {
    std::string error;
    std::size_t offset = 99;
    EXPECT_FALSE(parse_layup(text, error, offset).has_value()) << text;
    EXPECT_EQ(offset, at) << text << ": " << error;
    EXPECT_FALSE(error.empty());
  }
}

const char* kGood = R"(materials:
  m: {neo_hookean: {E: 10, nu: 0.3}}
laminates:
  - name: lam
    size: [10, 5]
    elements: [2, 1]
    layup: "[0,90]s"
    ply_thickness: 0.5
    material: m
    interface: {stiffness: 100, viscous: 0.02}
tools:
  - name: punch
    sphere: {centre: [5, 2.5, 12], radius: 10}
    motion: {displacement: [0, 0, -1], ramp: smooth}
contact:
  - {ply: lam.4, face: top, tool: punch, stiffness: 100, coulomb: 0.2, stick_velocity: 0.01}
boundary_conditions:
  - clamp: {ply: lam.1, edge: x0}
)";

TEST(LaminateCase, BuildsStackedPliesWithContactBetweenNeighbours) {
  const CaseCheck c = check_case_text(kGood, "good.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  ASSERT_EQ(c.spec.plies.size(), 4u);
  const double angles[] = {0, 90, 90, 0};
  for (int k = 0; k < 4; ++k) {
    const CasePly& p = c.spec.plies[static_cast<std::size_t>(k)];
    EXPECT_EQ(p.name, "lam." + std::to_string(k + 1));
    EXPECT_DOUBLE_EQ(p.origin.z(), 0.5 * k);
    EXPECT_DOUBLE_EQ(p.angle_deg, angles[k]);
  }
  ASSERT_EQ(c.spec.contacts.size(), 4u);  // three interfaces and the punch
  EXPECT_EQ(c.spec.contacts[0].label, "lam.1/lam.2");
  EXPECT_EQ(c.spec.contacts[3].label, "lam.4/punch");
  EXPECT_DOUBLE_EQ(c.spec.contacts[1].law.friction.viscous, 0.02);
  const Problem problem = build_problem(c.spec);
  EXPECT_EQ(problem.model.n_bodies(), 4);
  EXPECT_EQ(problem.model.n_interactions(), 4);
  // The reference state: the plies touch (gap 0) and the punch is 1.5 mm above.
  const VecX X = problem.model.reference_positions();
  EXPECT_NEAR(c.spec.tools[0].tool.at(Vec3(5, 2.5, 2.0), 0.0).gap, 0.0, 1e-12);
  EXPECT_NEAR(c.spec.tools[0].tool.at(Vec3(5, 2.5, 1.0), c.spec.solver.process_time).gap, 0.0, 1e-12);
}

TEST(LaminateCase, ExplicitListOfPlies) {
  std::string text = kGood;
  text.replace(text.find("layup: \"[0,90]s\""), std::string("layup: \"[0,90]s\"").size(),
               "layup: [{angle: 45, thickness: 0.2}, {angle: -45}]");
  const CaseCheck c = check_case_text(text, "list.yaml");
  // lam.4 no longer exists: the contact with the punch names a ply that is not there.
  ASSERT_EQ(c.problems.size(), 1u) << c.located(0);
  EXPECT_EQ(c.problems[0].kind, ProblemKind::kUnknownPly);
  EXPECT_EQ(c.problems[0].place.line, 16);
  ASSERT_EQ(c.spec.plies.size(), 2u);
  EXPECT_DOUBLE_EQ(c.spec.plies[0].thickness, 0.2);
  EXPECT_DOUBLE_EQ(c.spec.plies[1].thickness, 0.5);
  EXPECT_DOUBLE_EQ(c.spec.plies[1].origin.z(), 0.2);
  EXPECT_DOUBLE_EQ(c.spec.plies[1].angle_deg, -45);
}

// The one problem of `text` (kGood with `from` replaced by `to`), its line and column.
CaseProblem only_problem(const std::string& from, const std::string& to) {
  std::string text = kGood;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  const CaseCheck c = check_case_text(text, "bad.yaml");
  EXPECT_EQ(c.problems.size(), 1u) << (c.problems.empty() ? "no problem" : c.located(0) + " ...");
  return c.problems.empty() ? CaseProblem{} : c.problems[0];
}

TEST(LaminateCase, BadContactInputIsReportedWithItsPlace) {
  CaseProblem p = only_problem("\"[0,90]s\"", "\"[0,9x0]s\"");
  EXPECT_EQ(p.place.line, 7);
  EXPECT_EQ(p.place.column, 12 + 1 + 4);  // the value's column, the quote, then "[0,9"
  EXPECT_NE(p.message.find("layup"), std::string::npos) << p.message;

  {  // a misspelt shape: the unknown key where it is, and the tool without a shape
    std::string text = kGood;
    text.replace(text.find("sphere:"), 7, "sphear:");
    const CaseCheck c = check_case_text(text, "bad.yaml");
    ASSERT_EQ(c.problems.size(), 2u);
    EXPECT_EQ(c.problems[0].kind, ProblemKind::kMissing);
    EXPECT_EQ(c.problems[0].place.line, 12);
    EXPECT_EQ(c.problems[1].kind, ProblemKind::kUnknownKey);
    EXPECT_EQ(c.problems[1].place.line, 13);
    EXPECT_EQ(c.problems[1].place.column, 5);
  }

  p = only_problem("tool: punch, stiffness", "tool: pnuch, stiffness");
  EXPECT_EQ(p.kind, ProblemKind::kUnknownTool);
  EXPECT_EQ(p.place.line, 16);

  p = only_problem("{ply: lam.4, face: top", "{ply: lam.5, face: top");
  EXPECT_EQ(p.kind, ProblemKind::kUnknownPly);

  p = only_problem("interface: {stiffness: 100", "interface: {stiffness: -1");
  EXPECT_EQ(p.kind, ProblemKind::kOutOfRange);
  EXPECT_EQ(p.place.line, 10);
  EXPECT_NE(p.message.find("stiffness"), std::string::npos);

  p = only_problem(", stick_velocity: 0.01", "");
  EXPECT_EQ(p.kind, ProblemKind::kMissing);
  EXPECT_NE(p.message.find("stick_velocity"), std::string::npos);

  p = only_problem("radius: 10}", "radius: 0}");
  EXPECT_EQ(p.kind, ProblemKind::kOutOfRange);
  EXPECT_EQ(p.place.line, 13);

  // The normal law's tail and the slip-distance Coulomb form (contact_law.hpp).
  p = only_problem("interface: {stiffness: 100", "interface: {tail: -0.1, stiffness: 100");
  EXPECT_EQ(p.kind, ProblemKind::kOutOfRange);
  EXPECT_NE(p.message.find("tail"), std::string::npos) << p.message;
  p = only_problem("interface: {stiffness: 100", "interface: {tail: 0.1, tolerance: 0.001, stiffness: 100");
  EXPECT_EQ(p.kind, ProblemKind::kUnsupported);
  p = only_problem(", stick_velocity: 0.01", ", stick_velocity: 0.01, stick_slip: 0.001");
  EXPECT_EQ(p.kind, ProblemKind::kConflict);
  EXPECT_NE(p.message.find("stick_slip"), std::string::npos) << p.message;
  const CaseCheck ok = check_case_text(
      std::string(kGood).replace(std::string(kGood).find(", stick_velocity: 0.01"), 22, ", stick_slip: 0.001"),
      "slip.yaml");
  ASSERT_TRUE(ok.ok()) << ok.located(0);
}

TEST(LaminateCase, StlToolsMissingOrMalformed) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_contact_case_test";
  std::filesystem::create_directories(dir);
  {
    std::ofstream bad(dir / "bad.stl");
    bad << "solid t\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertx 1 0 0\n";
  }
  const std::string case_path = (dir / "case.yaml").string();
  std::string text = kGood;
  text.replace(text.find("sphere: {centre: [5, 2.5, 12], radius: 10}"),
               std::string("sphere: {centre: [5, 2.5, 12], radius: 10}").size(), "mesh: {file: bad.stl}");
  CaseCheck c = check_case_text(text, case_path);
  ASSERT_EQ(c.problems.size(), 1u);
  EXPECT_EQ(c.problems[0].place.line, 13);
  EXPECT_NE(c.problems[0].message.find("bad.stl:5:7"), std::string::npos) << c.problems[0].message;
  text.replace(text.find("bad.stl"), 7, "none.stl");
  c = check_case_text(text, case_path);
  ASSERT_EQ(c.problems.size(), 1u);
  EXPECT_NE(c.problems[0].message.find("none.stl"), std::string::npos) << c.problems[0].message;
  std::filesystem::remove_all(dir);
}

TEST(LaminateCase, ContactSamplesCheckClean) {
  const std::filesystem::path dir = std::filesystem::path(SF_SOURCE_DIR) / "data/forming/contact";
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    const CaseCheck c = check_case_file(entry.path().string());
    EXPECT_TRUE(c.ok()) << (c.ok() ? "" : c.located(0));
    EXPECT_FALSE(c.spec.contacts.empty()) << entry.path();
    ++n;
  }
  EXPECT_GE(n, 1);
}

TEST(ContactOutputs, ToolColumnsAndPartsOfEveryStep) {
  const CaseCheck c = check_case_text(R"(materials:
  soft: {neo_hookean: {E: 10, nu: 0.3}}
plies:
  - {name: p, size: [10, 10], thickness: 1, elements: [2, 2], material: soft}
tools:
  - name: table
    plane: {point: [0, 0, 0], normal: [0, 0, 1]}
  - name: punch
    plane: {point: [0, 0, 1], normal: [0, 0, -1]}
    motion: {displacement: [0, 0, -0.01]}
contact:
  - {ply: p, face: bottom, tool: table, stiffness: 100}
  - {ply: p, face: top, tool: punch, stiffness: 100}
boundary_conditions:
  - symmetry: {ply: p, plane: x0}
  - symmetry: {ply: p, plane: y0}
solver: {steps: 2}
)",
                                      "outputs.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_contact_outputs_test";
  const fixtures::RunOutput out = fixtures::run_into(c.spec, dir);
  ASSERT_TRUE(out.report.ok()) << out.report.message;
  const io::CsvTable& h = out.history;
  ASSERT_EQ(h.n_rows(), 3u);
  const auto cell = [&](std::size_t row, const char* name) {
    return std::stod(std::string(h.cell(row, h.column_index(name))));
  };
  EXPECT_DOUBLE_EQ(cell(2, "time"), 1.0);
  EXPECT_DOUBLE_EQ(cell(2, "punch_uz"), -0.01);
  EXPECT_DOUBLE_EQ(cell(1, "punch_uz"), -0.005);
  // Squeezed between two planes: the punch is pushed up, the table down, equally.
  const double up = cell(2, "punch_fz"), down = cell(2, "table_fz");
  EXPECT_GT(up, 0.1);
  EXPECT_NEAR(up, -down, 1e-6 * up);
  EXPECT_EQ(out.summary.at("analysis"), "quasi-static (contact with tools)");
  const std::string pvd = fixtures::read_text(dir / "result.pvd");
  for (const char* part : {"steps/tool_table_0002.vtu", "steps/tool_punch_0002.vtu", "steps/contact_0002.vtu"}) {
    EXPECT_NE(pvd.find(part), std::string::npos) << part;
    EXPECT_TRUE(std::filesystem::exists(dir / part)) << part;
  }
  const io::VolumeMesh points = io::read_vtu((dir / "steps/contact_0002.vtu").string());
  EXPECT_EQ(points.points.rows(), 2 * 4 * 36);
  bool has_pressure = false;
  for (const io::FieldArray& f : points.point_data) has_pressure = has_pressure || f.name == "pressure";
  EXPECT_TRUE(has_pressure);
  // The ply frame carries the contact fields on its faces: squeezed homogeneously between
  // frictionless planes, every face point has the pressure punch_fz / A (A = 100 mm^2,
  // reference area) and one negative gap (the faces slip outwards as the ply spreads).
  const io::VolumeMesh ply = io::read_vtu((dir / "steps/step_0002.vtu").string());
  const auto field = [&](const char* name) -> const io::FieldArray* {
    for (const io::FieldArray& f : ply.point_data)
      if (f.name == name) return &f;
    return nullptr;
  };
  const io::FieldArray *pressure = field("contact_pressure"), *gap = field("contact_gap"),
                       *slip = field("contact_slip"), *rate = field("contact_slip_rate");
  ASSERT_TRUE(pressure && gap && slip && rate);
  EXPECT_EQ(slip->n_components, 3);
  EXPECT_EQ(rate->n_components, 3);
  const double p = up / 100.0;
  int on_faces = 0, inside = 0;
  double gap0 = 0.0;
  for (Index i = 0; i < ply.points.rows(); ++i) {
    const double z = ply.points(i, 2);
    const auto k = static_cast<std::size_t>(i);
    if (z > 0.2 && z < 0.8) {  // between the faces: no contact fields
      EXPECT_EQ(pressure->values[k], 0.0);
      EXPECT_TRUE(std::isnan(gap->values[k]));
      ++inside;
      continue;
    }
    EXPECT_NEAR(pressure->values[k], p, 1e-8 * p) << "point " << i;
    if (on_faces == 0) gap0 = gap->values[k];
    EXPECT_LT(gap->values[k], 0.0);
    EXPECT_NEAR(gap->values[k], gap0, 1e-6 * std::abs(gap0)) << "point " << i;
    EXPECT_NEAR(slip->values[3 * k + 2], 0.0, 1e-9);  // tangential
    ++on_faces;
  }
  EXPECT_GT(on_faces, 0);
  EXPECT_GT(inside, 0);
  std::filesystem::remove_all(dir);
}

TEST(ContactOutputs, PlyFramesCarryTheAccumulatedSlipAndItsRate) {
  // A stiff block, clamped at x0, on a table sliding along +x at 2 mm/s for 0.3 s with
  // viscous friction: its bottom face slips -0.6 mm (relative to the table) at -2 mm/s.
  const CaseCheck c = check_case_text(R"(materials:
  block: {neo_hookean: {E: 10000, nu: 0.3}}
plies:
  - {name: b, size: [10, 10], thickness: 1, elements: [2, 2], material: block}
tools:
  - name: table
    plane: {point: [0, 0, 0], normal: [0, 0, 1]}
    motion: {velocity: [2, 0, 0]}
contact:
  - {ply: b, face: bottom, tool: table, stiffness: 1000, viscous: 0.02}
boundary_conditions:
  - clamp: {ply: b, edge: x0}
loads:
  - pressure: {ply: b, face: top, value: 0.2}
solver: {steps: 3, process_time: 0.3}
output: {samples: [2, 2]}
)",
                                      "slip.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_contact_slip_test";
  const fixtures::RunOutput out = fixtures::run_into(c.spec, dir);
  ASSERT_TRUE(out.report.ok()) << out.report.message;
  const io::VolumeMesh ply = io::read_vtu((dir / "steps/step_0003.vtu").string());
  const io::FieldArray *slip = nullptr, *rate = nullptr, *pressure = nullptr;
  for (const io::FieldArray& f : ply.point_data) {
    if (f.name == "contact_slip") slip = &f;
    if (f.name == "contact_slip_rate") rate = &f;
    if (f.name == "contact_pressure") pressure = &f;
  }
  ASSERT_TRUE(slip && rate && pressure);
  int bottom = 0;
  for (Index i = 0; i < ply.points.rows(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (ply.points(i, 2) > 0.05) {
      EXPECT_EQ(slip->values[3 * k], 0.0);
      continue;
    }
    EXPECT_NEAR(slip->values[3 * k], -0.6, 1e-3) << "point " << i;
    EXPECT_NEAR(rate->values[3 * k], -2.0, 3e-3) << "point " << i;
    EXPECT_NEAR(slip->values[3 * k + 2], 0.0, 1e-6);
    EXPECT_GT(pressure->values[k], 0.0);
    ++bottom;
  }
  EXPECT_GT(bottom, 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sf::forming

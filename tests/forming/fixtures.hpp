#pragma once
// Small builders shared by the forming tests (tests/forming/, tests/verification/):
// plies on rectangles, one-ply models, the ply laws' parameter sets, single distorted
// bricks, affine fields, held dofs, and `simform run` into a test folder. Each used to
// be copied into several test files; they build inputs, they assert nothing.
#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/case/schema.hpp"
#include "forming/element/element.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/model.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/run/run.hpp"

namespace sf::forming::fixtures {

// Largest absolute entry.
template <class Derived>
double max_abs(const Eigen::MatrixBase<Derived>& m) {
  return m.cwiseAbs().maxCoeff();
}

// ---- Plies and models ---------------------------------------------------------------

// A flat ply of n1 x n2 bricks on the rectangle [0, lx] x [0, ly] in the x-y plane
// (bottom face z = 0 for kBottom, mid-surface for kMiddle), thickness h, layup angle in
// degrees; optional graded breakpoints along x and y (mm).
inline PlyMesh rectangle_ply(double lx, double ly, double h, int n1, int n2, double angle_deg = 0.0,
                             PlyPlacement placement = PlyPlacement::kBottom, const std::vector<double>& breaks1 = {},
                             const std::vector<double>& breaks2 = {}) {
  return PlyMesh(
      mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), lx, ly, n1, n2, breaks1, breaks2), h,
      angle_deg, placement);
}

// A model of one ply with one material.
inline Model one_ply_model(PlyMesh ply, std::shared_ptr<const Material> material) {
  Model model;
  model.add_ply(std::move(ply), std::move(material));
  return model;
}

inline std::shared_ptr<const Material> neo_hookean(double mu, double lambda) {
  return std::make_shared<NeoHookean>(NeoHookeanParams{mu, lambda});
}

// Transversely isotropic constants (MPa): the incompressible law (the element adds p),
// and the compressible one with the matrix's Lame constant lambda.
inline TransverselyIsotropicParams ti_incompressible(double mu_t, double mu_l, double kappa_f) {
  TransverselyIsotropicParams p;
  p.mu_T = mu_t;
  p.mu_L = mu_l;
  p.kappa_f = kappa_f;
  p.incompressible = true;
  return p;
}
inline TransverselyIsotropicParams ti_compressible(double mu_t, double mu_l, double kappa_f, double lambda) {
  TransverselyIsotropicParams p = ti_incompressible(mu_t, mu_l, kappa_f);
  p.incompressible = false;
  p.lambda = lambda;
  return p;
}

// ---- Single bricks ------------------------------------------------------------------

// The one brick of an l1 x l2 x h ply (mm), its reference parameters perturbed by
// `distortion` (absolute, uniform in [-1, 1] per entry) so the reference is curved and
// skewed.
inline BrickParams distorted_brick(std::mt19937& rng, double distortion, double l1 = 2.0, double l2 = 1.5,
                                   double h = 0.4) {
  const PlyMesh ply = rectangle_ply(l1, l2, h, 1, 1);
  BrickParams X = ply.element_parameters(0, ply.reference());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < kBrickFunctions; ++k)
    for (int i = 0; i < 3; ++i) X(k, i) += distortion * u(rng);
  return X;
}

// Current parameters of brick X: a random homogeneous F (entries of F - I up to 0.3,
// det F >= 0.5) applied to X plus a random perturbation of size `noise`, redrawn until
// every Gauss point of `rule` has det F > min_det_f.
inline BrickParams deformed_brick(std::mt19937& rng, const BrickParams& X, double noise,
                                  const quadrature::TensorRule<3>& rule, double min_det_f) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    Mat3 F = Mat3::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F(i, j) += 0.3 * u(rng);
    if (F.determinant() < 0.5) continue;
    BrickParams x = X * F.transpose();
    for (int k = 0; k < kBrickFunctions; ++k)
      for (int i = 0; i < 3; ++i) x(k, i) += noise * u(rng);
    bool ok = true;
    for (const Mat3& f : brick_deformation_gradients(X, x, rule)) ok = ok && f.determinant() > min_det_f;
    if (ok) return x;
  }
}

// ---- Fields and held dofs -----------------------------------------------------------

// x = F X + t on every parameter of the ply (the translation on values only), flattened.
inline VecX affine(const PlyMesh& ply, const Mat3& F, const Vec3& t) {
  MatX x = ply.reference();
  for (Index p = 0; p < x.rows(); ++p) {
    x.row(p) = (F * x.row(p).transpose()).transpose();
    if (p % 4 == mesh::kValue) x.row(p) += t.transpose();
  }
  return PlyMesh::flatten(x);
}

// Surface nodes of the ply at x = const (1e-9 mm), ascending.
inline std::vector<Index> surface_nodes_at_x(const PlyMesh& ply, double x) {
  std::vector<Index> out;
  for (Index s = 0; s < ply.n_surface_nodes(); ++s)
    if (std::abs(ply.surface().node_position(s).x() - x) < 1e-9) out.push_back(s);
  return out;
}

inline std::vector<Index> all_surface_nodes(const PlyMesh& ply) {
  std::vector<Index> out;
  for (Index s = 0; s < ply.n_surface_nodes(); ++s) out.push_back(s);
  return out;
}

// Which parameters of a node are held: every one (values, d/ds1, d/ds2, cross), or the
// "section" of a face x = const: values and the along-face tangent d/ds2 (u given on the
// face, the continuum Dirichlet condition).
enum class Held { kAllParameters, kSection };

// Global dofs of the held parameters of the surface nodes of body `body`, both layers,
// all three coordinates (order: node, layer, parameter, coordinate).
inline std::vector<Index> node_dofs(const Model& model, int body, const std::vector<Index>& surface_nodes,
                                    Held held = Held::kAllParameters) {
  const PlyMesh& ply = model.ply(body);
  std::vector<Index> out;
  for (Index s : surface_nodes)
    for (int layer = 0; layer < 2; ++layer)
      for (int d = 0; d < 4; ++d) {
        if (held == Held::kSection && d != mesh::kValue && d != mesh::kD2) continue;
        for (int i = 0; i < 3; ++i) out.push_back(model.dof(body, ply.node(s, layer), d, i));
      }
  return out;
}

// The dofs prescribed at their values in `target` (n_dofs).
inline std::vector<PrescribedDof> held_at(const std::vector<Index>& dofs, const VecX& target) {
  std::vector<PrescribedDof> out;
  out.reserve(dofs.size());
  for (Index d : dofs) out.push_back({d, target(d)});
  return out;
}

// ---- simform run --------------------------------------------------------------------

// A quiet run of `spec` into `dir` (emptied first), with its history and summary read back.
struct RunOutput {
  RunReport report;
  io::CsvTable history;
  nlohmann::json summary;
};
inline RunOutput run_into(const FormingCase& spec, const std::filesystem::path& dir, const std::string& grid = "",
                          int grid_marks = 5) {
  std::filesystem::remove_all(dir);
  RunOptions o;
  o.out_dir = dir.string();
  o.quiet = true;
  o.grid_out = grid;
  o.grid_marks = grid_marks;
  RunOutput out;
  out.report = run_case(spec, o);
  out.history = io::read_csv((dir / "history.csv").string());
  out.summary = io::read_json((dir / "summary.json").string());
  return out;
}

// The whole text of a file ("" when it cannot be read).
inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ---- Case texts ---------------------------------------------------------------------

// A coarse plane-strain double-diaphragm bend: two plies between Mooney-Rivlin
// diaphragms (symmetry at x0) pressed into a die slot; the vacuum line is
// "  vacuum: {pressure: 0.02, ramp: linear}" (line 28), which tests vary.
inline constexpr const char* kDiaphragmBend = R"(units: "mm, N, MPa, s"
materials:
  ply_law: {neo_hookean: {E: 200, nu: 0.3}}
  rubber: {mooney_rivlin: {c10: 0.3, c01: 0.05, nu: 0.45}}
laminates:
  - name: lam
    origin: [0, 0, 1]
    size: [20, 5]
    elements: [6, 1]
    layup: "[0_2]"
    ply_thickness: 0.5
    material: ply_law
    plane_strain: true
    interface: {stiffness: 50, viscous: 0.02, band: 0.01}
tools:
  - name: die
    die: {centre: [0, 0, 0], normal: [0, 0, 1], slot_half_width: 10, along: [0, 1, 0], edge_radius: 3}
    motion: {fixed: true}
diaphragms:
  name: dd
  laminate: lam
  frame: {origin: [0, 0], size: [30, 5]}
  elements: [10, 1]
  thickness: 1
  material: rubber
  symmetry: [x0]
  pressure: {value: 0.02, face: top, ramp: linear}
  vacuum: {pressure: 0.02, ramp: linear}
  contact: {stiffness: 50, viscous: 0.05, band: 0.01}
  tools: [{tool: die, stiffness: 50, band: 0.01}]
boundary_conditions:
  - symmetry: {ply: lam.1, plane: x0}
  - symmetry: {ply: lam.2, plane: x0}
solver: {steps: 3, process_time: 0.1, max_iterations: 40, tolerance: 1.0e-6}
)";

}  // namespace sf::forming::fixtures

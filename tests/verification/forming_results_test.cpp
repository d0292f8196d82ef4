// Verification of the forming results (issue 13 item 5; notes/forming-verification.md
// section 1.2; docs/forming.md "Forming results"):
//
//  * picture-frame shear kinematics: a 0/90 pair of stiff-fibre plies whose edges follow
//    the hinged frame (L_frame = 145 mm, crosshead d = 20 and 40 mm) is solved with its
//    interior free; the trellis shear angle of the solution must be the closed form
//    gamma = 90 - 2 theta, cos theta = (sqrt(2) L + d) / (2 L), everywhere, and the fibres
//    unstretched;
//  * bias extension (section 1.1): a tied +-45 pair's shear in zone C against the
//    closed form of the inextensible kinematics (the refinement study is in
//    docs/forming.md "Bias extension");
//  * a symmetric laminate under a centred spherical punch (full model, no symmetry
//    conditions) stays mirror-symmetric about both mid-planes;
//  * the punch's reaction force (tool_force.csv) equals the integral of the contact
//    pressure written on the top ply's face in the last frame (a post-processing path
//    independent of the solver's), integrated over the reference face: the pressure is
//    a force per reference area (see the test).
#include <unistd.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "common/io/csv.hpp"
#include "common/io/vtk_xml.hpp"
#include "forming/case/reader.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/output/forming_fields.hpp"
#include "forming/solve/static_solver.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// The hinged frame's map for crosshead displacement d: the sides (initially along x and
// y) turn symmetrically about the diagonal, unstretched; theta = half the angle between
// them.
Mat3 frame_map(double L, double d, double* gamma_deg) {
  const double theta = std::acos((std::sqrt(2.0) * L + d) / (2.0 * L));
  *gamma_deg = 90.0 - 2.0 * theta / kDeg;
  const double a1 = kPi / 4 - theta, a2 = kPi / 4 + theta;
  Mat3 F = Mat3::Identity();
  F(0, 0) = std::cos(a1);
  F(1, 0) = std::sin(a1);
  F(0, 1) = std::cos(a2);
  F(1, 1) = std::sin(a2);
  return F;
}

TEST(PictureFrame, TrellisShearOfTheSolvedPairFollowsTheFrameKinematics) {
  const double L = 145.0, h = 1.0;
  for (const double d : {20.0, 40.0}) {
    Model model;
    for (int k = 0; k < 2; ++k) {
      PlyMesh ply(mesh::make_rectangle_mesh(Vec3(0, 0, 1.5 * h * k), Vec3::UnitX(), Vec3::UnitY(), L, L, 4, 4), h,
                  k == 0 ? 0.0 : 90.0, PlyPlacement::kBottom);
      auto law = std::make_shared<TransverselyIsotropic>(fixtures::ti_compressible(0.4, 0.5, 5000.0, 1.0),
                                                         ply.fibre_direction());
      model.add_ply(std::move(ply), law);
    }
    double gamma = 0.0;
    const Mat3 F = frame_map(L, d, &gamma);
    VecX target(model.n_dofs());
    for (int b = 0; b < 2; ++b)
      target.segment(model.offset(b), model.ply(b).n_dofs()) = fixtures::affine(model.ply(b), F, Vec3::Zero());
    // The frame holds the in-plane coordinates of every parameter of the edge nodes;
    // through the thickness the plies are free (one z value held against a rigid drift).
    std::vector<PrescribedDof> bcs;
    for (int b = 0; b < 2; ++b) {
      for (Index s : model.ply(b).boundary_surface_nodes())
        for (int layer = 0; layer < 2; ++layer)
          for (int p = 0; p < 4; ++p)
            for (int i = 0; i < 2; ++i) {
              const Index dof = model.dof(b, model.ply(b).node(s, layer), p, i);
              bcs.push_back({dof, target(dof)});
            }
      const Index z = model.dof(b, model.ply(b).node(0, 0), 0, 2);
      bcs.push_back({z, target(z)});
    }
    StaticOptions options;
    options.initial_increment = 0.25;
    options.max_steps = 60;
    const StaticResult res = solve_static(model, model.reference_positions(), bcs, VecX(), options);
    ASSERT_TRUE(res.report.ok()) << res.report.brief();
    const FormingFields fields(model, res.positions);
    double err = 0.0, stretch = 0.0;
    for (int b = 0; b < 2; ++b)
      for (Index e = 0; e < model.ply(b).n_elements(); ++e)
        for (const Vec3& xi : {Vec3(0.5, 0.5, 0.5), Vec3(0.2, 0.7, 0.5), Vec3(0.9, 0.1, 0.5)}) {
          const PlyPointFields f = fields.at(b, e, xi);
          err = std::max(err, std::abs(f.trellis_shear_deg - gamma));
          stretch = std::max(stretch, std::abs(f.fibre_stretch - 1.0));
        }
    std::printf(
        "picture frame L = %.0f mm, d = %.0f mm: gamma closed form %.4f deg, max |error| %.2e deg, "
        "max |fibre stretch - 1| %.2e\n",
        L, d, gamma, err, stretch);
    EXPECT_LT(err, 1e-6);
    EXPECT_LT(stretch, 1e-8);
  }
}

// A +-45 pair tied everywhere (no inter-ply slip) as one body: the energy of the two
// unidirectional laws summed, W = W_TI(a+) + W_TI(a-), i.e. a pin-jointed biaxial net
// with a soft matrix. The measured shear angle is 90 deg - angle(F a+, F a-).
class TiedPair final : public Material {
 public:
  TiedPair(const TransverselyIsotropicParams& p)
      : plus_(p, Vec3(1, 1, 0).normalized()), minus_(p, Vec3(1, -1, 0).normalized()) {}
  MaterialResponse evaluate(const Mat3& C, bool want_tangent) const override {
    MaterialResponse a = plus_.evaluate(C, want_tangent);
    const MaterialResponse b = minus_.evaluate(C, want_tangent);
    a.energy += b.energy;
    a.stress += b.stress;
    a.tangent += b.tangent;
    return a;
  }
  std::string name() const override { return "tied +-45 pair"; }

 private:
  TransverselyIsotropic plus_, minus_;
};

double bias_gamma_deg(double L0, double d) { return 90.0 - 2.0 * std::acos((L0 + d) / (std::sqrt(2.0) * L0)) / kDeg; }

// Zone-C shear angles of a solved bias-extension specimen (H = 2 W): the mean over the
// elements whose centres lie in the central box used before (|x - H/2| < 0.15 H,
// |y - W/2| < 0.2 W), the area mean over zone C itself (the diamond |x - H/2| + |y - W/2|
// <= W/2, sampled on a 0.5 mm grid) and the value at the centre.
struct BiasZoneC {
  double box_mean = 0.0, zone_mean = 0.0, centre = 0.0, max_stretch = 0.0;
};

double pair_shear_deg(const Mat3& F) {
  const Vec3 ap = F * Vec3(1, 1, 0).normalized(), am = F * Vec3(1, -1, 0).normalized();
  return 90.0 - std::acos(ap.dot(am) / (ap.norm() * am.norm())) / kDeg;
}

BiasZoneC bias_zone_c(const Model& model, const VecX& x, double H, double W) {
  const FormingFields fields(model, x);
  const PlyMesh& ply = model.ply(0);
  BiasZoneC out;
  int n = 0;
  std::vector<std::array<Vec3, 2>> corners;  // reference plan corners of each element
  for (Index e = 0; e < ply.n_elements(); ++e) {
    const PlyPointFields f = fields.at(0, e, Vec3(0.5, 0.5, 0.5));
    corners.push_back({fields.at(0, e, Vec3(0, 0, 0.5)).X, fields.at(0, e, Vec3(1, 1, 0.5)).X});
    if (std::abs(f.X[0] - 0.5 * H) > 0.15 * H || std::abs(f.X[1] - 0.5 * W) > 0.2 * W) continue;
    out.box_mean += pair_shear_deg(f.F);
    ++n;
  }
  out.box_mean /= std::max(1, n);
  const auto at = [&](double X, double Y) {
    for (Index e = 0; e < ply.n_elements(); ++e) {
      const auto& c = corners[static_cast<std::size_t>(e)];
      if (X < c[0][0] || X > c[1][0] || Y < c[0][1] || Y > c[1][1]) continue;
      return fields.at(0, e, Vec3((X - c[0][0]) / (c[1][0] - c[0][0]), (Y - c[0][1]) / (c[1][1] - c[0][1]), 0.5));
    }
    throw Error("bias_zone_c: no element at the point");
  };
  double sum = 0.0;
  int m = 0;
  for (double X = 0.25; X < H; X += 0.5)
    for (double Y = 0.25; Y < W; Y += 0.5) {
      if (std::abs(X - 0.5 * H) + std::abs(Y - 0.5 * W) > 0.5 * W) continue;
      const PlyPointFields f = at(X, Y);
      sum += pair_shear_deg(f.F);
      const Vec3 ap = f.F * Vec3(1, 1, 0).normalized(), am = f.F * Vec3(1, -1, 0).normalized();
      out.max_stretch = std::max({out.max_stretch, std::abs(ap.norm() - 1.0), std::abs(am.norm() - 1.0)});
      ++m;
    }
  out.zone_mean = sum / m;
  out.centre = pair_shear_deg(at(0.5 * H, 0.5 * W).F);
  return out;
}

// Solves the bias extension of the tied pair (H x W, 2m x m bricks, fibre constant
// kappa_f against a matrix of mu = 0.01 MPa) to clamp displacement d.
VecX solve_bias(Model& model, double H, double d) {
  const PlyMesh& ply = model.ply(0);
  VecX target = model.reference_positions();
  const std::vector<Index> pulled = fixtures::surface_nodes_at_x(ply, H);
  for (Index s : pulled)
    for (int layer = 0; layer < 2; ++layer) target(model.dof(0, ply.node(s, layer), 0, 0)) += d;
  std::vector<Index> held = fixtures::node_dofs(model, 0, fixtures::surface_nodes_at_x(ply, 0.0));
  const std::vector<Index> end = fixtures::node_dofs(model, 0, pulled);
  held.insert(held.end(), end.begin(), end.end());
  StaticOptions options;
  options.initial_increment = 0.25;
  options.max_increment = 0.5;
  options.max_steps = 200;
  options.max_iterations = 40;
  const StaticResult res =
      solve_static(model, model.reference_positions(), fixtures::held_at(held, target), VecX(), options);
  EXPECT_TRUE(res.report.ok()) << res.report.brief();
  return res.positions;
}

TEST(BiasExtension, CentralZoneShearOfATiedPlusMinus45PairApproachesTheInextensibleKinematics) {
  // H x W = 100 x 50 mm (H/W = 2, L0 = H - W = 50 mm), clamped ends, one end pulled by d
  // along x, fibres kappa_f = 200 MPa against a matrix of mu = 0.01 MPa (2e4), 12 x 6
  // bricks. SF_BIAS_BRICKS_ACROSS (default 6), SF_BIAS_KAPPA (MPa, default 200) and
  // SF_BIAS_D (mm, default 5) set up the study of docs/forming.md "Bias extension": the
  // closed form is the inextensible limit with uniform shear in zone C and kinks at the
  // zone boundaries. The C1 Hermite mesh cannot kink, so near-inextensible fibres put
  // more shear at the centre and less near the boundaries (centre +53 % here, converging
  // as h^1.1 to h^1.5); the area mean over zone C, which the kinematics fix, is within
  // 1 % from 8 x 4 bricks on. Softer fibres (2e2) stretch and fall 14 % short.
  const double H = 100.0, W = 50.0, L0 = H - W;
  const char* env_m = std::getenv("SF_BIAS_BRICKS_ACROSS");
  const char* env_k = std::getenv("SF_BIAS_KAPPA");
  const char* env_d = std::getenv("SF_BIAS_D");
  const int m = env_m ? std::max(2, std::atoi(env_m)) : 6;
  const double kappa = env_k ? std::atof(env_k) : 200.0;
  const double d = env_d ? std::atof(env_d) : 5.0;
  Model model;
  model.add_ply(fixtures::rectangle_ply(H, W, 1.0, 2 * m, m, 45.0),
                std::make_shared<TiedPair>(fixtures::ti_compressible(0.01, 0.01, kappa, 0.02)));
  const VecX x = solve_bias(model, H, d);
  const BiasZoneC z = bias_zone_c(model, x, H, W);
  const double exact = bias_gamma_deg(L0, d);
  const auto err = [&](double v) { return 100.0 * (v - exact) / exact; };
  std::printf(
      "bias extension 100 x 50 mm, %d x %d bricks, kappa_f/mu = %g, d = %.1f mm: closed form %.3f deg; zone C "
      "area mean %.3f deg (%+.1f %%), centre %.3f (%+.1f %%), central box mean %.3f (%+.1f %%); max |fibre "
      "stretch - 1| in zone C %.1e\n",
      2 * m, m, kappa / 0.01, d, exact, z.zone_mean, err(z.zone_mean), z.centre, err(z.centre), z.box_mean,
      err(z.box_mean), z.max_stretch);
  if (env_m || env_k || env_d) return;            // a study: the bounds below are for the default set-up
  EXPECT_NEAR(z.zone_mean, exact, 0.02 * exact);  // measured +0.6 %
  EXPECT_LT(z.max_stretch, 2e-3);                 // measured 7.9e-4 (near the zone boundaries)
  EXPECT_GT(z.centre, exact);                     // the smeared boundaries (see above)
}

// A full [0,90,90,0]-like laminate of two neo-Hookean stand-in plies (as
// data/forming/contact/laminate_punch.yaml), clamped on every edge, lying on a bilateral
// plane, pressed by a sphere on its centre.
const char* kSymmetricCase = R"(
units: "mm, N, MPa, s"
materials:
  stand_in:
    neo_hookean: {E: 10, nu: 0.3}
laminates:
  - name: lam
    size: [20, 20]
    elements: [8, 8]
    layup: "[0,90]"
    ply_thickness: 0.5
    material: stand_in
    interface: {stiffness: 50, band: 0.005}
tools:
  - name: punch
    sphere: {centre: [10, 10, 21], radius: 20}
    motion: {displacement: [0, 0, -0.3], ramp: linear}
contact:
  - {ply: lam.2, face: top, tool: punch, stiffness: 50, band: 0.005}
boundary_conditions:
  - symmetry: {ply: lam.1, plane: bottom}
  - clamp: {ply: lam.1, edge: x0}
  - clamp: {ply: lam.1, edge: x1}
  - clamp: {ply: lam.1, edge: y0}
  - clamp: {ply: lam.1, edge: y1}
  - clamp: {ply: lam.2, edge: x0}
  - clamp: {ply: lam.2, edge: x1}
  - clamp: {ply: lam.2, edge: y0}
  - clamp: {ply: lam.2, edge: y1}
solver: {steps: 4, process_time: 1, max_iterations: 30, tolerance: 1.0e-9}
output: {every: 4, samples: [8, 1]}
)";

class PressedLaminate : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One folder per test process: ctest runs this suite's tests at the same time, and a
    // results folder takes one writer at a time (the second run refused, and gtest then
    // reported its test as skipped, not failed).
    dir_ = std::filesystem::path(SF_BINARY_DIR) / "verification_out" /
           ("pressed_laminate." + std::to_string(static_cast<long>(::getpid())));
    const CaseCheck c = check_case_text(kSymmetricCase, "pressed_laminate.yaml");
    ASSERT_TRUE(c.ok());
    spec_ = new FormingCase(c.spec);
    run_ = new fixtures::RunOutput(fixtures::run_into(*spec_, dir_));
  }
  static void TearDownTestSuite() {
    delete run_;
    delete spec_;
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  static io::VolumeMesh last_frame() { return io::read_vtu((dir_ / "steps" / "step_0004.vtu").string()); }
  static std::filesystem::path dir_;
  static FormingCase* spec_;
  static fixtures::RunOutput* run_;
};
std::filesystem::path PressedLaminate::dir_;
FormingCase* PressedLaminate::spec_ = nullptr;
fixtures::RunOutput* PressedLaminate::run_ = nullptr;

const io::FieldArray& field(const std::vector<io::FieldArray>& fields, const std::string& name) {
  for (const io::FieldArray& f : fields)
    if (f.name == name) return f;
  throw Error("no field " + name);
}

TEST_F(PressedLaminate, StaysMirrorSymmetric) {
  ASSERT_TRUE(run_->report.ok()) << run_->report.message;
  const io::VolumeMesh m = last_frame();
  const io::FieldArray& u = field(m.point_data, "displacement");
  const io::FieldArray& ply = field(m.cell_data, "ply");
  std::vector<double> body(static_cast<std::size_t>(m.points.rows()), -1.0);
  for (std::size_t c = 0; c < m.n_cells(); ++c)
    for (Index k = m.offsets[c]; k < m.offsets[c + 1]; ++k)
      body[static_cast<std::size_t>(m.connectivity[static_cast<std::size_t>(k)])] = ply.values[c];
  // Every point has its mirror images about x = 10 and y = 10 among the points (same
  // reference position X = x - u mirrored); compare displacements.
  const Index n = m.points.rows();
  std::vector<Vec3> X(static_cast<std::size_t>(n)), U(static_cast<std::size_t>(n));
  double umax = 0.0;
  for (Index p = 0; p < n; ++p) {
    const std::size_t q = static_cast<std::size_t>(p);
    U[q] = Vec3(u.values[3 * q], u.values[3 * q + 1], u.values[3 * q + 2]);
    X[q] = m.points.row(p).transpose() - U[q];
    umax = std::max(umax, U[q].norm());
  }
  double err = 0.0;
  int pairs = 0;
  for (int axis = 0; axis < 2; ++axis)
    for (std::size_t p = 0; p < X.size(); ++p) {
      Vec3 Xm = X[p];
      Xm[axis] = 20.0 - Xm[axis];
      for (std::size_t q = 0; q < X.size(); ++q) {
        if (body[q] != body[p] || (X[q] - Xm).norm() > 1e-7) continue;
        Vec3 Um = U[p];
        Um[axis] = -Um[axis];
        err = std::max(err, (U[q] - Um).norm());
        ++pairs;
        break;
      }
    }
  std::printf(
      "pressed laminate: max |u| %.4f mm, largest mirror asymmetry %.2e mm (%.1e of max |u|) over %d "
      "point pairs\n",
      umax, err, err / umax, pairs);
  EXPECT_GT(umax, 0.2);
  EXPECT_GT(pairs, static_cast<int>(X.size()));  // (nearly) every point has both mirror images
  EXPECT_LT(err, 1e-6 * umax);
}

TEST_F(PressedLaminate, PunchForceEqualsTheIntegralOfContactPressure) {
  ASSERT_TRUE(run_->report.ok()) << run_->report.message;
  const io::CsvTable t = io::read_csv((dir_ / "tool_force.csv").string());
  const double force = t.number(t.n_rows() - 1, t.column_index("punch_force_N"));
  // The top ply's top faces: body 1, cells of the top layer (one here), nodes 4-7.
  const io::VolumeMesh m = last_frame();
  const io::FieldArray& ply = field(m.cell_data, "ply");
  const io::FieldArray& p = field(m.point_data, "contact_pressure");
  const io::FieldArray& u = field(m.point_data, "displacement");
  Vec3 integral = Vec3::Zero();
  double nominal = 0.0;  // over the reference face: the pressure as a force per reference area
  const double g = 1.0 / std::sqrt(3.0);
  for (std::size_t c = 0; c < m.n_cells(); ++c) {
    if (ply.values[c] != 1.0) continue;
    const Index* node = &m.connectivity[static_cast<std::size_t>(m.offsets[c])];
    std::array<Vec3, 4> x, X;
    std::array<double, 4> pr;
    for (int k = 0; k < 4; ++k) {
      const std::size_t q = static_cast<std::size_t>(node[4 + k]);
      x[static_cast<std::size_t>(k)] = m.points.row(node[4 + k]).transpose();
      X[static_cast<std::size_t>(k)] =
          x[static_cast<std::size_t>(k)] - Vec3(u.values[3 * q], u.values[3 * q + 1], u.values[3 * q + 2]);
      pr[static_cast<std::size_t>(k)] = p.values[static_cast<std::size_t>(node[4 + k])];
    }
    // Bilinear quad (nodes counter-clockwise), 2 x 2 Gauss points: the pressure pushes the
    // punch along the face's outward normal (up).
    for (const double s : {-g, g})
      for (const double r : {-g, g}) {
        const std::array<double, 4> N = {0.25 * (1 - s) * (1 - r), 0.25 * (1 + s) * (1 - r), 0.25 * (1 + s) * (1 + r),
                                         0.25 * (1 - s) * (1 + r)};
        const Vec3 xs = 0.25 * (-(1 - r) * x[0] + (1 - r) * x[1] + (1 + r) * x[2] - (1 + r) * x[3]);
        const Vec3 xr = 0.25 * (-(1 - s) * x[0] - (1 + s) * x[1] + (1 + s) * x[2] + (1 - s) * x[3]);
        double pv = 0.0;
        for (int k = 0; k < 4; ++k) pv += N[static_cast<std::size_t>(k)] * pr[static_cast<std::size_t>(k)];
        integral += pv * xs.cross(xr);
        const Vec3 Xs = 0.25 * (-(1 - r) * X[0] + (1 - r) * X[1] + (1 + r) * X[2] - (1 + r) * X[3]);
        const Vec3 Xr = 0.25 * (-(1 - s) * X[0] - (1 + s) * X[1] + (1 + s) * X[2] + (1 - s) * X[3]);
        nominal += pv * Xs.cross(Xr).norm();
      }
  }
  const double rel = std::abs(integral[2] - force) / force, rel_nominal = std::abs(nominal - force) / force;
  std::printf(
      "pressed laminate: punch force %.6f N (tool_force.csv); integral of contact pressure over the "
      "deformed face %.6f N (z; lateral %.1e N; %.2e), over the reference face %.6f N (%.2e)\n",
      force, integral[2], integral.head<2>().norm(), rel, nominal, rel_nominal);
  EXPECT_GT(force, 0.1);
  // The contact law's pressure is a force per REFERENCE area (the records' weights are
  // reference areas): over the reference face the written field integrates to the
  // reaction within the interpolation of the field (bilinear through the contact points);
  // over the deformed face it is larger by the face's area stretch (~6 % here, where the
  // punch squeezes the stand-in ply by about 20 %).
  EXPECT_LT(rel_nominal, 0.02);
  EXPECT_GT(integral[2], nominal);
  (void)rel;
  EXPECT_LT(integral.head<2>().norm(), 1e-6 * force);
}

}  // namespace
}  // namespace sf::forming

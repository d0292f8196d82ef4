// Forming results (forming/output/forming_fields.hpp, forming_results.hpp) on states with
// a known answer: a rigid rotation (stretch 1, angle change = the rotation, thickness
// kept), trellis shear of a 0/90 and a +-45 pair (the shear angle imposed), a uniform
// thickness change, a sinusoidal waviness (amplitude and wavelength), the tool force
// table and the line profiles of a translated laminate.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "common/io/csv.hpp"
#include "forming/output/forming_fields.hpp"
#include "forming/output/forming_results.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

std::shared_ptr<const Material> ti_ply(const PlyMesh& ply) {
  return std::make_shared<TransverselyIsotropic>(fixtures::ti_compressible(0.4, 0.5, 1000.0, 1.0),
                                                 ply.fibre_direction());
}

// A stack of plies (angles bottom first) of l x l x h on n x n bricks, TI law.
Model stack(const std::vector<double>& angles, double l = 40.0, double h = 1.0, int n = 4) {
  Model model;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    PlyMesh ply(
        mesh::make_rectangle_mesh(Vec3(0, 0, h * static_cast<double>(k)), Vec3::UnitX(), Vec3::UnitY(), l, l, n, n), h,
        angles[k], PlyPlacement::kBottom);
    auto m = ti_ply(ply);
    model.add_ply(std::move(ply), m);
  }
  return model;
}

// x = F X + t on every body.
VecX affine_all(const Model& model, const Mat3& F, const Vec3& t) {
  VecX x(model.n_dofs());
  for (int b = 0; b < model.n_bodies(); ++b)
    x.segment(model.offset(b), model.ply(b).n_dofs()) = fixtures::affine(model.ply(b), F, t);
  return x;
}

// Every mid-thickness sample of every ply: f(fields).
template <class Check>
void for_all_points(const Model& model, const FormingFields& fields, Check check) {
  for (int b = 0; b < model.n_bodies(); ++b)
    for (Index e = 0; e < model.ply(b).n_elements(); ++e)
      for (const Vec3& xi : {Vec3(0.5, 0.5, 0.5), Vec3(0.1, 0.8, 0.5), Vec3(0.9, 0.3, 0.5)})
        check(b, fields.at(b, e, xi));
}

TEST(FormingFields, RigidRotationKeepsStretchAndThicknessAndTurnsTheFibres) {
  const Model model = stack({45.0, -45.0});
  const double phi = 30.0;
  const Mat3 R = Eigen::AngleAxisd(phi * kDeg, Vec3::UnitZ()).toRotationMatrix();
  const FormingFields fields(model, affine_all(model, R, Vec3(3, -2, 5)));
  EXPECT_EQ(fields.partner(0), 1);
  EXPECT_EQ(fields.partner(1), 0);
  for_all_points(model, fields, [&](int, const PlyPointFields& f) {
    EXPECT_NEAR(f.fibre_stretch, 1.0, 1e-12);
    EXPECT_NEAR(f.fibre_angle_change_deg, phi, 1e-9);
    EXPECT_NEAR(f.ply_shear_deg, 0.0, 1e-9);
    EXPECT_NEAR(f.thickness, 1.0, 1e-12);
    EXPECT_NEAR(f.trellis_shear_deg, 0.0, 1e-9);
  });
}

TEST(FormingFields, TrellisShearOfA0And90PairIsTheImposedAngle) {
  const Model model = stack({0.0, 90.0});
  const double gamma = 20.0;
  Mat3 F = Mat3::Identity();  // x fibres stay, y fibres turn by gamma, both inextensible
  F(0, 1) = std::sin(gamma * kDeg);
  F(1, 1) = std::cos(gamma * kDeg);
  const FormingFields fields(model, affine_all(model, F, Vec3::Zero()));
  for_all_points(model, fields, [&](int b, const PlyPointFields& f) {
    EXPECT_NEAR(f.trellis_shear_deg, gamma, 1e-9) << "ply " << b;
    EXPECT_NEAR(f.fibre_stretch, 1.0, 1e-12);
    EXPECT_NEAR(f.ply_shear_deg, b == 0 ? gamma : -gamma, 1e-9) << "ply " << b;
    EXPECT_NEAR(f.fibre_angle_change_deg, b == 0 ? 0.0 : -gamma, 1e-9);
  });
}

TEST(FormingFields, BiasExtensionKinematicsOfAPlusMinus45Pair) {
  // Pure shear of inextensible +-45 fibres: the half angle theta to the load axis x,
  // stretches sqrt(2) cos(theta) along x and sqrt(2) sin(theta) across; gamma = 90 - 2 theta.
  const Model model = stack({45.0, -45.0, 45.0});
  const double theta = 35.0;
  const Mat3 F =
      Vec3(std::sqrt(2.0) * std::cos(theta * kDeg), std::sqrt(2.0) * std::sin(theta * kDeg), 1.0).asDiagonal();
  const FormingFields fields(model, affine_all(model, F, Vec3::Zero()));
  EXPECT_EQ(fields.partner(1), 0);  // tie between plies 0 and 2: the lower one
  for_all_points(model, fields, [&](int b, const PlyPointFields& f) {
    EXPECT_NEAR(f.trellis_shear_deg, 90.0 - 2.0 * theta, 1e-9) << "ply " << b;
    EXPECT_NEAR(f.fibre_stretch, 1.0, 1e-12);
    EXPECT_NEAR(std::abs(f.fibre_angle_change_deg), 45.0 - theta, 1e-9);
  });
}

TEST(FormingFields, UniformThicknessChange) {
  const Model model = stack({0.0, 90.0}, 40.0, 0.5);
  const Mat3 F = Vec3(1.1, 1.0 / 1.1 / 0.8, 0.8).asDiagonal();
  Mat3 G = F;
  G(0, 2) = 0.3;  // a transverse shear does not change the thickness measured along the normal
  for (const Mat3& M : {F, G}) {
    const FormingFields fields(model, affine_all(model, M, Vec3::Zero()));
    for_all_points(model, fields, [&](int, const PlyPointFields& f) { EXPECT_NEAR(f.thickness, 0.4, 1e-12); });
  }
}

TEST(FormingFields, PartnersSkipParallelPliesAndIsotropicOnes) {
  const Model model = stack({0.0, 90.0, 90.0, 0.0});
  const FormingFields fields(model, model.reference_positions());
  EXPECT_EQ(fields.partner(0), 1);
  EXPECT_EQ(fields.partner(1), 0);
  EXPECT_EQ(fields.partner(2), 3);
  EXPECT_EQ(fields.partner(3), 2);
  Model iso;
  iso.add_ply(fixtures::rectangle_ply(10, 10, 1, 2, 2, 0.0), fixtures::neo_hookean(1.0, 1.0));
  iso.add_ply(fixtures::rectangle_ply(10, 10, 1, 2, 2, 90.0), fixtures::neo_hookean(1.0, 1.0));
  const FormingFields none(iso, iso.reference_positions());
  EXPECT_EQ(none.partner(0), -1);
  EXPECT_TRUE(std::isnan(none.at(0, 0, Vec3(0.5, 0.5, 0.5)).trellis_shear_deg));
}

// x = X + (0, 0, A sin(k X)) on every parameter (values, and the derivatives through the
// map's Jacobian; the cross derivative stays 0).
VecX wavy(const PlyMesh& ply, double amplitude, double wavelength) {
  const double k = 2.0 * kPi / wavelength;
  MatX x = ply.reference();
  for (Index n = 0; n < ply.n_nodes(); ++n) {
    const double X = ply.reference()(4 * n, 0);
    x(4 * n, 2) += amplitude * std::sin(k * X);
    x(4 * n + 1, 2) += amplitude * k * std::cos(k * X) * ply.reference()(4 * n + 1, 0);
    x(4 * n + 2, 2) += amplitude * k * std::cos(k * X) * ply.reference()(4 * n + 2, 0);
  }
  return PlyMesh::flatten(x);
}

TEST(FormingFields, WrinklingIndicatorMeasuresASinusoid) {
  const Model model = stack({0.0}, 100.0, 0.5, 50);  // 2 mm bricks
  const double A = 0.8, lambda = 8.0;
  const FormingFields fields(model, wavy(model.ply(0), A, lambda));
  const WrinkleResult w = fields.wrinkles(0, 2);
  std::printf("sinusoid A %.3f mm, lambda %.2f mm: amplitude %.4f, rms %.4f, wavelength %.4f mm\n", A, lambda,
              w.amplitude, w.rms, w.wavelength);
  EXPECT_NEAR(w.radius, 8.0, 1e-9);
  EXPECT_NEAR(w.amplitude, A, 0.15 * A);
  EXPECT_NEAR(w.rms, A / std::sqrt(2.0), 0.15 * A);
  EXPECT_NEAR(w.wavelength, lambda, 0.1 * lambda);
  // A smooth long wave (the part's shape) is absorbed by the smoothed surface.
  const FormingFields shape(model, wavy(model.ply(0), 5.0, 400.0));
  EXPECT_LT(shape.wrinkles(0, 2).amplitude, 0.01);
  // A rigidly moved flat ply: nothing.
  const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const FormingFields flat(model, affine_all(model, R, Vec3(1, 2, 3)));
  EXPECT_LT(flat.wrinkles(0, 2).amplitude, 1e-9);
}

TEST(FormingResults, ToolForceTableOfATool) {
  const std::string history =
      "step,load_factor,tool_ux,tool_uy,tool_uz,tool_fx,tool_fy,tool_fz,strain_energy,newton_iterations,cutbacks,"
      "residual,time,punch_ux,punch_uy,punch_uz,punch_fx,punch_fy,punch_fz\n"
      "0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n"
      "1,0.5,0,0,0,0,0,0,1,3,0,0,0.05,0,0,-1,0.1,0,4\n"
      "2,1,0,0,0,0,0,0,2,3,0,0,0.1,0,0,-2,0.2,0,9\n";
  const io::CsvTable t = io::read_csv_string(tool_force_csv(history, "history.csv", 1.0), "tool_force.csv");
  ASSERT_EQ(t.n_rows(), 3u);
  EXPECT_DOUBLE_EQ(t.number(2, t.column_index("time_s")), 0.1);
  EXPECT_DOUBLE_EQ(t.number(2, t.column_index("punch_stroke_mm")), 2.0);
  EXPECT_DOUBLE_EQ(t.number(2, t.column_index("punch_force_N")), 9.0);  // plies push back up: positive
  EXPECT_DOUBLE_EQ(t.number(1, t.column_index("punch_fx_N")), 0.1);
}

TEST(FormingResults, ToolForceTableOfTheToolEdgeWithoutTools) {
  const std::string history =
      "step,load_factor,tool_ux,tool_uy,tool_uz,tool_fx,tool_fy,tool_fz,strain_energy,newton_iterations,cutbacks,"
      "residual\n0,0,0,0,0,0,0,0,0,0,0,0\n1,1,2,0,0,30,0,0,1,3,0,0\n";
  const io::CsvTable t = io::read_csv_string(tool_force_csv(history, "history.csv", 4.0), "tool_force.csv");
  EXPECT_DOUBLE_EQ(t.number(1, t.column_index("time_s")), 4.0);
  EXPECT_DOUBLE_EQ(t.number(1, t.column_index("edge_stroke_mm")), 2.0);
  EXPECT_DOUBLE_EQ(t.number(1, t.column_index("edge_force_N")), 30.0);
  EXPECT_THROW(tool_force_csv("step,x\n1,2\n", "h.csv", 1.0), Error);
}

TEST(FormingResults, ProfilesOfATranslatedLaminateShowTheDrawIn) {
  const Model model = stack({0.0, 90.0}, 40.0, 1.0, 4);
  FormingCase spec;
  spec.plies.resize(2);
  spec.plies[0].name = "a";
  spec.plies[1].name = "b";
  const Vec3 c = part_centre(spec, model);
  EXPECT_NEAR(c[0], 20.0, 1e-12);
  EXPECT_NEAR(c[1], 20.0, 1e-12);
  const Vec3 t(-1.5, 0.5, 2.0);
  const io::CsvTable p = io::read_csv_string(profiles_csv(spec, model, affine_all(model, Mat3::Identity(), t)), "p");
  // 3 directions x 2 plies, every quarter brick (2.5 mm): 0 and 90 to 20 mm (9 points),
  // 45 to 28.28 mm (12 points).
  EXPECT_EQ(p.n_rows(), 2u * (9 + 12 + 9));
  for (std::size_t r = 0; r < p.n_rows(); ++r) {
    const double deg = p.number(r, p.column_index("direction_deg"));
    const Vec3 d(std::cos(deg * kDeg), std::sin(deg * kDeg), 0.0);
    EXPECT_NEAR(p.number(r, p.column_index("draw_in_mm")), -t.dot(d), 1e-7);
    EXPECT_NEAR(p.number(r, p.column_index("thickness_mm")), 1.0, 1e-12);
    EXPECT_NEAR(p.number(r, p.column_index("trellis_shear_deg")), 0.0, 1e-9);
  }
  // Symmetry planes x0 and y0: the centre is the symmetry corner.
  spec.boundaries.push_back({});
  spec.boundaries.back().kind = CaseBoundary::Kind::kSymmetry;
  spec.boundaries.back().side = PlySide::kX0;
  spec.boundaries.push_back(spec.boundaries.back());
  spec.boundaries.back().side = PlySide::kY0;
  EXPECT_NEAR(part_centre(spec, model).head<2>().norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace sf::forming

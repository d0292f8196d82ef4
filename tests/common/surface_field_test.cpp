// Property tests of field evaluation on surface meshes (common/fe/surface_field.hpp):
// evaluate vs evaluate3, update flags, derivatives against finite differences,
// and the global basis rows / element dof maps used by assembly, on quad and
// collapsed elements.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include "common/fe/surface_field.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::fe {
namespace {

using test::kFdFirst;
using test::kFdStep;
using test::kRoundoff;

constexpr unsigned kAll = basis::kValues | basis::kFirst | basis::kSecond;

std::string where(Index e, const Vec2& xi) {
  std::ostringstream os;
  os << "element " << e << " at xi=(" << xi[0] << ", " << xi[1] << ")";
  return os.str();
}

MatX random_parameters(Index rows, Index cols, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatX m(rows, cols);
  for (Index i = 0; i < rows; ++i)
    for (Index j = 0; j < cols; ++j) m(i, j) = u(rng);
  return m;
}

// A graded rectangle (quads only) and a disk (collapsed + quads).
mesh::SurfaceMesh rectangle() {
  return mesh::make_rectangle_mesh(Vec3(1, 2, 3), Vec3::UnitX(), Vec3::UnitZ(), 4.0, 2.5, 2, 2, {0, 1, 4}, {0, 2, 2.5});
}
mesh::SurfaceMesh disk() { return mesh::make_disk_mesh(Vec3(0, 0, 1), Vec3::UnitX(), Vec3::UnitY(), 2.0, 2, 6); }

TEST(SurfaceFieldEvaluate, Evaluate3AgreesWithEvaluate) {
  std::mt19937 rng(test::kSeed + 300);
  for (const mesh::SurfaceMesh& m : {rectangle(), disk()}) {
    const MatX params = random_parameters(m.n_dofs(), 3, rng);
    const SurfaceField f(m, params);
    ASSERT_EQ(f.n_components(), 3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (Index e = 0; e < m.n_elements(); ++e)
      for (int q = 0; q < 4; ++q) {
        const Vec2 xi(u(rng), u(rng));
        const FieldPoint a = f.evaluate(e, xi, kAll);
        const SurfacePoint b = f.evaluate3(e, xi, kAll);
        const SurfacePoint c = f.evaluate3(e, basis::BicubicHermite::evaluate(xi, kAll));
        for (int i = 0; i < 3; ++i) {
          EXPECT_NEAR(a.value[i], b.x[i], kRoundoff) << "value " << i << ", " << where(e, xi);
          EXPECT_NEAR(c.x[i], b.x[i], kRoundoff) << "value " << i << " (precomputed basis), " << where(e, xi);
          for (int j = 0; j < 2; ++j) {
            EXPECT_NEAR(a.first(i, j), b.dx(i, j), kRoundoff) << "first (" << i << "," << j << "), " << where(e, xi);
            EXPECT_NEAR(c.dx(i, j), b.dx(i, j), kRoundoff) << "first (" << i << "," << j << "), " << where(e, xi);
          }
          for (int j = 0; j < 3; ++j) {
            EXPECT_NEAR(a.second(i, j), b.d2x(i, j), kRoundoff) << "second (" << i << "," << j << "), " << where(e, xi);
            EXPECT_NEAR(c.d2x(i, j), b.d2x(i, j), kRoundoff) << "second (" << i << "," << j << "), " << where(e, xi);
          }
        }
      }
  }
}

TEST(SurfaceFieldEvaluate, OnlyRequestedPartsAreFilled) {
  std::mt19937 rng(test::kSeed + 301);
  const mesh::SurfaceMesh m = rectangle();
  const SurfaceField f(m, random_parameters(m.n_dofs(), 3, rng));
  const SurfaceField g(m, random_parameters(m.n_dofs(), 2, rng));
  const Vec2 xi(0.3, 0.6);
  const SurfacePoint full = f.evaluate3(1, xi, kAll);
  const FieldPoint gfull = g.evaluate(1, xi, kAll);
  for (unsigned flags = 0; flags <= kAll; ++flags) {
    const bool want0 = flags & basis::kValues, want1 = flags & basis::kFirst, want2 = flags & basis::kSecond;
    const std::string tag = "flags " + std::to_string(flags);
    // Dynamic result: unrequested parts stay empty, requested ones are sized and right.
    const FieldPoint p = g.evaluate(1, xi, flags);
    EXPECT_EQ(p.updated, flags) << tag;
    EXPECT_EQ(p.value.size(), want0 ? 2 : 0) << tag << ": value";
    EXPECT_EQ(p.first.size(), want1 ? 4 : 0) << tag << ": first";
    EXPECT_EQ(p.second.size(), want2 ? 6 : 0) << tag << ": second";
    if (want0) {
      EXPECT_NEAR((p.value - gfull.value).cwiseAbs().maxCoeff(), 0.0, kRoundoff) << tag;
    }
    if (want1) {
      EXPECT_NEAR((p.first - gfull.first).cwiseAbs().maxCoeff(), 0.0, kRoundoff) << tag;
    }
    if (want2) {
      EXPECT_NEAR((p.second - gfull.second).cwiseAbs().maxCoeff(), 0.0, kRoundoff) << tag;
    }
    // Fixed-size result: unrequested parts stay zero.
    const SurfacePoint s = f.evaluate3(1, xi, flags);
    EXPECT_EQ(s.updated, flags) << tag;
    EXPECT_NEAR((s.x - (want0 ? full.x : Vec3::Zero())).cwiseAbs().maxCoeff(), 0.0, kRoundoff) << tag << ": x";
    EXPECT_NEAR((s.dx - (want1 ? full.dx : Mat32::Zero())).cwiseAbs().maxCoeff(), 0.0, kRoundoff) << tag << ": dx";
    EXPECT_NEAR((s.d2x - (want2 ? full.d2x : Mat3::Zero())).cwiseAbs().maxCoeff(), 0.0, kRoundoff) << tag << ": d2x";
  }
}

TEST(SurfaceFieldEvaluate, CachesTheMeshElementParameters) {
  std::mt19937 rng(test::kSeed + 302);
  for (const mesh::SurfaceMesh& m : {rectangle(), disk()}) {
    const MatX params = random_parameters(m.n_dofs(), 2, rng);
    const SurfaceField f(m, params);
    EXPECT_EQ(&f.mesh(), &m);
    for (Index e = 0; e < m.n_elements(); ++e) {
      const MatX expected = m.element_parameters(e, params);
      ASSERT_EQ(f.element_parameters(e).rows(), 16);
      ASSERT_EQ(f.element_parameters(e).cols(), 2);
      EXPECT_NEAR((f.element_parameters(e) - expected).cwiseAbs().maxCoeff(), 0.0, kRoundoff) << "element " << e;
    }
  }
}

TEST(SurfaceFieldEvaluate, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(test::kSeed + 303);
  for (const mesh::SurfaceMesh& m : {rectangle(), disk()}) {
    const SurfaceField f(m, random_parameters(m.n_dofs(), 2, rng));
    std::uniform_real_distribution<double> u(0.05, 0.95);
    for (Index e = 0; e < m.n_elements(); ++e)
      for (int q = 0; q < 3; ++q) {
        const Vec2 xi(u(rng), u(rng));
        const FieldPoint p = f.evaluate(e, xi, kAll);
        for (int i = 0; i < 2; ++i) {
          const Vec2 h = kFdStep * Vec2::Unit(i);
          const FieldPoint pp = f.evaluate(e, xi + h, kAll), pm = f.evaluate(e, xi - h, kAll);
          // Columns of the second derivatives for (i, j): 11 -> 0, 12 -> 1, 22 -> 2.
          for (int c = 0; c < 2; ++c) {
            EXPECT_NEAR(p.first(c, i), (pp.value[c] - pm.value[c]) / (2 * kFdStep), kFdFirst)
                << "u" << c << ",xi" << i + 1 << ", " << where(e, xi);
            for (int j = 0; j < 2; ++j)
              EXPECT_NEAR(p.second(c, i + j), (pp.first(c, j) - pm.first(c, j)) / (2 * kFdStep), kFdFirst)
                  << "u" << c << ",xi" << i + 1 << "xi" << j + 1 << ", " << where(e, xi);
          }
        }
      }
  }
}

// ---------------------------------------------------------------------------
// Global basis rows and element dof maps.

double pick(const FieldPoint& p, int which) {
  switch (which) {
    case 0:
      return p.value[0];
    case 1:
      return p.first(0, 0);
    case 2:
      return p.first(0, 1);
    default:
      return p.second(0, which - 3);
  }
}

void check_global_basis_rows(const mesh::SurfaceMesh& m, unsigned seed, bool collapsed_only) {
  std::mt19937 rng(seed);
  const MatX params = random_parameters(m.n_dofs(), 1, rng);
  const SurfaceField f(m, params);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int checked = 0;
  for (Index e = 0; e < m.n_elements(); ++e) {
    if (collapsed_only && m.element(e).shape != mesh::ElementShape::kCollapsed) continue;
    const mesh::ElementMap map = m.element_map(e);
    for (int q = 0; q < 4; ++q) {
      const Vec2 xi = q == 0 ? Vec2(u(rng), 0.0) : Vec2(u(rng), u(rng));  // include the apex edge
      const auto b = basis::BicubicHermite::evaluate(xi, kAll);
      const FieldPoint p = f.evaluate(e, xi, kAll);
      for (int which = 0; which < 6; ++which) {
        const GlobalBasisRow row = global_basis_row(map, b, which);
        ASSERT_EQ(row.dofs.size(), row.coefs.size());
        const std::set<Index> distinct(row.dofs.begin(), row.dofs.end());
        EXPECT_EQ(distinct.size(), row.dofs.size()) << "duplicate dofs are merged, " << where(e, xi);
        double sum = 0.0;
        for (std::size_t j = 0; j < row.dofs.size(); ++j) {
          ASSERT_GE(row.dofs[j], 0);
          ASSERT_LT(row.dofs[j], m.n_dofs());
          sum += row.coefs[j] * params(row.dofs[j], 0);
        }
        EXPECT_NEAR(sum, pick(p, which), kRoundoff) << "which=" << which << ", " << where(e, xi);
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

TEST(SurfaceFieldGlobalBasis, RowReproducesEvaluationOnQuads) {
  check_global_basis_rows(rectangle(), test::kSeed + 310, false);
}

TEST(SurfaceFieldGlobalBasis, RowReproducesEvaluationOnCollapsedElements) {
  check_global_basis_rows(disk(), test::kSeed + 311, true);
}

TEST(SurfaceFieldGlobalBasis, RowReproducesEvaluationOnTheWholeDisk) {
  check_global_basis_rows(disk(), test::kSeed + 312, false);
}

TEST(SurfaceFieldElementDofMap, ReproducesElementParameters) {
  std::mt19937 rng(test::kSeed + 320);
  for (const mesh::SurfaceMesh& m : {rectangle(), disk()}) {
    const MatX params = random_parameters(m.n_dofs(), 3, rng);
    for (Index e = 0; e < m.n_elements(); ++e) {
      const ElementDofMap map = element_dof_map(m.element_map(e));
      const bool collapsed = m.element(e).shape == mesh::ElementShape::kCollapsed;
      // Quad: 4 nodes x 4 parameters. Collapsed: apex value, D1, D2 (no cross) + 2 x 4.
      EXPECT_EQ(map.dofs.size(), collapsed ? 11u : 16u) << "element " << e;
      const std::set<Index> distinct(map.dofs.begin(), map.dofs.end());
      EXPECT_EQ(distinct.size(), map.dofs.size()) << "distinct dofs, element " << e;
      ASSERT_EQ(map.t.rows(), 16);
      ASSERT_EQ(map.t.cols(), static_cast<Index>(map.dofs.size()));
      MatX local(map.dofs.size(), 3);
      for (std::size_t j = 0; j < map.dofs.size(); ++j) local.row(j) = params.row(map.dofs[j]);
      const MatX ue = map.t * local;
      const MatX expected = m.element_parameters(e, params);
      for (int k = 0; k < 16; ++k)
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(ue(k, c), expected(k, c), kRoundoff)
              << "element " << e << " parameter " << k << " component " << c;
      if (collapsed) {
        const Index apex_cross = mesh::SurfaceMesh::dof(m.element(e).nodes[0], mesh::kD12);
        EXPECT_EQ(std::count(map.dofs.begin(), map.dofs.end(), apex_cross), 0)
            << "apex cross parameter is not an element dof, element " << e;
      }
    }
  }
}

TEST(SurfaceFieldElementDofMap, AgreesWithGlobalBasisRows) {
  // row(which) = N_which^T T, dof by dof.
  std::mt19937 rng(test::kSeed + 321);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const mesh::SurfaceMesh& m : {rectangle(), disk()})
    for (Index e = 0; e < m.n_elements(); ++e) {
      const mesh::ElementMap emap = m.element_map(e);
      const ElementDofMap dmap = element_dof_map(emap);
      const Vec2 xi(u(rng), u(rng));
      const auto b = basis::BicubicHermite::evaluate(xi, kAll);
      for (int which = 0; which < 6; ++which) {
        Eigen::Matrix<double, 16, 1> n;
        if (which == 0)
          n = b.value;
        else if (which <= 2)
          n = b.first.col(which - 1);
        else
          n = b.second.col(which - 3);
        const Eigen::RowVectorXd expected = n.transpose() * dmap.t;
        const GlobalBasisRow row = global_basis_row(emap, b, which);
        for (std::size_t j = 0; j < dmap.dofs.size(); ++j) {
          const auto it = std::find(row.dofs.begin(), row.dofs.end(), dmap.dofs[j]);
          const double coef = it == row.dofs.end() ? 0.0 : row.coefs[it - row.dofs.begin()];
          EXPECT_NEAR(coef, expected[j], kRoundoff)
              << "dof " << dmap.dofs[j] << ", which=" << which << ", " << where(e, xi);
        }
        for (Index d : row.dofs)
          EXPECT_NE(std::find(dmap.dofs.begin(), dmap.dofs.end(), d), dmap.dofs.end())
              << "row dof " << d << " is an element dof, " << where(e, xi);
      }
    }
}

}  // namespace
}  // namespace sf::fe

// Which linear path a Newton tangent takes, and that keeping the symbolic analysis
// across a contact pattern that grows gives the solution of a fresh analysis:
//  * two stacked plies in frictionless penalty contact: the assembled tangent is
//    symmetric, the model says so, the workspace stores the lower triangle and CHOLMOD's
//    Cholesky factorises it; with viscous inter-ply friction the tangent is unsymmetric,
//    both triangles are stored and UMFPACK's LU does the work;
//  * a pattern laid out before contact closes grows by the contact entries (flush) and
//    the kept solver re-analyses once; the next factorisations keep that analysis and
//    solve exactly as a fresh pattern with a fresh analysis does.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "common/linalg/solver.hpp"
#include "forming/contact/body_contact.hpp"
#include "forming/model/model.hpp"
#include "forming/solve/tangent_solver.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

// Two 10 x 10 mm plies of 3 x 3 bricks, 0.5 mm thick, the upper on the lower, contact
// of the lower's top with the upper's bottom (penalty 100 N/mm^3), viscous friction
// c_f (0: none).
Model stacked_plies(double viscous) {
  Model model;
  const auto law = fixtures::neo_hookean(10.0, 10.0);
  for (int k = 0; k < 2; ++k)
    model.add_ply(
        PlyMesh(mesh::make_rectangle_mesh(Vec3(0, 0, 0.5 * k), Vec3::UnitX(), Vec3::UnitY(), 10.0, 10.0, 3, 3), 0.5,
                0.0),
        law);
  ContactOptions o;
  o.normal.stiffness = 100.0;
  o.friction.viscous = viscous;
  o.points = 3;
  model.add_interaction(std::make_shared<BodyContact>("interface", model, ContactSurface::whole_face(model, 0, true),
                                                      ContactSurface::whole_face(model, 1, false), o));
  return model;
}

// Positions with the upper ply pressed `press` mm into the lower and slid `slide` mm in x,
// and the context of a quasi-static step of 0.1 s from the reference.
struct State {
  VecX x, previous;
  InteractionContext context;
};
State pressed(const Model& model, double press, double slide = 0.01) {
  State s;
  s.previous = model.reference_positions();
  s.x = s.previous;
  const Index half = model.n_dofs() / 2;  // the upper ply's dofs come second, same layout
  // Translate the upper ply: only its position parameters move, which are the entries
  // where the two plies' reference parameters differ by the 0.5 mm of the stacking.
  for (Index d = 0; d < half; ++d) {
    const double dz = s.previous(half + d) - s.previous(d);
    if (d % 3 == 2 && std::abs(dz - 0.5) < 1e-12) s.x(half + d) -= press;
    if (d % 3 == 0 && std::abs(dz - 0.5) < 1e-12 &&
        std::abs(s.previous(half + d + 2) - s.previous(d + 2) - 0.5) < 1e-12)
      s.x(half + d) += slide;
  }
  s.context.previous = &s.previous;
  s.context.previous_time = 0.0;
  s.context.time = 0.1;
  return s;
}

// The first quarter of each ply's parameters held: both plies clamped along some nodes,
// so K_ff is regular with or without contact.
std::vector<bool> free_dofs(const Model& model) {
  std::vector<bool> is_free = model.used_dofs();
  const Index half = model.n_dofs() / 2;
  for (Index d = 0; d < half / 4; ++d) {
    is_free[static_cast<std::size_t>(d)] = false;
    is_free[static_cast<std::size_t>(half + d)] = false;
  }
  return is_free;
}

double asymmetry(const linalg::SparseMatrix& k) {
  const linalg::SparseMatrix kt = k.transpose();
  return (k - kt).norm() / k.norm();
}

TEST(FormingTangentPath, FrictionlessContactTakesTheSymmetricPathFrictionTheLu) {
  for (const double viscous : {0.0, 0.05}) {
    SCOPED_TRACE(viscous);
    const Model model = stacked_plies(viscous);
    const State s = pressed(model, 0.002);
    // The tangent itself (both triangles over every dof).
    const Assembly a = model.assemble(s.x, s.context, true);
    ASSERT_TRUE(a.ok) << a.message;
    const double asym = asymmetry(a.tangent);
    std::printf("[ measured ] viscous %.2f: |K - K^T| / |K| = %.3e, symmetric_tangent %d\n", viscous, asym,
                model.symmetric_tangent() ? 1 : 0);
    TangentWorkspace w;
    w.prepare(model, free_dofs(model), linalg::SolverKind::kAuto, !model.symmetric_tangent());
    ASSERT_TRUE(model.assemble_into(s.x, s.context, &w.pattern()).ok);
    const linalg::SolveReport& r = w.solver().factorize(w.pattern().matrix());
    ASSERT_TRUE(r.ok()) << r.brief();
    if (viscous == 0.0) {
      EXPECT_LT(asym, 1e-12);
      EXPECT_TRUE(model.symmetric_tangent());
      EXPECT_TRUE(w.solver().lower());
      EXPECT_EQ(r.used, linalg::SolverKind::kCholmod) << r.brief();
    } else {
      EXPECT_GT(asym, 1e-6);  // the friction tangent is genuinely unsymmetric
      EXPECT_FALSE(model.symmetric_tangent());
      EXPECT_FALSE(w.solver().lower());
      // MUMPS's LU where it is built in (UMFPACK behind it), else UMFPACK's.
      EXPECT_EQ(r.used, linalg::solver_available(linalg::SolverKind::kMumps) ? linalg::SolverKind::kMumps
                                                                             : linalg::SolverKind::kUmfpack)
          << r.brief();
    }
  }
}

TEST(FormingTangentPath, GrownPatternWithKeptAnalysisSolvesAsAFreshOne) {
  for (const double viscous : {0.0, 0.05}) {
    SCOPED_TRACE(viscous);
    const Model model = stacked_plies(viscous);
    const std::vector<bool> is_free = free_dofs(model);
    const bool unsym = !model.symmetric_tangent();
    // Kept: laid out and factorised with the plies apart (no contact entries), then with
    // contact closed (the pattern grows, one re-analysis), then at a second contact state
    // (slid further: other values, the same pairs; analysis kept).
    TangentWorkspace kept;
    kept.prepare(model, is_free, linalg::SolverKind::kAuto, unsym);
    // (The layout for the Cholesky, TangentSolver::lay_out, moves entries too: a generation.)
    const int laid_out = kept.pattern().generation();
    State apart = pressed(model, -1.5);  // 1.5 mm above: beyond the search reach
    ASSERT_TRUE(model.assemble_into(apart.x, apart.context, &kept.pattern()).ok);
    const Index nnz_apart = kept.pattern().matrix().nonZeros();
    ASSERT_TRUE(kept.solver().factorize(kept.pattern().matrix()).ok());
    const State s1 = pressed(model, 0.002), s2 = pressed(model, 0.002, 0.02);
    ASSERT_TRUE(model.assemble_into(s1.x, s1.context, &kept.pattern()).ok);
    EXPECT_GT(kept.pattern().matrix().nonZeros(), nnz_apart);  // contact grew the pattern
    EXPECT_EQ(kept.pattern().generation(), laid_out + 1);
    const linalg::SolveReport r1 = kept.solver().factorize(kept.pattern().matrix());
    ASSERT_TRUE(r1.ok()) << r1.brief();
    EXPECT_FALSE(r1.reused_analysis);
    const int grown = kept.pattern().generation();  // (and laid out again for the Cholesky)
    ASSERT_TRUE(model.assemble_into(s2.x, s2.context, &kept.pattern()).ok);
    EXPECT_EQ(kept.pattern().generation(), grown);  // same contact pairs: no growth
    const linalg::SolveReport r2 = kept.solver().factorize(kept.pattern().matrix());
    ASSERT_TRUE(r2.ok()) << r2.brief();
    EXPECT_TRUE(r2.reused_analysis) << r1.brief() << " | " << r2.brief();
    const VecX b = VecX::LinSpaced(kept.pattern().n_active(), -1.0, 2.0);
    const VecX x_kept = kept.solver().solve(b);
    // Fresh: pattern laid out and analysed at s2 directly.
    TangentWorkspace fresh;
    fresh.prepare(model, is_free, linalg::SolverKind::kAuto, unsym);
    ASSERT_TRUE(model.assemble_into(s2.x, s2.context, &fresh.pattern()).ok);
    ASSERT_TRUE(fresh.solver().factorize(fresh.pattern().matrix()).ok());
    const VecX x_fresh = fresh.solver().solve(b);
    const double diff = (x_kept - x_fresh).norm() / x_fresh.norm();
    std::printf("[ measured ] viscous %.2f: kept against fresh analysis, relative difference %.3e\n", viscous, diff);
    EXPECT_LT(diff, 1e-10);
  }
}

}  // namespace
}  // namespace sf::forming

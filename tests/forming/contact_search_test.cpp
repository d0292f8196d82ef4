// Tests of the contact search pieces (forming/contact/box_tree.hpp,
// forming/contact/contact_surface.hpp, forming/contact/face_projection.hpp):
//  * the box tree returns exactly the boxes a brute-force scan finds, for random boxes
//    and points, with and without a margin;
//  * a face's Bezier box holds every point of the face (sampled densely) of a curved,
//    perturbed ply;
//  * the projection on a face finds the closest point: the residual r = p - x(zeta) is
//    normal to the face at an interior foot, and no sampled face point is closer.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "forming/contact/box_tree.hpp"
#include "forming/contact/contact_surface.hpp"
#include "forming/contact/face_projection.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

TEST(BoxTree, FindsExactlyTheBoxesABruteForceScanFinds) {
  std::mt19937 rng(test::kSeed + 31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Box> boxes;
  for (int i = 0; i < 500; ++i) {
    const Vec3 c(100 * u(rng), 100 * u(rng), 10 * u(rng));
    const Vec3 h(5 * u(rng), 5 * u(rng), 1 * u(rng));
    Box b;
    b.add(c - h);
    b.add(c + h);
    boxes.push_back(b);
  }
  const BoxTree tree(boxes);
  EXPECT_EQ(tree.n_boxes(), 500);
  std::vector<Index> hits;
  int total = 0;
  for (int q = 0; q < 2000; ++q) {
    const Vec3 p(100 * u(rng), 100 * u(rng), 10 * u(rng));
    const double margin = q % 2 ? 0.0 : 2.0;
    tree.query(p, margin, hits);
    std::vector<Index> brute;
    for (Index i = 0; i < 500; ++i)
      if (boxes[static_cast<std::size_t>(i)].contains(p, margin)) brute.push_back(i);
    std::sort(hits.begin(), hits.end());
    ASSERT_EQ(hits, brute) << "query " << q;
    total += static_cast<int>(hits.size());
  }
  EXPECT_GT(total, 100);  // the queries did hit boxes
}

// A 3 x 2 ply, every dof perturbed: curved faces.
struct Curved {
  Model model;
  VecX x;
};

Curved curved_ply() {
  Curved c;
  c.model.add_ply(fixtures::rectangle_ply(9.0, 6.0, 1.0, 3, 2), fixtures::neo_hookean(1.0, 1.0));
  c.x = c.model.reference_positions();
  std::mt19937 rng(test::kSeed + 32);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index i = 0; i < c.x.size(); ++i) c.x(i) += 0.3 * u(rng);
  return c;
}

Vec3 face_point(const FaceBasis& b, const MatX& pos, double s, double t) {
  const FaceBasisValues v = b.evaluate(s, t, false);
  Vec3 x = Vec3::Zero();
  for (int a = 0; a < v.n; ++a) x += v.value[static_cast<std::size_t>(a)] * pos.row(a).transpose();
  return x;
}

TEST(ContactSurface, BezierBoxesHoldTheirFacesTopBottomAndSides) {
  const Curved c = curved_ply();
  std::vector<std::pair<Index, BrickFace>> faces;
  for (Index e = 0; e < 6; ++e)
    for (BrickFace f : {BrickFace::kTop, BrickFace::kBottom, BrickFace::kXi1Min, BrickFace::kXi1Max, BrickFace::kXi2Min,
                        BrickFace::kXi2Max})
      faces.emplace_back(e, f);
  const ContactSurface s(c.model, 0, faces);
  for (Index f = 0; f < s.n_faces(); ++f) {
    const MatX pos = s.positions(f, c.x);
    const Box box = face_box(s.basis(f), pos);
    for (int j = 0; j <= 20; ++j)
      for (int i = 0; i <= 20; ++i) {
        const Vec3 p = face_point(s.basis(f), pos, i / 20.0, j / 20.0);
        ASSERT_TRUE(box.contains(p, 1e-12)) << "face " << f << " at " << i << "," << j;
      }
  }
}

TEST(FaceProjection, FindsTheClosestPointOfACurvedFace) {
  const Curved c = curved_ply();
  const ContactSurface s = ContactSurface::whole_face(c.model, 0, true);
  std::mt19937 rng(test::kSeed + 33);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int interior = 0;
  for (Index f = 0; f < s.n_faces(); ++f) {
    const MatX pos = s.positions(f, c.x);
    for (int q = 0; q < 20; ++q) {
      const Vec3 on = face_point(s.basis(f), pos, 0.1 + 0.8 * u(rng), 0.1 + 0.8 * u(rng));
      const Vec3 p = on + Vec3(0.3 * (u(rng) - 0.5), 0.3 * (u(rng) - 0.5), 0.4 * (u(rng) - 0.5));
      const FaceFoot foot = project_on_face(s.basis(f), pos, p);
      ASSERT_TRUE(foot.converged);
      const Vec3 r = p - foot.x;
      if (foot.exit_edge < 0 && foot.zeta.minCoeff() > 0.0 && foot.zeta.maxCoeff() < 1.0) {
        ++interior;
        EXPECT_LT(std::abs(r.dot(foot.x1)) / foot.x1.norm(), 1e-10);
        EXPECT_LT(std::abs(r.dot(foot.x2)) / foot.x2.norm(), 1e-10);
      }
      double nearest = 1e300;
      for (int j = 0; j <= 40; ++j)
        for (int i = 0; i <= 40; ++i)
          nearest = std::min(nearest, (p - face_point(s.basis(f), pos, i / 40.0, j / 40.0)).norm());
      EXPECT_LE(foot.distance, nearest + 1e-12);
    }
  }
  EXPECT_GT(interior, 60);
}

}  // namespace
}  // namespace sf::forming

// Labels across views (gsa/digitise/match.hpp): the symmetry group of the labels, recovery of
// a view's turn and shift by epipolar geometry, and the refusals: an ambiguous shift along
// the baseline without a reference mark, and a calibration that does not fit.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <set>

#include "gsa/digitise/match.hpp"

namespace sf::gsa::digitise {
namespace {

using ::testing::HasSubstr;

// Two cameras over a flat 21 x 21 grid of 5 mm; baseline at `baseline_deg` to the grid.
struct TwoViews {
  Camera c0, c1;
  ViewMarks v0, v1;
};

Camera camera_at(const Vec3& pos) {
  Camera c;
  c.width = 1600;
  c.height = 1200;
  c.fx = c.fy = 2400;
  c.cx = 800;
  c.cy = 600;
  const Vec3 z = (Vec3(0, 0, 0) - pos).normalized();
  const Vec3 down(0, -1, 0);
  const Vec3 y = (down - down.dot(z) * z).normalized();
  const Vec3 x = y.cross(z);
  c.R.row(0) = x;
  c.R.row(1) = y;
  c.R.row(2) = z;
  c.t = -c.R * pos;
  return c;
}

TwoViews two_views(double baseline_deg, int symmetry_of_view1, const Label& shift_of_view1, bool reference) {
  TwoViews s;
  const double a = baseline_deg * kPi / 180;
  s.c0 = camera_at(Vec3(100 * std::cos(a), 100 * std::sin(a), 420));
  s.c1 = camera_at(Vec3(-100 * std::cos(a), -100 * std::sin(a), 420));
  LabelTransform t1 = LabelTransform::identity(Vec2::Zero());
  t1.symmetry = symmetry_of_view1;
  for (ViewMarks* v : {&s.v0, &s.v1}) v->has_reference = reference;
  for (int j = -10; j <= 10; ++j)
    for (int i = -10; i <= 10; ++i) {
      const Vec3 X(5.0 * i, -5.0 * j, 0.0);
      s.v0.centres.push_back(s.c0.project(X));
      s.v0.labels.push_back(Label(i, j));
      s.v1.centres.push_back(s.c1.project(X));
      // View 1 labels the same mark L as t1(L) + shift; match_view must find the inverse.
      s.v1.labels.push_back(t1.apply(Label(i, j)) + shift_of_view1);
    }
  return s;
}

TEST(DigitiseMatch, RecoversATurnedAndShiftedView) {
  {  // transforms form the squares symmetry group
    for (const Vec2& r : {Vec2(0, 0), Vec2(0.5, 0.5)}) {
      for (int s = 0; s < 8; ++s) {
        LabelTransform t = LabelTransform::identity(r);
        t.symmetry = s;
        // The reference stays where it is; distances between labels are kept.
        const Label a(3, -2), b(-1, 4);
        EXPECT_EQ((t.apply(a) - t.apply(b)).squaredNorm(), (a - b).squaredNorm());
        if (r == Vec2(0.5, 0.5)) {
          // The four corners of the reference cell map onto themselves.
          std::set<std::pair<int, int>> corners;
          for (const Label& l : {Label(0, 0), Label(1, 0), Label(0, 1), Label(1, 1)})
            corners.insert({t.apply(l).x(), t.apply(l).y()});
          EXPECT_EQ(corners, (std::set<std::pair<int, int>>{{0, 0}, {1, 0}, {0, 1}, {1, 1}}));
        } else {
          EXPECT_EQ(t.apply(Label(0, 0)), Label(0, 0));
        }
      }
    }
    LabelTransform quarter = LabelTransform::identity(Vec2::Zero());
    quarter.symmetry = 1;
    Label l(2, 1);
    for (int k = 0; k < 4; ++k) l = quarter.apply(l);
    EXPECT_EQ(l, Label(2, 1));  // four quarter turns
  }
  {  // recovers aturned and shifted view
    for (int sym : {0, 1, 2, 3}) {
      const TwoViews s = two_views(20, sym, Label(3, -2), false);
      const MatchResult m = match_view(s.c0, s.v0, s.c1, s.v1);
      ASSERT_TRUE(m.ok) << m.message;
      for (std::size_t k = 0; k < s.v1.labels.size(); ++k)
        EXPECT_EQ(m.transform.apply(s.v1.labels[k]), s.v0.labels[k]) << "symmetry " << sym;
      EXPECT_EQ(m.n_consistent, 441);
    }
  }
}

TEST(DigitiseMatch, RefusesAmbiguousShiftsAndWrongCalibrations) {
  {  // ashift along the baseline is ambiguous without areference
    // Baseline along the grid's i axis: every shift along i keeps the marks on their
    // epipolar lines (up to the lines' convergence), so the view cannot be labelled.
    const TwoViews s = two_views(0, 0, Label(0, 0), false);
    const MatchResult m = match_view(s.c0, s.v0, s.c1, s.v1);
    EXPECT_FALSE(m.ok);
    EXPECT_THAT(m.message, HasSubstr("ambiguous"));
    // The same with the reference mark seen by both: fine.
    const TwoViews r = two_views(0, 0, Label(0, 0), true);
    const MatchResult mr = match_view(r.c0, r.v0, r.c1, r.v1);
    EXPECT_TRUE(mr.ok) << mr.message;
  }
  {  // acalibration that does not fit is reported
    const TwoViews s = two_views(20, 0, Label(0, 0), true);
    Camera wrong = s.c1;
    // Turned by 3 degrees about its axis: marks move up to 17 px off their epipolar lines.
    wrong.R = Eigen::AngleAxisd(0.05, Vec3::UnitZ()).toRotationMatrix() * wrong.R;
    const MatchResult m = match_view(s.c0, s.v0, wrong, s.v1);
    EXPECT_FALSE(m.ok);
    EXPECT_THAT(m.message, HasSubstr("calibration"));
  }
}

}  // namespace
}  // namespace sf::gsa::digitise

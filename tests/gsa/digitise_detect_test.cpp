// Marks in one image (gsa/digitise/detect.hpp), on rendered photographs with noise, blur
// and uneven lighting: every mark found and labelled right, centres against the exact
// projected geometry (the dot's projected area centroid, the projected junction), partly
// hidden and cut marks dropped with a reason, and bad images refused with a message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/core/error.hpp"
#include "gsa/digitise/detect.hpp"
#include "gsa/digitise/triangulate.hpp"
#include "tests/common/io_test_util.hpp"
#include "tests/gsa/digitise_test_util.hpp"

namespace sf::gsa::digitise {
namespace {

using test::tol::kDotCentreRmsPx;
using test::tol::kJunctionRmsPx;
using test::tol::kMarkMaxPx;
using ::testing::HasSubstr;

struct Check {
  Index n = 0, wrong = 0;
  double rms = 0, max = 0;
};

// Each labelled mark against where the exact geometry puts it in camera `cam`.
Check check(const ViewMarks& v, const Camera& cam, const synth::Scene& sc, synth::PatternKind marks) {
  const auto truth = test::truth_map(sc);
  Check c;
  double ss = 0;
  for (std::size_t k = 0; k < v.centres.size(); ++k) {
    const auto it = truth.find(test::material_index(v.labels[k], marks));
    if (it == truth.end()) {
      ++c.wrong;
      continue;
    }
    const Vec2 m(it->second.i * sc.pattern.pitch, it->second.j * sc.pattern.pitch);
    Vec2 expected = cam.project(it->second.position);
    if (marks == synth::PatternKind::kDots) {
      const bool ref = it->second.i == 0 && it->second.j == 0;
      const double r = 0.5 * (ref ? sc.pattern.reference_diameter : sc.pattern.dot_diameter);
      // The centroid of the projected dot (the dot is stretched on a formed part: use the
      // exact outline through the sheet map rather than a disc).
      std::vector<Vec2> poly;
      for (int q = 0; q < 180; ++q) {
        const double t = 2 * kPi * q / 180;
        poly.push_back(cam.project(sc.sheet.position(m + r * Vec2(std::cos(t), std::sin(t)))));
      }
      double A = 0;
      Vec2 C = Vec2::Zero();
      for (std::size_t q = 0; q < poly.size(); ++q) {
        const Vec2 a = poly[q] - poly[0], b = poly[(q + 1) % poly.size()] - poly[0];
        const double cr = a.x() * b.y() - a.y() * b.x();
        A += cr;
        C += cr * (a + b);
      }
      expected = poly[0] + C / (3.0 * A);
    }
    const double e = (v.centres[k] - expected).norm();
    if (e > 2.0) {
      ++c.wrong;
      continue;
    }
    ++c.n;
    ss += e * e;
    c.max = std::max(c.max, e);
  }
  c.rms = c.n ? std::sqrt(ss / c.n) : 0;
  return c;
}

TEST(DigitiseDetect, DotsOnTheBlankAndTheDomeAreAllFoundLabelledAndCentred) {
  const auto o = test::small_example();
  const Rig rig = test::true_rig(o);
  for (synth::SheetShape shape : {synth::SheetShape::kFlat, synth::SheetShape::kDome}) {
    const synth::Scene sc = synth::example_part(o, shape);
    const GreyImage img = synth::render(rig.cameras[0], sc, o.effects);
    const ViewMarks v = find_marks(img, "view", DetectOptions{});
    EXPECT_TRUE(v.has_reference);
    EXPECT_EQ(v.centres.size(), 961u) << "shape " << static_cast<int>(shape);
    const Check c = check(v, rig.cameras[0], sc, o.marks);
    EXPECT_EQ(c.wrong, 0);
    EXPECT_LT(c.rms, kDotCentreRmsPx) << "shape " << static_cast<int>(shape);
    EXPECT_LT(c.max, kMarkMaxPx);
  }
}

TEST(DigitiseDetect, EllipseCentresAreCloseToo) {
  const auto o = test::small_example();
  const Rig rig = test::true_rig(o);
  const synth::Scene sc = synth::example_part(o, synth::SheetShape::kFlat);
  DetectOptions d;
  d.centre = CentreMethod::kEllipse;
  const ViewMarks v = find_marks(synth::render(rig.cameras[1], sc, o.effects), "view", d);
  const Check c = check(v, rig.cameras[1], sc, o.marks);
  EXPECT_EQ(c.wrong, 0);
  EXPECT_LT(c.rms, 2 * kDotCentreRmsPx);  // edge points at half contrast: measured 0.02 px
}

TEST(DigitiseDetect, LineJunctionsOnTheBendAreLabelledAndCentred) {
  const auto o = test::small_example(synth::PatternKind::kLines);
  const Rig rig = test::true_rig(o);
  const synth::Scene sc = synth::example_part(o, synth::SheetShape::kBend);
  DetectOptions d;
  d.kind = MarkKind::kLines;
  const ViewMarks v = find_marks(synth::render(rig.cameras[0], sc, o.effects), "view", d);
  EXPECT_TRUE(v.has_reference);
  EXPECT_EQ(v.reference_lattice, Vec2(0.5, 0.5));
  EXPECT_GT(v.centres.size(), 850u);  // junctions on the steepest edge columns may be dropped
  const Check c = check(v, rig.cameras[0], sc, o.marks);
  EXPECT_EQ(c.wrong, 0);
  EXPECT_LT(c.rms, kJunctionRmsPx);
  EXPECT_LT(c.max, kMarkMaxPx);
}

TEST(DigitiseDetect, PartlyHiddenAndCutDotsAreDroppedWithAReason) {
  auto o = test::small_example();
  o.occlusion = true;
  const Rig rig = test::true_rig(o);
  const synth::Scene sc = synth::example_part(o, synth::SheetShape::kDome);
  const ViewMarks v = find_marks(synth::render(rig.cameras[0], sc, o.effects), "view", DetectOptions{});
  const Check c = check(v, rig.cameras[0], sc, o.marks);
  EXPECT_EQ(c.wrong, 0);
  EXPECT_LT(c.max, kMarkMaxPx);  // no biased centre of a partial dot gets through
  // Marks lost to the flap and the trimmed corner: fewer than 961 but most of them kept.
  EXPECT_LT(v.centres.size(), 940u);
  EXPECT_GT(v.centres.size(), 900u);
  bool edge_or_hidden = false, cut = false;
  for (const Rejection& r : v.rejected) {
    edge_or_hidden = edge_or_hidden || r.reason.find("uneven sheet") != std::string::npos ||
                     r.reason.find("partly hidden") != std::string::npos;
    cut = cut || r.reason.find("area") != std::string::npos || r.reason.find("outline") != std::string::npos;
  }
  EXPECT_TRUE(edge_or_hidden);
  EXPECT_TRUE(cut);
}

TEST(DigitiseDetect, LightMarksAndSeedsWithoutAReference) {
  {  // light marks on adark sheet
    const auto o = test::small_example();
    const Rig rig = test::true_rig(o);
    const synth::Scene sc = synth::example_part(o, synth::SheetShape::kFlat);
    GreyImage img = synth::render(rig.cameras[0], sc, o.effects);
    for (float& p : img.pixels) p = 1.0f - p;
    DetectOptions d;
    d.dark_marks = false;
    const ViewMarks v = find_marks(img, "negative", d);
    EXPECT_EQ(v.centres.size(), 961u);
    EXPECT_EQ(check(v, rig.cameras[0], sc, o.marks).wrong, 0);
  }
  {  // without areference the seed pixel decides the origin
    auto o = test::small_example();
    o.reference = false;
    const Rig rig = test::true_rig(o);
    const synth::Scene sc = synth::example_part(o, synth::SheetShape::kFlat);
    DetectOptions d;
    d.seed = rig.cameras[0].project(sc.sheet.position(Vec2(10, -5))) + Vec2(2, -1);  // mark (2, -1), a bit off
    const ViewMarks v = find_marks(synth::render(rig.cameras[0], sc, o.effects), "view", d);
    EXPECT_FALSE(v.has_reference);
    // Labels relative to the seed mark: material (I, J) = (i + 2, -j - 1).
    const auto truth = test::truth_map(sc);
    Index wrong = 0;
    for (std::size_t k = 0; k < v.centres.size(); ++k) {
      const auto it = truth.find({v.labels[k].x() + 2, -v.labels[k].y() - 1});
      if (it == truth.end() || (rig.cameras[0].project(it->second.position) - v.centres[k]).norm() > 0.5) ++wrong;
    }
    EXPECT_EQ(wrong, 0);
    DetectOptions far = d;
    far.seed = Vec2(3, 3);  // a corner of the image, no mark near
    EXPECT_THAT(io::test::message_of<InputError>(
                    [&] { find_marks(synth::render(rig.cameras[0], sc, o.effects), "view.png", far); }),
                HasSubstr("--seed"));
  }
}

TEST(DigitiseDetect, BadImagesAndOptionsAreRefused) {
  {  // images without agrid are refused with the image name
    const GreyImage blank(640, 480, 0.6f);
    EXPECT_THAT(io::test::message_of<InputError>([&] { find_marks(blank, "blank.png", DetectOptions{}); }),
                HasSubstr("blank.png"));
    // A handful of dots only.
    GreyImage few(640, 480, 0.8f);
    for (int k = 0; k < 4; ++k)
      for (int y = -4; y <= 4; ++y)
        for (int x = -4; x <= 4; ++x)
          if (x * x + y * y <= 16) few.at(100 + 100 * k + x, 200 + y) = 0.1f;
    EXPECT_THAT(io::test::message_of<InputError>([&] { find_marks(few, "few.png", DetectOptions{}); }),
                HasSubstr("few.png"));
  }
  {  // options out of range name the option
    DetectOptions d;
    d.threshold = 1.5;
    EXPECT_THAT(io::test::message_of<UsageError>([&] { d.validate(); }), HasSubstr("--threshold"));
  }
}

}  // namespace
}  // namespace sf::gsa::digitise

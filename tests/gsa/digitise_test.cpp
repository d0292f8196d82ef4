// From rendered photographs to 3-D grid marks and grid files (gsa/digitise/digitise.hpp),
// with the exact cameras: positions against the exact marks, zero mislabels, the reports of
// hidden and cut marks, three cameras without a reference mark, and refusal of a
// calibration or image set that does not belong.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "gsa/digitise/digitise.hpp"
#include "gsa/digitise/image.hpp"
#include "tests/common/io_test_util.hpp"
#include "tests/gsa/digitise_test_util.hpp"

namespace sf::gsa::digitise {
namespace {

using test::tol::kMarkMax3dMm;
using test::tol::kMarkRms3dMm;
using ::testing::AllOf;
using ::testing::HasSubstr;

TEST(Digitise, BlankAndDomeFromTwoViewsToAGridFile) {
  const auto o = test::small_example();
  const Rig rig = test::true_rig(o);
  const synth::Scene flat = synth::example_part(o, synth::SheetShape::kFlat);
  const synth::Scene dome = synth::example_part(o, synth::SheetShape::kDome);
  const auto flat_images = test::render_set(rig, flat, o.effects, 3);
  const auto dome_images = test::render_set(rig, dome, o.effects, 5);
  const SetResult u = digitise_set(rig, flat_images, DigitiseOptions{});
  const SetResult d = digitise_set(rig, dome_images, DigitiseOptions{});
  for (const auto& [s, sc] : {std::pair<const SetResult*, const synth::Scene*>{&u, &flat}, {&d, &dome}}) {
    const synth::Comparison c = synth::compare_marks(s->marks, *sc, o.marks);
    EXPECT_EQ(c.mislabelled, 0);
    EXPECT_EQ(c.n, 961) << "every visible mark";
    EXPECT_LT(c.rms, kMarkRms3dMm);
    EXPECT_LT(c.max, kMarkMax3dMm);
    EXPECT_TRUE(s->has_reference);
    EXPECT_GT(s->dot_diameter_mm, 1.9);  // measured from the images: 2 mm printed
    EXPECT_LT(s->dot_diameter_mm, 2.3);  // (2.1 stretched on the dome)
    EXPECT_LT(s->rms_px, 0.05);
  }
  // The perspective-bias correction brings the dome's marks closer to the truth (measured
  // 0.0062 against 0.0071 mm RMS).
  DigitiseOptions raw;
  raw.bias_correction = false;
  EXPECT_LT(synth::compare_marks(d.marks, dome, o.marks).rms,
            synth::compare_marks(digitise_set(rig, dome_images, raw).marks, dome, o.marks).rms);

  // The grid file: both states joined, each in its grid frame.
  const Vec3 eye = rig.cameras[0].centre();
  const std::vector<GridRow> rows = join_sets(&u, grid_frame(u, eye), d, grid_frame(d, eye), 0.0);
  ASSERT_EQ(rows.size(), 961u);
  double worst_flat = 0;  // the blank in its grid frame: plane z = 0, mark (i, j) at (5 i, -5 j)
  for (const GridRow& r : rows)
    worst_flat = std::max(worst_flat, (r.undeformed - Vec3(5.0 * r.ij.x(), -5.0 * r.ij.y(), 0)).norm());
  EXPECT_LT(worst_flat, 0.05);
  std::ostringstream os;
  write_grid(os, rows, {"test"});
  const io::CsvTable t = io::read_csv_string(os.str(), "grid.csv");
  for (const char* c : {"id", "i", "j", "X", "Y", "Z", "x", "y", "z", "reproj_deformed_px", "views_undeformed"})
    EXPECT_TRUE(t.has_column(c)) << c;
  EXPECT_EQ(t.n_rows(), 961u);
  // Nominal undeformed positions from the pitch.
  const std::vector<GridRow> nominal = join_sets(nullptr, Eigen::Isometry3d::Identity(), d, grid_frame(d, eye), 5.0);
  for (const GridRow& r : nominal) {
    EXPECT_EQ(r.undeformed, Vec3(5.0 * r.ij.x(), -5.0 * r.ij.y(), 0.0));
    EXPECT_EQ(r.views_undeformed, 0);
  }
  const GridData g = grid_data(nominal);
  EXPECT_EQ(g.n_points(), 961);
  EXPECT_TRUE(g.has_ij);
}

TEST(Digitise, LineJunctionsOnTheBend) {
  const auto o = test::small_example(synth::PatternKind::kLines);
  const Rig rig = test::true_rig(o);
  const synth::Scene sc = synth::example_part(o, synth::SheetShape::kBend);
  DigitiseOptions d;
  d.detect.kind = MarkKind::kLines;
  const SetResult s = digitise_set(rig, test::render_set(rig, sc, o.effects), d);
  const synth::Comparison c = synth::compare_marks(s.marks, sc, o.marks);
  EXPECT_EQ(c.mislabelled, 0);
  EXPECT_GT(c.n, 750);  // junctions of the grid's corners and steepest columns are left out
  EXPECT_LT(c.rms, kMarkRms3dMm);
  EXPECT_LT(c.max, kMarkMax3dMm);
}

TEST(Digitise, HiddenAndCutMarksAreReportedNeverMislabelled) {
  auto o = test::small_example();
  o.occlusion = true;
  const Rig rig = test::true_rig(o);
  const synth::Scene sc = synth::example_part(o, synth::SheetShape::kDome);
  const SetResult s = digitise_set(rig, test::render_set(rig, sc, o.effects), DigitiseOptions{});
  const synth::Comparison c = synth::compare_marks(s.marks, sc, o.marks);
  EXPECT_EQ(c.mislabelled, 0);
  EXPECT_LT(c.rms, kMarkRms3dMm);
  EXPECT_LT(c.max, kMarkMax3dMm);
  EXPECT_LT(c.n, 935);  // the trimmed corner and the flap cost marks
  EXPECT_GT(c.n, 890);
  Index reasons = 0;
  for (const ViewReport& v : s.views) reasons += static_cast<Index>(v.rejected.size());
  EXPECT_GT(reasons, 10);
  const nlohmann::json j = s.to_json();
  EXPECT_FALSE(j["views"][0]["rejected"].empty());
  EXPECT_TRUE(j["views"][0]["rejected"][0].contains("reason"));
}

TEST(Digitise, ThreeCamerasWithoutAReferenceMark) {
  auto o = test::small_example();
  o.n_cameras = 3;
  o.reference = false;
  const Rig rig = test::true_rig(o);
  const synth::Scene sc = synth::example_part(o, synth::SheetShape::kBend);
  const SetResult s = digitise_set(rig, test::render_set(rig, sc, o.effects), DigitiseOptions{});
  EXPECT_FALSE(s.has_reference);
  for (const ViewReport& v : s.views) EXPECT_TRUE(v.dropped.empty()) << v.name << ": " << v.dropped;
  // Labels start at the mark nearest the middle of camera 0's marks: the shift comes from one
  // mark, and then every mark must agree with it.
  const DigitisedMark& mid = s.marks[s.marks.size() / 2];
  Label shift(0, 0);
  double best = 1e9;
  for (const synth::TrueMark& t : synth::true_marks(sc)) {
    const double dist = (t.position - mid.X).norm();
    if (dist < best) {
      best = dist;
      shift = Label(t.i, -t.j) - mid.ij;
    }
  }
  const synth::Comparison c = synth::compare_marks(s.marks, sc, o.marks, Eigen::Isometry3d::Identity(), shift);
  EXPECT_EQ(c.mislabelled, 0);
  EXPECT_EQ(c.n, 961);
  EXPECT_LT(c.rms, kMarkRms3dMm);
}

TEST(Digitise, CalibrationsAndImageSetsThatDoNotBelongAreRefused) {
  const auto o = test::small_example();
  Rig rig = test::true_rig(o);
  {  // the images given in the wrong camera order
    const auto images = test::render_set(rig, synth::example_part(o, synth::SheetShape::kDome), o.effects);
    Rig swapped = rig;
    std::swap(swapped.cameras[0], swapped.cameras[1]);
    const std::string msg = io::test::message_of<InputError>([&] { digitise_set(swapped, images, DigitiseOptions{}); });
    EXPECT_THAT(msg, HasSubstr("cam1.png"));
    EXPECT_THAT(msg, HasSubstr("calibration"));
  }
  io::test::ScratchDir dir;
  write_png(dir.file("a.png"), GreyImage(1024, 768, 0.5f));
  write_png(dir.file("small.png"), GreyImage(800, 600, 0.5f));
  io::test::write_text(dir.file("text.png"), "not an image");
  EXPECT_THAT(
      io::test::message_of<InputError>([&] { read_image_set(rig, {dir.file("a.png")}, "--deformed", "r.json"); }),
      HasSubstr("1 image given, but the rig r.json has 2 cameras"));
  EXPECT_THAT(io::test::message_of<InputError>([&] {
                read_image_set(rig, {dir.file("a.png"), dir.file("small.png")}, "--deformed", "r.json");
              }),
              AllOf(HasSubstr("small.png"), HasSubstr("800 x 600"), HasSubstr("1024 x 768")));
  EXPECT_THAT(io::test::message_of<InputError>([&] {
                read_image_set(rig, {dir.file("a.png"), dir.file("none.png")}, "--deformed", "r.json");
              }),
              AllOf(HasSubstr("none.png"), HasSubstr("no such file")));
  EXPECT_THAT(io::test::message_of<InputError>([&] {
                read_image_set(rig, {dir.file("a.png"), dir.file("text.png")}, "--deformed", "r.json");
              }),
              HasSubstr("text.png"));
  const std::vector<NamedImage> blank = {{"b0.png", GreyImage(1024, 768, 0.5f)},
                                         {"b1.png", GreyImage(1024, 768, 0.5f)}};
  EXPECT_THAT(io::test::message_of<InputError>([&] { digitise_set(rig, blank, DigitiseOptions{}); }),
              HasSubstr("b0.png"));
}

}  // namespace
}  // namespace sf::gsa::digitise

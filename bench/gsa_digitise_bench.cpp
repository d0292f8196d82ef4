// gsa_digitise_bench [WxH] [calibration_views] [repeats]
//
// The figures of docs/digitise.md for the synthetic study of gsa/digitise/example.hpp
// (default 1632x1224 = 2 megapixels, 12 chessboard views per camera):
//   1. calibration from rendered chessboards: focal length and principal point errors,
//      reprojection errors per image and overall, baseline error;
//   2. 3-D marks (dots and line grids on the blank, a dome and a bend; an occluded dome;
//      three cameras) against the exact positions: with the exact cameras (in the world
//      frame) and with the calibrated rig (after the best rigid motion), marks labelled,
//      mislabels;
//   3. time to digitise one image pair read from PNG files (2 cores);
//   4. images to strains: gsa analyse on the digitised flat blank and dome against gsa
//      analyse on the exact grid with 0.01 mm noise, both against the exact strains.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <thread>

#include "gsa/accuracy.hpp"
#include "gsa/analysis.hpp"
#include "gsa/digitise/calibrate.hpp"
#include "gsa/digitise/digitise.hpp"
#include "gsa/digitise/example.hpp"

namespace {

using namespace sf;
using namespace sf::gsa;
using namespace sf::gsa::digitise;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

Eigen::Isometry3d pose(const Camera& c) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = c.R;
  T.translation() = c.t;
  return T;
}

// Exact strains of the rows' labels on `formed`.
std::vector<ExactStrain> exact_strains(const std::vector<GridRow>& rows, const synth::Scene& formed,
                                       synth::PatternKind kind) {
  std::vector<ExactStrain> out;
  for (const GridRow& r : rows) {
    const auto [I, J] = synth::material_index(r.ij, kind);
    const auto [l1, l2] = formed.sheet.stretches(Vec2(I * formed.pattern.pitch, J * formed.pattern.pitch));
    out.push_back({l1, l2, 0.0});
  }
  return out;
}

StrainError strains_of(const GridData& g, const std::vector<ExactStrain>& exact) {
  AnalyseOptions o;
  const AnalysisResult r = analyse(g, o);
  return strain_error(g, r, exact);
}

}  // namespace

int main(int argc, char** argv) {
  synth::ExampleOptions o;
  if (argc > 1 && std::sscanf(argv[1], "%dx%d", &o.width, &o.height) != 2) {
    std::fprintf(stderr, "usage: gsa_digitise_bench [WxH] [calibration_views] [repeats]\n");
    return 2;
  }
  if (argc > 2) o.calibration_views = std::atoi(argv[2]);
  const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 3;
  std::printf(
      "gsa_digitise_bench: %d x %d pixels (%.2f megapixels), %d chessboard views per camera, noise %.1f grey "
      "levels, blur %.1f px, uneven lighting\n\n",
      o.width, o.height, o.width * o.height / 1e6, o.calibration_views, o.effects.noise_sigma * 255,
      o.effects.blur_sigma);

  // 1. Calibration.
  const std::vector<Camera> truth = synth::example_cameras(o);
  const std::vector<synth::Scene> boards = synth::example_calibration_boards(o);
  auto t0 = Clock::now();
  std::vector<std::vector<NamedImage>> calib(truth.size());
  for (std::size_t c = 0; c < truth.size(); ++c)
    for (std::size_t b = 0; b < boards.size(); ++b) {
      synth::Effects fx = o.effects;
      fx.seed = static_cast<unsigned>(1000 + 10 * b + c);
      calib[c].push_back(
          {"cam" + std::to_string(c) + "/view_" + std::to_string(b), synth::render(truth[c], boards[b], fx)});
    }
  const double t_render = since(t0);
  const synth::BoardSpec bs = synth::example_board(o);
  CalibrateOptions co;
  co.target = {TargetKind::kChessboard, bs.cols, bs.rows, bs.square};
  t0 = Clock::now();
  const CalibrationResult cal = calibrate_rig(calib, co);
  const double t_cal = since(t0);
  std::printf("1. Calibration (%zu x %zu views rendered in %.1f s, calibrated in %.1f s)\n", truth.size(),
              boards.size(), t_render, t_cal);
  std::printf("   camera  fx err %%   fy err %%   cx err px  cy err px   RMS px   worst image px\n");
  for (std::size_t c = 0; c < truth.size(); ++c) {
    const Camera &e = cal.rig.cameras[c], &t = truth[c];
    double worst = 0;
    for (const ImageReport& ir : cal.cameras[c].images) worst = std::max(worst, ir.rms_px);
    std::printf("   cam%zu   %+8.4f  %+8.4f   %+8.3f   %+8.3f   %7.4f   %7.4f\n", c, 100 * (e.fx / t.fx - 1),
                100 * (e.fy / t.fy - 1), e.cx - t.cx, e.cy - t.cy, cal.cameras[c].rms_px, worst);
  }
  for (const StereoReport& s : cal.stereo) {
    const Mat3 R = truth[s.camera].R * truth[0].R.transpose();
    const Vec3 tt = truth[s.camera].t - R * truth[0].t;
    std::printf("   cam%ld relative to cam0: RMS %.4f px, baseline %.4f mm (exact %.4f, error %+.4f %%)\n",
                static_cast<long>(s.camera), s.rms_px, s.baseline, tt.norm(), 100 * (s.baseline / tt.norm() - 1));
  }

  // 2. 3-D marks.
  std::printf(
      "\n2. 3-D marks (mm)                   on part labelled mislabelled | exact cameras: RMS    max "
      "| calibrated rig: RMS in cam0 frame, rigidly aligned: RMS    max\n");
  Rig exact_rig;
  exact_rig.cameras = truth;
  struct Case {
    const char* name;
    synth::PatternKind marks;
    synth::SheetShape shape;
    bool occlusion;
    int cameras;
  };
  const Case cases[] = {
      {"dots, flat blank", synth::PatternKind::kDots, synth::SheetShape::kFlat, false, 2},
      {"dots, dome", synth::PatternKind::kDots, synth::SheetShape::kDome, false, 2},
      {"dots, bend", synth::PatternKind::kDots, synth::SheetShape::kBend, false, 2},
      {"dots, dome, flap + trimmed corner", synth::PatternKind::kDots, synth::SheetShape::kDome, true, 2},
      {"lines, flat blank", synth::PatternKind::kLines, synth::SheetShape::kFlat, false, 2},
      {"lines, dome", synth::PatternKind::kLines, synth::SheetShape::kDome, false, 2},
      {"lines, bend", synth::PatternKind::kLines, synth::SheetShape::kBend, false, 2},
  };
  for (const Case& k : cases) {
    synth::ExampleOptions ko = o;
    ko.marks = k.marks;
    ko.occlusion = k.occlusion;
    ko.n_cameras = k.cameras;
    const synth::Scene sc = synth::example_part(ko, k.shape);
    const auto images = synth::render_views(truth, sc, ko.effects, 7);
    DigitiseOptions d;
    d.detect.kind = k.marks == synth::PatternKind::kLines ? MarkKind::kLines : MarkKind::kDots;
    const SetResult se = digitise_set(exact_rig, images, d);
    const SetResult sc_cal = digitise_set(cal.rig, images, d);
    const synth::Comparison ce = synth::compare_marks(se.marks, sc, k.marks);
    const synth::Comparison cc = synth::compare_marks(sc_cal.marks, sc, k.marks, pose(truth[0]));
    std::printf(
        "   %-34s %6zu  %6ld   %6ld     |            %7.4f %7.4f |              %7.4f                %7.4f "
        "%7.4f\n",
        k.name, synth::true_marks(sc).size(), static_cast<long>(ce.n),
        static_cast<long>(ce.mislabelled + cc.mislabelled), ce.rms, ce.max, cc.rms, cc.rms_rigid, cc.max_rigid);
  }
  {
    synth::ExampleOptions ko = o;
    ko.n_cameras = 3;
    ko.reference = false;
    const std::vector<Camera> cams3 = synth::example_cameras(ko);
    Rig rig3;
    rig3.cameras = cams3;
    const synth::Scene sc = synth::example_part(ko, synth::SheetShape::kDome);
    const SetResult s = digitise_set(rig3, synth::render_views(cams3, sc, ko.effects, 9), DigitiseOptions{});
    // No reference mark: labels start at the mark nearest the middle; find the shift.
    const DigitisedMark& mid = s.marks[s.marks.size() / 2];
    Label shift(0, 0);
    double best = 1e9;
    for (const synth::TrueMark& t : synth::true_marks(sc))
      if ((t.position - mid.X).norm() < best) {
        best = (t.position - mid.X).norm();
        shift = Label(t.i, -t.j) - mid.ij;
      }
    const synth::Comparison c = synth::compare_marks(s.marks, sc, ko.marks, Eigen::Isometry3d::Identity(), shift);
    std::printf("   %-34s %6zu  %6ld   %6ld     |            %7.4f %7.4f |   (exact cameras only)\n",
                "dots, dome, 3 cameras, no reference", synth::true_marks(sc).size(), static_cast<long>(c.n),
                static_cast<long>(c.mislabelled), c.rms, c.max);
  }

  // 3. Time for one image pair from PNG files.
  {
    const synth::Scene sc = synth::example_part(o, synth::SheetShape::kDome);
    const auto images = synth::render_views(truth, sc, o.effects, 11);
    const std::string dir = (std::filesystem::temp_directory_path() / "gsa_digitise_bench").string();
    std::filesystem::create_directories(dir);
    std::vector<std::string> paths;
    for (std::size_t c = 0; c < images.size(); ++c) {
      paths.push_back(dir + "/cam" + std::to_string(c) + ".png");
      write_png(paths.back(), images[c].image);
    }
    std::vector<double> times;
    for (int r = 0; r < repeats; ++r) {
      t0 = Clock::now();
      const SetResult s = digitise_set(cal.rig, read_image_set(cal.rig, paths, "--deformed", "rig"), DigitiseOptions{});
      times.push_back(since(t0));
      if (s.marks.empty()) return 1;
    }
    std::sort(times.begin(), times.end());
    std::printf(
        "\n3. Digitising one %.1f-megapixel image pair read from PNG (dome, %u threads): best %.2f s, median "
        "%.2f s of %d\n",
        o.width * o.height / 1e6, std::thread::hardware_concurrency(), times.front(), times[times.size() / 2], repeats);
    std::filesystem::remove_all(dir);
  }

  // 4. Images to strains.
  {
    const synth::Scene flat = synth::example_part(o, synth::SheetShape::kFlat);
    const synth::Scene dome = synth::example_part(o, synth::SheetShape::kDome);
    const auto flat_images = synth::render_views(truth, flat, o.effects, 13);
    const auto dome_images = synth::render_views(truth, dome, o.effects, 17);
    std::printf(
        "\n4. Images to strains (dome; RMS error of E1 and E2 against the exact strains, marks inside the "
        "outer ring)\n");
    for (const auto& [label, rig] :
         {std::pair<const char*, const Rig*>{"calibrated rig", &cal.rig}, {"exact cameras", &exact_rig}}) {
      const SetResult u = digitise_set(*rig, flat_images, DigitiseOptions{});
      const SetResult d = digitise_set(*rig, dome_images, DigitiseOptions{});
      const Vec3 eye = rig->cameras[0].centre();
      const std::vector<GridRow> rows = join_sets(&u, grid_frame(u, eye), d, grid_frame(d, eye), 0.0);
      const GridData g = grid_data(rows);
      const StrainError e = strains_of(g, exact_strains(rows, dome, o.marks));
      // Reference: the exact grid of the same labels with 0.01 mm noise per coordinate.
      std::mt19937 rng(5);
      std::normal_distribution<double> noise(0.0, 0.01);
      GridData ref = g;
      for (Index p = 0; p < ref.n_points(); ++p) {
        const auto [I, J] = synth::material_index(rows[p].ij, o.marks);
        const Vec2 m(I * o.pitch, J * o.pitch);
        const Vec3 X = flat.sheet.position(m), x = dome.sheet.position(m);
        for (int k = 0; k < 3; ++k) {
          ref.undeformed(p, k) = X(k) + noise(rng);
          ref.deformed(p, k) = x(k) + noise(rng);
        }
      }
      const StrainError er = strains_of(ref, exact_strains(rows, dome, o.marks));
      std::printf(
          "   %-15s digitised: E1 %.2e  E2 %.2e (RMS %.2e, %ld marks) | exact + 0.01 mm noise: E1 %.2e  E2 "
          "%.2e (RMS %.2e) | ratio %.2f\n",
          label, e.rms_e1, e.rms_e2, e.rms(), static_cast<long>(e.n), er.rms_e1, er.rms_e2, er.rms(),
          e.rms() / er.rms());
    }
  }
  return 0;
}

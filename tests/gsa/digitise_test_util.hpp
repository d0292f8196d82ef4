#pragma once
// Shared pieces of the gsa/digitise tests: the synthetic study at a reduced size, truth
// lookups, and the named tolerances (each says what it bounds and what was measured).

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "gsa/digitise/digitise.hpp"
#include "gsa/digitise/example.hpp"

namespace sf::gsa::digitise::test {

namespace tol {
// Dot centre in a rendered image against the exact centroid of the projected dot
// (0.8-megapixel views, noise 1.5 grey levels, blur 0.7 px). Measured 0.006-0.012 px RMS.
inline constexpr double kDotCentreRmsPx = 0.03;
// Line-grid junctions against the exact projected junction. Measured 0.015-0.02 px RMS.
inline constexpr double kJunctionRmsPx = 0.04;
// Any single accepted mark (dots or junctions). Measured < 0.09 px.
inline constexpr double kMarkMaxPx = 0.2;
// 3-D marks from two 0.8-megapixel views with the exact cameras: measured 0.005-0.009 mm RMS
// (the 2-megapixel target of the issue is 0.02 mm; tests/digitise_long checks it).
inline constexpr double kMarkRms3dMm = 0.02;
inline constexpr double kMarkMax3dMm = 0.08;
// The same with the rig calibrated from 8 rendered chessboard views per camera, after the
// best rigid motion onto the truth: the calibration's errors add a smooth distortion of the
// measured shape. Measured 0.010 mm RMS at 0.8 megapixels.
inline constexpr double kMarkRms3dCalibratedMm = 0.03;
// Calibration from 8 rendered chessboard views per camera at 0.8 megapixels: relative
// focal-length error (measured < 0.05 %), RMS reprojection (measured 0.03 px).
inline constexpr double kFocalRel = 2e-3;
inline constexpr double kCalibrationRmsPx = 0.1;
// Relative baseline error of the stereo calibration (measured < 0.02 %).
inline constexpr double kBaselineRel = 1e-3;
}  // namespace tol

// The study at 1024 x 768 (0.8 megapixels): a third of the pixels of the 2-megapixel
// views, so a test renders in a fraction of a second.
inline synth::ExampleOptions small_example(synth::PatternKind marks = synth::PatternKind::kDots) {
  synth::ExampleOptions o;
  o.width = 1024;
  o.height = 768;
  o.marks = marks;
  o.calibration_views = 8;
  return o;
}

inline Rig true_rig(const synth::ExampleOptions& o) {
  Rig rig;
  rig.cameras = synth::example_cameras(o);
  return rig;
}

inline std::vector<NamedImage> render_set(const Rig& rig, const synth::Scene& scene, const synth::Effects& fx,
                                          unsigned seed = 1) {
  std::vector<NamedImage> out;
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    synth::Effects e = fx;
    e.seed = seed + 17 * static_cast<unsigned>(c);
    out.push_back({rig.cameras[c].name + ".png", synth::render(rig.cameras[c], scene, e)});
  }
  return out;
}

inline std::pair<int, int> material_index(const Label& l, synth::PatternKind marks) {
  return synth::material_index(l, marks);
}

// True marks keyed by their material index.
inline std::map<std::pair<int, int>, synth::TrueMark> truth_map(const synth::Scene& scene) {
  std::map<std::pair<int, int>, synth::TrueMark> m;
  for (const synth::TrueMark& t : synth::true_marks(scene)) m[{t.i, t.j}] = t;
  return m;
}

}  // namespace sf::gsa::digitise::test

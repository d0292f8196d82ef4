#pragma once
// One set of grid labels for all views of a rig: epipolar geometry decides how each view's
// own labels (i, j) map onto camera 0's.
//
// Each view is labelled on its own (detect.hpp): relative to the reference mark when it
// sees it, with i along its image's rows and j down its columns. Between two views the
// labels then differ by a quarter turn (the camera may be turned about its axis; never a
// mirror, since every camera sees the printed side) and, without a reference in both, a
// shift:
//
//     L_0 = S (L_v - r) + r + o        r = the reference's lattice coordinates
//
// Every (S, o) is scored by the number of marks that land on a camera-0 mark within
// `tolerance_px` of the epipolar line of their own image position (shifts are proposed by
// votes of marks near the middle of the view). The best must be clearly better than the
// second best, or the view is reported as ambiguous -- which happens when the grid lines
// run along the epipolar lines and no reference mark is seen in both views: a shift along
// the baseline then fits too. Print a reference mark, turn the part relative to the
// baseline, or add a third camera.

#include <string>

#include "gsa/digitise/camera.hpp"
#include "gsa/digitise/detect.hpp"

namespace sf::gsa::digitise {

// An element of the square lattice's symmetry group with an integer shift.
struct LabelTransform {
  int symmetry = 0;  // 0..3: rotation by 90 x k degrees; 4..7: the same after i <-> j
  Label offset = Label(0, 0);
  Vec2 reference = Vec2::Zero();  // r: (0, 0) or (0.5, 0.5)

  Label apply(const Label& l) const;
  static LabelTransform identity(const Vec2& reference) {
    LabelTransform t;
    t.reference = reference;
    return t;
  }
};

struct MatchOptions {
  double tolerance_px = 2.0;  // epipolar distance that counts as consistent
  double ambiguity = 0.7;     // second best / best above this: ambiguous
};

struct MatchResult {
  bool ok = false;
  LabelTransform transform;
  Index n_consistent = 0;  // marks of the view that agree with camera 0
  Index n_second = 0;      // the same for the runner-up (S, o)
  std::string message;     // why not ok
};

// How view v's labels map onto view 0's. Both views' marks, and their cameras.
MatchResult match_view(const Camera& cam0, const ViewMarks& view0, const Camera& camv, const ViewMarks& viewv,
                       const MatchOptions& options = {});

}  // namespace sf::gsa::digitise

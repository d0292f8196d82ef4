#pragma once
// Blunders: isolated digitising mistakes, told apart from real features.
//
// A large fit residual alone does not make a point wrong: a neck narrower than
// the smoothing, a wrinkle or a dimple leaves large residuals on every point it
// covers. A blunder (a mark clicked on the wrong dot, a digit typed wrong, a DIC
// subset that matched the wrong place) is a point its neighbours disagree with.
// Each point is therefore judged against its own neighbourhood, leaving the point
// out:
//
//   1. its k nearest neighbours (by undeformed position) give a local quadratic
//      fit v(s, t) = c0 + c1 s + c2 t + c3 s^2 + c4 s t + c5 t^2 of each value
//      component over the neighbours' tangent-plane coordinates (s, t) about the
//      point; the point's deviation is |v_p - c0| / sqrt(1 + v0) (mm), v0 the
//      variance factor of the prediction c0 (larger at gaps and at the outline);
//   2. the noise level is robust: the median deviation over all points over the
//      median of a chi distribution with the tested number of components;
//   3. a point is a blunder when its deviation exceeds `threshold` noise levels
//      AND `isolation` times the second largest deviation among its 8 nearest
//      neighbours, so a coherent region of large deviations (a feature, even a line
//      one point wide) is never flagged;
//   4. a pass flags only points whose deviation is the largest among their 8
//      nearest neighbours (a blunder spoils its neighbours' fits too); the check is
//      repeated without the points flagged so far, up to `passes` times.
//
// Undeformed state: values = the undeformed positions, only the normal component
// counts (in-plane positions define where a point is, they cannot be predicted).
// Deformed state: values = the deformed positions against the undeformed
// in-plane coordinates, all three components count.

#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa {

struct BlunderOptions {
  int neighbours = 16;     // k (>= 8)
  double threshold = 4.5;  // deviation in noise levels
  double isolation = 2.5;  // deviation over the second largest deviation of the 8 nearest neighbours
  int passes = 6;
  double floor = 0.0;  // the threshold is at least this (mm): round-off and the local fit's own
                       // misfit set the noise level of noise-free data
  void validate() const;
};

// The candidate neighbours of each point (nearest first) among the points a check
// used: kept so a second check of the same positions among the same points (the
// deformed state after the undeformed one) does not search them again.
struct BlunderNeighbours {
  std::vector<bool> among;  // the points searched
  int count = 0;            // candidates per point
  std::vector<std::vector<Index>> candidates;
};

struct BlunderCheck {
  std::vector<double> deviation;  // per point, mm (NaN where not checked)
  double noise = 0.0;             // robust noise level per component, mm
  double threshold = 0.0;         // deviation above which a point can be flagged, mm
  std::vector<bool> flagged;      // per point
  Index n_flagged() const;
  std::shared_ptr<const BlunderNeighbours> neighbours;  // the candidates searched (or reused)
};

// positions: n x 3 undeformed positions (where the points are); values: n x 3 the
// state to check (the positions themselves for the undeformed state); usable: the
// points taking part (others are neither checked nor used). normal_only: test the
// deviation along the local normal of the positions only.
// `reuse`: the neighbours of an earlier check of the same positions, taken when they
// were searched among the same points (else searched again).
BlunderCheck find_blunders(const Points3& positions, const Points3& values, const std::vector<bool>& usable,
                           bool normal_only, const BlunderOptions& options = {},
                           std::shared_ptr<const BlunderNeighbours> reuse = nullptr);

}  // namespace sf::gsa

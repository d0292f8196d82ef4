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
//   2. the noise, robust. Undeformed state: one level, the median deviation over all
//      points over the median of a chi distribution with one component. Deformed state:
//      a noise covariance of the deviation vectors (robust: the vectors within 3 x the
//      median squared Mahalanobis distance, three rounds, scaled so that the median
//      squared distance is chi-square(3)'s median). Stereo DIC measures along its
//      viewing direction several times worse than across it: one level for all three
//      components is set by that direction's noise, and an in-plane blunder of 10
//      in-plane sigmas stays under it. The covariance has two levels, along its
//      noisiest axis and across it, whatever the axis (the cameras' direction, fixed
//      while a dome's normal turns). The point's score: the deviation in noise levels,
//      its Mahalanobis length under the covariance (undeformed: deviation / level);
//   3. a point is a blunder when its score exceeds `threshold` AND `isolation`
//      times the second largest score among its 8 nearest neighbours, so a
//      coherent region of large deviations (a feature, even a line one point wide)
//      is never flagged; its deviation must also exceed `floor`;
//   4. a pass flags only points whose score is the largest among their 8
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
  bool two_level = true;  // deformed state: scored under the noise covariance (false: one level
                          // for all components, the rule before; kept for comparison)
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
  std::vector<double> score;      // the deviation in noise levels (2. above)
  double noise = 0.0;             // robust noise level per component, all components alike, mm
  // Deformed state: the noise covariance's level along its noisiest axis, and per
  // component across it (the root mean square of the other two), mm (0: not estimated).
  double noise_axis = 0.0, noise_across = 0.0;
  Vec3 axis = Vec3::Zero();       // the noisiest axis (unit; sign arbitrary)
  double threshold = 0.0;         // threshold x noise (the isotropic level), mm: what a deviation of
                                  // typical direction must exceed
  std::vector<bool> flagged;      // per point
  Index n_flagged() const;
  // The noise level along point p's deviation (deviation / score), mm, and the deviation a
  // point of that direction must exceed: max(threshold x that level, floor), mm.
  double noise_along(Index p) const;
  double threshold_of(Index p, const BlunderOptions& options) const;
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
// The neighbour search of find_blunders with the same arguments, on its own: started
// ahead (on another thread beside other work) and passed as find_blunders' `reuse`.
std::shared_ptr<const BlunderNeighbours> blunder_neighbours(const Points3& positions, const Points3& values,
                                                            const std::vector<bool>& usable,
                                                            const BlunderOptions& options = {});

}  // namespace sf::gsa

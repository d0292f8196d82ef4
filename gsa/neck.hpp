#pragma once
// Limit strains across a neck along a section, after the position-dependent method of
// ISO 12004-2 (docs/theory/strain.md "Neck evaluation"):
//
//  1. the neck is at the largest major strain along the section;
//  2. its inner boundaries, one each side, are where the major strain's second derivative
//     along the section (central differences) is largest within the search half-width W
//     of the peak: the shoulders where the localised neck leaves the smooth background;
//  3. fit windows of width W = 10 (1 + minor/major at the peak) in the length unit (mm),
//     at least 3 points each, run outward from the inner boundaries (leaving out the
//     boundary point and its outer neighbour, which its central difference reached);
//  4. an inverse second-order parabola 1/major = a s^2 + b s + c is fitted by least squares
//     to the points of both windows; its apex s* = -b/(2a) gives the limit major strain
//     1/(c - b^2/(4a)) (a > 0 is required: the background must rise toward the neck);
//  5. the minor strain: a second-order parabola over the same windows, evaluated at s*;
//  6. the section must show a localised neck: the peak strain more than 2 % above the limit
//     (else the fit's maximum is only the smooth background's, and no limit is reported).
//
// A neck that cannot be evaluated (too close to an end, too few points, a fit without
// a maximum) gives ok = false and a sentence why.

#include <limits>
#include <string>
#include <vector>

namespace sf::gsa {

struct NeckResult {
  bool ok = false;
  std::string message;  // why not, when !ok
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double peak_position = kNaN, peak_major = kNaN;  // the largest measured major strain
  double apex_position = kNaN;                     // s* of the fitted inverse parabola
  double limit_major = kNaN, limit_minor = kNaN;   // limit strains at the apex
  double inner_left = kNaN, inner_right = kNaN;    // neck zone left out of the fit
  double outer_left = kNaN, outer_right = kNaN;    // outer ends of the fit windows
  double window_width = kNaN;                      // W
  int fit_points = 0;
  double fit_rms = kNaN;  // RMS misfit of the major strain over the windows
};

// `s` ascending positions along the section (length unit), `major`, `minor` strains there
// (NaN points are skipped).
NeckResult evaluate_neck(const std::vector<double>& s, const std::vector<double>& major,
                         const std::vector<double>& minor);

}  // namespace sf::gsa

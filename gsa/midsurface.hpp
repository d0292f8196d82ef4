#pragma once
// Mid-surface strains of a sheet whose grid was marked on one face (docs/theory/strain.md,
// "Mid-surface strains"). The fitted surfaces are the marked face; the mid-surface lies half
// the thickness h below it along the face's unit normal n (n = x,1 x x,2 / |...|):
//
//   r_mid = r - s (h/2) n,     s = +1 when the grid is on the top face (the side n points
//                                  to), s = -1 on the bottom face,
//   r_mid,a = r,a - s (h/2) n,a   (n,a exactly from the second derivatives of the fit:
//                                  n,a = P (r,1a x r,2 + r,1 x r,2a) / |r,1 x r,2|, P = I - n n^T)
//
// which is the metric a_mid = a + s h b + (h/2)^2 b a^-1 b of the face metric a and its
// second fundamental form b_ab = r,ab . n. Undeformed: h = t0 (the given thickness).
// Deformed: the current thickness h = t0 lambda3, lambda3 = 1 / (lambda1 lambda2) of the
// mid-surface strains (incompressible sheet), found by a fixed-point iteration that starts
// from the face's thickness stretch; it contracts by about h/(2R) per pass and stops when h
// changes by less than 1e-13 t0 (20 passes at most).

#include <optional>

#include "common/core/types.hpp"
#include "common/fe/surface_field.hpp"
#include "gsa/strain.hpp"

namespace sf::gsa {

enum class GridFace { kTop, kBottom };

struct MidSurfaceOptions {
  double thickness = 0.0;  // initial sheet thickness t0 in the grid's length unit (mm); 0: no correction
  GridFace face = GridFace::kTop;
  int iterations = 20;  // thickness fixed-point passes at most (stops when h changes < 1e-13 t0)
  bool enabled() const { return thickness > 0.0; }
};

struct MidSurfaceStrain {
  SurfaceStrain strain;    // principal stretches and directions of the mid-surface
  double thickness = 0.0;  // current thickness h (length unit), t0 / (lambda1 lambda2) of the mid-surface
};

// The unit normal's xi-derivatives [n,1 n,2] of a surface point with first and second
// derivatives; nothing when the tangents are degenerate.
std::optional<Mat32> normal_derivatives(const fe::SurfacePoint& p);

// Mid-surface strain at one material point from the face's undeformed and deformed points
// (both evaluated with values, first and second derivatives). Nothing where the tangents
// are degenerate or the offset surface folds (h/2 beyond a radius of curvature).
std::optional<MidSurfaceStrain> mid_surface_strain(const fe::SurfacePoint& undeformed, const fe::SurfacePoint& deformed,
                                                   const MidSurfaceOptions& options);

// "top" or "bottom" (any letter case); throws sf::UsageError naming `option` otherwise.
GridFace parse_grid_face(const std::string& text, const std::string& option = "--grid-face");

}  // namespace sf::gsa

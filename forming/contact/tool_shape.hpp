#pragma once
// Rigid tool surfaces: the shape of a tool at rest, as a signed gap function.
//
// A tool occupies a region of space; every shape answers, for a point x (mm, tool at
// rest; forming/contact/rigid_tool.hpp moves it):
//   gap     g(x): positive outside the tool, negative inside (penetration), 0 on it;
//   normal  n(x): the unit outward normal the contact force acts along;
//   dg/dx, dn/dx  their derivatives (for the consistent contact tangent);
//   in_front      false where the point is not opposite the surface at all (beside an
//                 open meshed surface's boundary): no contact there.
// Analytic shapes are exact signed distance functions phi: g = phi, n = grad phi,
// dg/dx = n, dn/dx = the Hessian of phi (symmetric), with the curvature of the
// surface at the closest point (sphere: (I - n n^T)/|x - c|). In the (rho, h) profile
// of a shape of revolution or extrusion, a rounded corner is the Minkowski sum of a
// sharp-cornered core with a disk of the fillet radius r: phi = sd_core - r.
//
//   plane     {point, normal}: the half-space behind the plane; phi = (x - p) . n.
//   sphere    {centre, radius} (a hemispherical punch):  phi = |x - c| - R.
//   cylinder  {point, axis, radius}, infinite along the axis (a bend punch nose or a
//             roller): phi = |x_perp| - R, x_perp the part of x - p across the axis.
//   punch     {tip, axis, radius, fillet}: a flat-ended cylindrical punch whose end face
//             (centre `tip`, outward normal `axis` = the direction it presses) meets its
//             side in a fillet of radius `fillet` (0 < fillet <= radius); it extends
//             without end behind the tip.
//   die       {centre, normal, opening, edge_radius}: a plate whose top face (through
//             `centre`, outward normal `normal`) has an opening, with its edge rounded by
//             `edge_radius`; `opening` is a circle {radius} (dome tooling) or a slot
//             {half_width, along} (bend tooling: the slot runs along the unit vector
//             `along`, in the top face). The plate extends without end sideways and below.
//   mesh      a triangulated surface (STL, common/io/stl.hpp) with smoothed normals
//             (common/mesh/triangle_surface.hpp): g = (x - p) . n with p the closest
//             point and n the smoothed normal there. n is not the gradient of g, so the
//             tangent of a meshed tool is not symmetric.
// Shapes also tessellate themselves (triangles, for the outputs) over a box of interest.
//
// Units: mm.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/stl.hpp"
#include "common/mesh/triangle_surface.hpp"

namespace sf::forming {

struct ToolPoint {
  double gap = 0.0;                     // mm
  Vec3 normal = Vec3::UnitZ();          // unit, outward
  Vec3 gap_gradient = Vec3::UnitZ();    // d gap / dx
  Mat3 normal_gradient = Mat3::Zero();  // d normal / dx, 1/mm
  bool in_front = true;
};

// Triangles of a tool surface for the outputs (mm).
struct ToolTessellation {
  Points3 points;
  std::vector<std::array<Index, 3>> triangles;
};

class ToolShape {
 public:
  virtual ~ToolShape() = default;
  // "plane", "sphere", "cylinder", "punch", "die", "mesh".
  virtual std::string kind() const = 0;
  virtual ToolPoint evaluate(const Vec3& x) const = 0;
  // True when normal_gradient is the (symmetric) Hessian of the gap and dg/dx = n.
  virtual bool symmetric() const { return true; }
  // Triangles of the surface where it lies within the box [lo, hi] (enlarged to hold
  // the shape's own features), at rest.
  virtual ToolTessellation tessellate(const Vec3& lo, const Vec3& hi) const = 0;
};

// Constructors throw sf::InputError naming the parameter (e.g. "sphere radius: expected
// a positive length (mm), found -1") for non-finite or out-of-range values.
std::shared_ptr<const ToolShape> make_plane(const Vec3& point, const Vec3& normal);
std::shared_ptr<const ToolShape> make_sphere(const Vec3& centre, double radius);
std::shared_ptr<const ToolShape> make_cylinder(const Vec3& point, const Vec3& axis, double radius);
std::shared_ptr<const ToolShape> make_punch(const Vec3& tip, const Vec3& axis, double radius, double fillet);
struct DieOpening {
  bool slot = false;           // false: circular opening
  double radius = 0.0;         // circle, mm
  double half_width = 0.0;     // slot, mm
  Vec3 along = Vec3::UnitY();  // slot direction (in the top face)
};
std::shared_ptr<const ToolShape> make_die(const Vec3& centre, const Vec3& normal, const DieOpening& opening,
                                          double edge_radius);
// A meshed tool, optionally scaled about the origin then translated (mm).
std::shared_ptr<const ToolShape> make_mesh_tool(const io::TriangleMesh& mesh, double scale = 1.0,
                                                const Vec3& offset = Vec3::Zero());

}  // namespace sf::forming

#pragma once
// Closest points on a triangulated surface (e.g. a tool read from STL, common/io/stl.hpp),
// with a bounding-volume tree (CGAL's AABB tree, kept in triangle_surface.cpp) and
// normals smoothed across facets, so that a contact force along the normal does not
// jump where the closest point crosses a facet edge.
//
// For a point x the surface answers (TriangleSurface::closest):
//   p          the closest point of the surface (exact, on its closest facet);
//   feature    where p lies on that facet: its interior, an edge or a vertex;
//   b          barycentric coordinates of p in the facet (b0 + b1 + b2 = 1, >= 0);
//   n_facet    the facet's unit normal (right-handed vertex order: the outward side);
//   n          the SMOOTHED unit normal: normalize(b0 N0 + b1 N1 + b2 N2), N_i the
//              vertex normals = angle-weighted means of the normals of the facets at
//              vertex i (Thuerrner & Wuethrich 1998). n is continuous over the surface
//              (an edge's normals depend on its two vertices only);
//   gap        (x - p) . n, signed: positive on the outward side;
//   and the derivatives of gap and n with respect to x, exact in the closest point's
//   region (where p moves with x as the projection onto the facet plane, onto an edge's
//   line, or stays at a vertex):
//     dp/dx = P  (I - n_f n_f^T, e e^T, or 0), db/dx = (db/dp) P,
//     dn/dx = (I - n n^T)/|m| sum_i N_i (db_i/dx)^T,  m = sum_i b_i N_i,
//     dgap/dx = n^T (I - P) + (x - p)^T dn/dx.
//   in_front   false where the surface is open and x lies beyond a boundary edge (its
//              closest point is on a free edge or vertex and x - p makes more than 60
//              degrees with +-n): no contact there.
// Cost: building the tree O(F log F) for F facets, a query O(log F) (CGAL AABB tree).
// Units: those of the vertices (e.g. mm).

#include <array>
#include <memory>
#include <vector>

#include "common/core/types.hpp"

namespace sf::mesh {

struct SurfaceClosestPoint {
  enum class Feature { kFace, kEdge, kVertex };
  Index triangle = -1;
  Feature feature = Feature::kFace;
  Vec3 point = Vec3::Zero();        // p
  Vec3 barycentric = Vec3::Zero();  // b
  Vec3 facet_normal = Vec3::Zero();
  Vec3 normal = Vec3::Zero();           // smoothed n
  double gap = 0.0;                     // (x - p) . n
  double distance = 0.0;                // |x - p|
  Vec3 gap_gradient = Vec3::Zero();     // d gap / dx
  Mat3 normal_gradient = Mat3::Zero();  // d n / dx (not symmetric in general)
  bool in_front = true;
};

class TriangleSurface {
 public:
  // vertices: n x 3; triangles: vertex indices, counter-clockwise seen from outside, of
  // positive area. Throws sf::InputError for an index out of range, a non-finite vertex,
  // a degenerate triangle, or an empty surface.
  TriangleSurface(Points3 vertices, std::vector<std::array<Index, 3>> triangles);

  SurfaceClosestPoint closest(const Vec3& x) const;

  const Points3& vertices() const;
  const std::vector<std::array<Index, 3>>& triangles() const;
  // Smoothed vertex normals, n x 3 (unit).
  const Points3& vertex_normals() const;
  Index n_triangles() const;
  // Bounding box corners.
  Vec3 lower() const;
  Vec3 upper() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace sf::mesh

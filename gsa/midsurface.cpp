#include "gsa/midsurface.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include "common/core/error.hpp"

namespace sf::gsa {

std::optional<Mat32> normal_derivatives(const fe::SurfacePoint& p) {
  const Vec3 r1 = p.dx.col(0), r2 = p.dx.col(1);
  const Vec3 c = r1.cross(r2);
  const double len = c.norm();
  if (!(len > 1e-12 * r1.norm() * r2.norm()) || !std::isfinite(len)) return std::nullopt;
  const Vec3 n = c / len;
  const Mat3 proj = Mat3::Identity() - n * n.transpose();
  const Vec3 r11 = p.d2x.col(0), r12 = p.d2x.col(1), r22 = p.d2x.col(2);
  Mat32 dn;
  dn.col(0) = proj * (r11.cross(r2) + r1.cross(r12)) / len;
  dn.col(1) = proj * (r12.cross(r2) + r1.cross(r22)) / len;
  return dn;
}

std::optional<MidSurfaceStrain> mid_surface_strain(const fe::SurfacePoint& pu, const fe::SurfacePoint& pd,
                                                   const MidSurfaceOptions& o) {
  const auto dnu = normal_derivatives(pu), dnd = normal_derivatives(pd);
  if (!dnu || !dnd || !(o.thickness > 0.0)) return std::nullopt;
  const double s = o.face == GridFace::kTop ? 1.0 : -1.0;
  const Mat32 G = pu.dx - s * 0.5 * o.thickness * *dnu;
  // Same orientation as the face: an offset beyond a radius of curvature folds the surface.
  auto folded = [](const Mat32& face, const Mat32& mid) {
    return face.col(0).cross(face.col(1)).dot(mid.col(0).cross(mid.col(1))) <= 0.0;
  };
  if (folded(pu.dx, G)) return std::nullopt;
  const auto face = surface_strain(pu.dx, pd.dx);
  double h = o.thickness * (face ? face->thickness_stretch() : 1.0);
  std::optional<SurfaceStrain> mid;
  // Fixed point h = t0 / (lambda1 lambda2)(h): contracts by about h / (2 R) per pass.
  for (int pass = 0; pass < std::max(1, o.iterations); ++pass) {
    const Mat32 g = pd.dx - s * 0.5 * h * *dnd;
    if (folded(pd.dx, g)) return std::nullopt;
    mid = surface_strain(G, g);
    if (!mid) return std::nullopt;
    const double next = o.thickness * mid->thickness_stretch();
    const bool converged = std::abs(next - h) <= 1e-13 * o.thickness;
    h = next;
    if (converged) break;
  }
  // The normals are the face's (the offset is along them): keep those of the face.
  mid->normal_undeformed = pu.dx.col(0).cross(pu.dx.col(1)).normalized();
  mid->normal_deformed = pd.dx.col(0).cross(pd.dx.col(1)).normalized();
  return MidSurfaceStrain{*mid, h};
}

GridFace parse_grid_face(const std::string& text, const std::string& option) {
  std::string t = text;
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (t == "top") return GridFace::kTop;
  if (t == "bottom") return GridFace::kBottom;
  throw UsageError(option +
                   ": expected top or bottom (the face the grid is on, relative to the fitted surface's "
                   "normal), found '" +
                   text + "'");
}

}  // namespace sf::gsa

// The classical grid strain method (for comparison): homogeneous strain per
// triangle of neighbouring marks, averaged to the marks.
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <map>

#include "common/core/error.hpp"
#include "gsa/analysis.hpp"
#include "gsa/plane.hpp"

namespace sf::gsa {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<Index, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

// Triangles from grid indices: each complete grid cell gives its four triangles
// (both diagonals), so the result does not depend on a diagonal choice.
std::vector<std::array<Index, 3>> grid_triangles(const GridData& g, const std::vector<Index>& usable) {
  std::map<std::pair<long, long>, Index> at;
  for (Index p : usable) at[{g.i[p], g.j[p]}] = p;
  std::vector<std::array<Index, 3>> tris;
  for (const auto& [cell, p00] : at) {
    const std::pair<long, long>& ij = cell;  // C++17 lambdas cannot capture a structured binding (clang)
    auto f = [&](long di, long dj) {
      auto it = at.find({ij.first + di, ij.second + dj});
      return it == at.end() ? Index(-1) : it->second;
    };
    const Index p10 = f(1, 0), p01 = f(0, 1), p11 = f(1, 1);
    if (p10 >= 0 && p01 >= 0) tris.push_back({p00, p10, p01});
    if (p10 >= 0 && p11 >= 0 && p01 >= 0) tris.push_back({p10, p11, p01});
    if (p10 >= 0 && p11 >= 0) tris.push_back({p00, p10, p11});
    if (p11 >= 0 && p01 >= 0) tris.push_back({p00, p11, p01});
  }
  return tris;
}

std::vector<std::array<Index, 3>> delaunay_triangles(const GridData& g, const std::vector<Index>& usable) {
  Points3 pts(static_cast<Index>(usable.size()), 3);
  for (std::size_t k = 0; k < usable.size(); ++k) pts.row(static_cast<Index>(k)) = g.undeformed.row(usable[k]);
  const PlaneFrame frame = best_fit_plane(pts);
  const Vec3& c = frame.centroid;
  const Vec3 &a1 = frame.a1, &a2 = frame.a2;
  std::vector<std::pair<Kernel::Point_2, Index>> in;
  in.reserve(usable.size());
  for (std::size_t k = 0; k < usable.size(); ++k) {
    const Vec3 q = pts.row(static_cast<Index>(k)).transpose() - c;
    in.emplace_back(Kernel::Point_2(q.dot(a1), q.dot(a2)), usable[k]);
  }
  Delaunay dt(in.begin(), in.end());
  // Drop sliver triangles on the convex hull (long edges between boundary marks).
  std::vector<std::array<Index, 3>> tris;
  std::vector<double> edge;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f)
    for (int k = 0; k < 3; ++k)
      edge.push_back(
          std::sqrt(CGAL::to_double(CGAL::squared_distance(f->vertex(k)->point(), f->vertex((k + 1) % 3)->point()))));
  std::nth_element(edge.begin(), edge.begin() + edge.size() / 2, edge.end());
  const double typical = edge.empty() ? 0.0 : edge[edge.size() / 2];
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    double longest = 0.0;
    for (int k = 0; k < 3; ++k)
      longest = std::max(
          longest,
          std::sqrt(CGAL::to_double(CGAL::squared_distance(f->vertex(k)->point(), f->vertex((k + 1) % 3)->point()))));
    if (longest > 2.5 * typical) continue;
    tris.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
  }
  return tris;
}

}  // namespace

AnalysisResult analyse_triangles(const GridData& g, const AnalyseOptions& options) {
  AnalysisResult r;
  r.method = Method::kTriangles;
  r.fibre_angles = options.fibre_angles;
  const Index n = g.n_points();
  r.points.resize(n);
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Index> usable;
  bool all_ij = g.has_ij;
  for (Index p = 0; p < n; ++p) {
    if (!g.has_undeformed(p))
      r.points[p].status = g.not_measured_undeformed(p) ? kStatusNotMeasured : kStatusMissingUndeformed;
    else if (!g.has_deformed(p))
      r.points[p].status = g.not_measured_deformed(p) ? kStatusNotMeasured : kStatusMissingDeformed;
    else
      usable.push_back(p);
    if (g.has_ij && g.i[p] == std::numeric_limits<long>::min()) all_ij = false;
  }
  if (usable.size() < 3)
    throw InputError(g.sources.front() + ": fewer than 3 points have both positions; no triangle can be formed");
  const auto tris = all_ij ? grid_triangles(g, usable) : delaunay_triangles(g, usable);
  r.n_triangles = static_cast<Index>(tris.size());
  // Accumulate the embedded right Cauchy-Green tensor C3 = F^T F (3x3, in the
  // undeformed tangent plane) and F per mark.
  std::vector<Mat3> csum(n, Mat3::Zero()), fsum(n, Mat3::Zero());
  std::vector<Vec3> nsum(n, Vec3::Zero());  // consistently oriented triangle normals
  std::vector<int> count(n, 0);
  for (const auto& t : tris) {
    Mat32 G, gg;
    G.col(0) = (g.undeformed.row(t[1]) - g.undeformed.row(t[0])).transpose();
    G.col(1) = (g.undeformed.row(t[2]) - g.undeformed.row(t[0])).transpose();
    gg.col(0) = (g.deformed.row(t[1]) - g.deformed.row(t[0])).transpose();
    gg.col(1) = (g.deformed.row(t[2]) - g.deformed.row(t[0])).transpose();
    const Mat2 M = G.transpose() * G;
    if (!(M.determinant() > 1e-12 * M.trace() * M.trace())) continue;
    const Mat2 Minv = M.inverse();
    const Mat3 F = gg * Minv * G.transpose();  // maps undeformed tangents to deformed ones
    const Mat3 C = F.transpose() * F;
    const Vec3 normal = G.col(0).cross(G.col(1)).normalized();
    for (Index p : t) {
      nsum[p] += normal;
      csum[p] += C;
      fsum[p] += F;
      ++count[p];
    }
  }
  // One orientation for the whole part, as in the surface method: the normal
  // towards +Z (triangle lists are consistently oriented, but either way round).
  Vec3 total = Vec3::Zero();
  for (const Vec3& v : nsum) total += v;
  const double scale_n = total.norm();
  if (total.z() < -1e-9 * scale_n || (std::abs(total.z()) <= 1e-9 * scale_n && total.y() < 0))
    for (Vec3& v : nsum) v = -v;
  for (Index p : usable) {
    PointResult& pr = r.points[p];
    if (count[p] == 0) {
      pr.status = kStatusNoTriangle;
      continue;
    }
    const Mat3 C = csum[p] / count[p], F = fsum[p] / count[p];
    Eigen::SelfAdjointEigenSolver<Mat3> es(C);
    const Vec3 l2 = es.eigenvalues();  // ascending; l2[0] ~ 0 is the normal direction
    if (!(l2[1] > 0.0)) {
      pr.status = kStatusDegenerate;
      continue;
    }
    SurfaceStrain s;
    s.lambda1 = std::sqrt(l2[2]);
    s.lambda2 = std::sqrt(l2[1]);
    s.dir1_undeformed = es.eigenvectors().col(2);
    s.dir2_undeformed = es.eigenvectors().col(1);
    s.dir1_deformed = (F * s.dir1_undeformed).normalized();
    s.dir2_deformed = (F * s.dir2_undeformed).normalized();
    s.normal_undeformed = s.dir1_undeformed.cross(s.dir2_undeformed);
    s.normal_deformed = s.dir1_deformed.cross(s.dir2_deformed).normalized();
    pr.strain = s;
    if (options.fibre_angles.size() == 2) {
      Mat32 Gp;
      // Tangent frame oriented by the triangles' normal (eigenvector signs are arbitrary).
      Gp.col(0) = s.dir1_undeformed;
      Gp.col(1) = nsum[p].cross(s.dir1_undeformed).normalized();
      for (double angle : options.fibre_angles) {
        const auto a0 = tangent_at_angle(Gp, Vec3::UnitX(), angle);
        Vec3 a = a0 ? Vec3(F * *a0) : Vec3::Zero();
        pr.fibres.push_back(FibreResult{a.normalized(), a.norm()});
      }
      pr.shear_angle_deg = trellis_shear_deg(std::abs(options.fibre_angles[1] - options.fibre_angles[0]),
                                             pr.fibres[0].direction, pr.fibres[1].direction);
    }
  }
  r.times.strain = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace sf::gsa

#pragma once
// Nearest-point projection of 3-D points onto a bicubic Hermite surface mesh
// ("find xi", notes/fitting.md section 1.4).
//
// For a point p the projector looks for the element e and xi in [0,1]^2 that
// minimise f(xi) = |p - x(xi)|^2 over the whole mesh, where x(xi) is the field
// given by `parameters` (usually mesh.geometry(); units of p and x alike, e.g. mm).
//
// Algorithm (SurfaceProjector::project):
//  1. Candidates. Every element contributes a samples x samples grid of points
//     x(xi) at xi = ((i + 1/2)/samples, (j + 1/2)/samples) to a kd-tree (built
//     once in the constructor). The `candidates` nearest samples of p give the
//     candidate elements (distinct, in order of their nearest sample) and each
//     one's start xi (its nearest sample).
//  2. Pruning. The patch lies inside the convex hull of its 16 Bezier control
//     points, so the distance from p to their bounding box is a lower bound of
//     the distance to the element. A candidate whose bound is not below the best
//     distance found so far is skipped, as is an element where an earlier
//     candidate's walk already ended.
//  3. Newton per candidate (bound-constrained, full Hessian):
//       r = p - x,  g_i = -x,i . r,  H_ij = x,i . x,j - r . x,ij
//     step d = -H^-1 g; where H is not positive definite (p beyond the centre
//     of curvature) the Gauss-Newton matrix x,i . x,j is used instead, shifted by
//     1e-8 of its trace (Levenberg) so that it stays invertible where x,1 = 0 at
//     the apex of a collapsed element. |d| is limited to a trust radius of 0.5 in
//     xi; steps that increase f (beyond round-off) are halved. xi is clamped to
//     [0,1]^2; a component that sits on a bound with the gradient pushing outward
//     is dropped and the 1-D problem in the other component solved (sliding along
//     the edge). Converged when the xi step is below `xi_tolerance`; that last
//     step is still applied (to first order), so xi is usually good to ~1e-15.
//  4. Walking. When the element's iteration ends on an edge with the gradient
//     pointing outward (the foot point lies beyond the edge by more than
//     xi_tolerance):
//       * edge with a neighbour: continue in the neighbour at the mapped xi
//         (mesh.neighbour(): its edge, `reversed` flips the edge parameter);
//       * free (boundary) edge: stop, status kOnFreeEdge (the point lies beyond
//         the sheet's edge; the distance then has a tangential part);
//       * degenerate apex edge of a collapsed element (xi2 = 0): not an exit
//         across an edge; the walk continues in the collapsed element around the
//         same apex whose radial direction best matches p - x (passing "through"
//         the pole); with no such element it stops there, converged.
//     Walking back over the edge just crossed ends the walk (the minimum lies on
//     that edge). max_iterations counts over the whole walk, which bounds the hops.
//  5. The result is the candidate with the smallest distance.
//
// Each point is processed independently; the batch project_all() visits the
// points in Morton (Z-curve) order for cache locality, splits them over
// std::threads, and its output does not depend on the thread count or order.
// Cost: ~1-2 us per point and core for a 60 x 60 mesh with points near the
// surface (bench/projection_bench.cpp); about half of it is the kd-tree query.
//
// The projector copies everything it needs (element parameters, topology): the
// mesh may change or go away afterwards. The mesh's topology must be built
// (mesh.build_topology(); the generators do). Projectors are immutable and
// cheap to copy (shared state); one projector can serve many threads.

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::mesh {

struct ProjectionOptions {
  int candidates = 8;           // nearest kd-tree samples queried per point (>= 1)
  int samples_per_edge = 6;     // kd-tree samples per element: samples x samples (>= 1)
  int max_iterations = 30;      // Newton iterations per candidate, over all hops (>= 1)
  double xi_tolerance = 1e-10;  // convergence: xi step below this (> 0, < 0.1)
  int threads = 0;              // project_all(): 0 = sf::default_threads() (common/core/parallel.hpp)

  // Throws sf::InputError naming the option, what was expected and what was found.
  void validate() const;
};

struct Projection {
  enum class Status {
    kConverged,     // local minimum of |p - x| (interior, or on an edge/apex with no exit)
    kOnFreeEdge,    // clamped at a boundary edge: p lies beyond the sheet's edge, and
                    // `distance` has a tangential part
    kNotConverged,  // max_iterations spent (over the walk); the last point reached is reported
    kFailed,        // no result: non-finite input, empty mesh, element out of range
  };

  Index element = -1;                                         // element of the closest point (-1 when kFailed)
  Vec2 xi = Vec2::Zero();                                     // its xi in [0,1]^2
  Vec3 point = Vec3::Zero();                                  // the closest point x(element, xi)
  double distance = std::numeric_limits<double>::infinity();  // |p - point|; infinity when kFailed
  Status status = Status::kFailed;
  int iterations = 0;  // Newton iterations of the run that produced the result

  bool ok() const { return status == Status::kConverged || status == Status::kOnFreeEdge; }
  // One line, e.g. "converged e=12 xi=(0.25,0.5) d=0.0123 it=3".
  std::string brief() const;
};

const char* to_string(Projection::Status status);

class SurfaceProjector {
 public:
  // `parameters`: n_dofs x 3 nodal parameters of the surface (usually mesh.geometry()).
  // Throws sf::InputError on a shape mismatch or invalid options.
  SurfaceProjector(const SurfaceMesh& mesh, const Eigen::Ref<const MatX>& parameters, ProjectionOptions options = {});

  // Closest point of the surface to p.
  Projection project(const Vec3& p) const;
  // Batch (n_points x 3); result[i] belongs to row i. Parallel over options().threads.
  // (Not an overload of project(): Eigen converts between Vec3 and Points3
  // implicitly, which would make calls with expressions ambiguous.)
  std::vector<Projection> project_all(const Eigen::Ref<const Points3>& points) const;
  // Newton from a start guess in `element` (xi_start is clamped to [0,1]^2),
  // walking into neighbours as described above; no kd-tree search. Use it to
  // re-project a point whose previous location is known. kFailed when element is
  // out of range or p is not finite.
  Projection refine(const Vec3& p, Index element, const Vec2& xi_start) const;
  // refine() for every row of `points` from its own start (same length), in
  // parallel like project_all(). Throws sf::InputError on a length mismatch.
  std::vector<Projection> refine_all(const Eigen::Ref<const Points3>& points, const std::vector<Index>& elements,
                                     const std::vector<Vec2>& xi_start) const;

  const ProjectionOptions& options() const;
  Index n_elements() const;
  Index n_samples() const;  // points in the kd-tree

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace sf::mesh

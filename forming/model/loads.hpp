#pragma once
// External loads on ply bricks: follower and dead pressure on element faces, dead
// tractions on faces, body forces (gravity) and nodal forces, assembled into a global
// force f_ext(x) and its derivative K_ext = d f_ext / dx (the load-correction matrix,
// non-zero only for follower pressure).
//
// Faces of brick e (xi = (xi1, xi2, xi3) in [0,1]^3, xi3 = 0 bottom layer):
//   kBottom xi3 = 0, kTop xi3 = 1, kXi1Min xi1 = 0, kXi1Max xi1 = 1, kXi2Min xi2 = 0,
//   kXi2Max xi2 = 1.
// Each face is parameterised by (s, t) in [0,1]^2 chosen so that x,s x x,t points
// OUT of the element when the element is right-handed (det dx/dxi > 0):
//   kTop (xi1, xi2), kBottom (xi2, xi1), kXi1Max (xi2, xi3), kXi1Min (xi3, xi2),
//   kXi2Max (xi3, xi1), kXi2Min (xi1, xi3).
//
// Pressure p (MPa = N/mm^2, positive pushes INTO the body, like a gas on a membrane):
//   follower  f_k = -p  int N_k (x,s x x,t) ds dt      (current face: area and normal follow)
//             K_ext[(k,i),(l,j)] = -p int N_k ( N_l,t [x,s]x - N_l,s [x,t]x )_ij ds dt
//             ([a]x = the cross-product matrix, [a]x b = a x b). K_ext is not symmetric
//             in general (it is for a closed or fixed-boundary surface).
//   dead      the same with the reference face X (force fixed at its reference value).
// Traction t (N/mm^2 per REFERENCE area, dead): f_k = int N_k t |X,s x X,t| ds dt.
// Body force b (N/mm^3 per reference volume, dead; gravity: b = rho g):
//   f_k = int N_k b det(dX/dxi) dxi.
// Nodal force: N on a global dof.
// Quadrature: 4 x 4 Gauss on faces (with 2 through the thickness for side faces) and the
// model's brick rule for body forces. The forces are mapped to global dofs through the
// element maps (arc-length scale factors included), as the internal forces are.
//
// Units: mm, N, MPa.
#include <functional>
#include <utility>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/sparse.hpp"
#include "forming/model/model.hpp"
#include "forming/model/ramp.hpp"

namespace sf::forming {

// External force at load factor (or time) lambda and positions x, and (when asked for)
// its derivative d f_ext / dx (empty when the load does not depend on x).
struct ExternalLoad {
  VecX force;                    // n_dofs, N
  linalg::SparseMatrix tangent;  // n_dofs x n_dofs or empty, N/mm
};
// The load as the solvers see it: the static solver passes the load factor, the dynamic
// one the time.
using LoadFunction = std::function<ExternalLoad(double lambda, const VecX& x, bool want_tangent)>;

enum class BrickFace { kBottom, kTop, kXi1Min, kXi1Max, kXi2Min, kXi2Max };

// A brick face as a parameterised surface: the xi direction held fixed (at 0 or 1) and
// the directions of the face parameters (s, t), ordered so that d/ds x d/dt points out
// of the brick (pressure loads and contact surfaces rely on that orientation).
struct FaceMap {
  int fixed_dir;    // xi direction held fixed
  double fixed_at;  // its value (0 or 1)
  int s_dir, t_dir;
};
FaceMap face_map(BrickFace f);
// The brick point (xi) of face parameters (s, t).
Vec3 face_point(const FaceMap& fm, double s, double t);

struct FaceRef {
  int body = 0;
  Index element = 0;
  BrickFace face = BrickFace::kTop;
};

struct PressureLoad {
  std::vector<FaceRef> faces;
  double pressure = 0.0;  // MPa, positive into the body
  bool follower = true;
};

struct TractionLoad {
  std::vector<FaceRef> faces;
  Vec3 traction = Vec3::Zero();  // N/mm^2 per reference area
};

struct BodyForceLoad {
  int body = 0;
  Vec3 force_density = Vec3::Zero();  // N/mm^3 per reference volume
};

struct NodalForce {
  Index dof = -1;
  double value = 0.0;  // N
};

struct LoadSet {
  std::vector<PressureLoad> pressures;
  std::vector<TractionLoad> tractions;
  std::vector<BodyForceLoad> body_forces;
  std::vector<NodalForce> nodal;

  bool empty() const { return pressures.empty() && tractions.empty() && body_forces.empty() && nodal.empty(); }
  // True when some load depends on the current positions (follower pressure): its
  // tangent is then non-zero and in general unsymmetric.
  bool has_follower() const;
  // Assembles every load at positions x (n_dofs), each scaled by `factor` (its tangent is
  // empty unless has_follower()).
  ExternalLoad assemble(const Model& model, const Eigen::Ref<const VecX>& x, double factor, bool want_tangent) const;
};

// Load sets with their ramps: f_ext(lambda, x) = sum_i ramp_i(lambda) f_i(x), lambda
// clamped to [0, 1] (a dynamic run passes t / end_time).
// A load factor given as a table over the load factor: (lambda_k, factor_k) with
// lambda_0 = 0 < lambda_1 < ..., linear between, held at the last factor beyond the last
// lambda (a pressure's time table, t_k / process time; forming/case/build.cpp).
struct LoadTable {
  std::vector<double> lambda, factor;
  double at(double l) const;
};

struct RampedLoads {
  std::vector<std::pair<Ramp, LoadSet>> sets;
  std::vector<std::pair<LoadTable, LoadSet>> tabled;  // sets whose factor follows a table
  bool follower = false;                              // some load follows the deformation (unsymmetric tangent)

  bool empty() const { return sets.empty() && tabled.empty(); }
  void add(Ramp ramp, LoadSet set);
  void add(LoadTable table, LoadSet set);
  ExternalLoad at(const Model& model, double lambda, const VecX& x, bool want_tangent) const;
};

// Total area of the faces, reference (x = reference positions) or current (mm^2).
double face_area(const Model& model, const std::vector<FaceRef>& faces, const Eigen::Ref<const VecX>& x);

}  // namespace sf::forming

#pragma once
// A surface of a body for contact: a set of faces of its ply bricks (top or bottom faces,
// or side faces along an edge), each a patch x(s, t), (s, t) in [0,1]^2, of the brick's
// interpolation restricted to the face (forming/model/loads.hpp: face numbering and
// the (s, t) orientation, x,s x x,t pointing OUT of the brick).
//
// Face basis. On a face only some of the brick's 32 functions are non-zero: the 16 of
// one node layer on the top and bottom faces (bicubic Hermite in (xi1, xi2)), 8 on a
// side face (cubic Hermite along the ply edge x linear through the thickness). Each of
// these "active" functions is a product f_s(s) f_t(t) of a 1-D cubic Hermite or linear
// Lagrange function in each face direction:
//
//   face   fixed   s     t      active brick functions k = 4 n + d, n = a + 2b + 4c
//   top    xi3=1   xi1   xi2    c = 1 (16)          H(s) H(t)
//   bottom xi3=0   xi2   xi1    c = 0 (16)          H(s) H(t)
//   xi1min xi1=0   xi3   xi2    a = 0, k1 = 0 (8)   L(s) H(t)      (k1, k2: d = k1 + 2 k2)
//   xi1max xi1=1   xi2   xi3    a = 1, k1 = 0 (8)   H(s) L(t)
//   xi2min xi2=0   xi1   xi3    b = 0, k2 = 0 (8)   H(s) L(t)
//   xi2max xi2=1   xi3   xi1    b = 1, k2 = 0 (8)   L(s) H(t)
//
// The face's positions are the active functions' element parameters (scale factors
// applied, forming/model/ply_mesh.hpp), n_active x 3; FaceDofs maps them to the model's
// dofs: entry 3 a + i of a face vector (function a, coordinate i) takes coef times dof.
//
// Bounding boxes: the face is a tensor-product Bezier patch of degree 3 (Hermite
// directions: control points p0, p0 + d0/3, p1 - d1/3, p1) by 3 or 1, so it lies inside
// the convex hull, hence the box, of its 16 or 8 control points (a rigorous box, cheap
// to recompute as the surface moves).
//
// Units: mm.
#include <array>
#include <vector>

#include "common/core/types.hpp"
#include "forming/model/loads.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// Values and (s, t)-derivatives of the active functions of one face kind at a point.
struct FaceBasisValues {
  int n = 0;  // active functions (16 or 8)
  std::array<double, 16> value{}, ds{}, dt{}, dss{}, dst{}, dtt{};
};

// The active functions of a face kind (see header).
class FaceBasis {
 public:
  explicit FaceBasis(BrickFace face);
  BrickFace face() const { return face_; }
  int n_active() const { return n_; }
  // Brick function index (0..31) of active function a.
  int brick_function(int a) const { return brick_[static_cast<std::size_t>(a)]; }
  // The brick point xi of face point (s, t).
  Vec3 xi(double s, double t) const;
  // second: also the second derivatives.
  FaceBasisValues evaluate(double s, double t, bool second) const;
  // Bezier control points (n_active x n_active matrix B: control = B x_face), for boxes.
  const MatX& bezier() const { return bezier_; }
  // Face corners (s, t) = (0,0), (1,0), (0,1), (1,1) as brick local nodes (a + 2b + 4c).
  const std::array<int, 4>& corner_nodes() const { return corners_; }
  // The function values at the 3 x 3 grid (s, t) = (i / 2, j / 2), point i + 3 j, as
  // evaluate() gives them (the start of every closest-point projection).
  const std::array<double, 16>& grid_values(int point) const { return grid_[static_cast<std::size_t>(point)]; }

 private:
  BrickFace face_;
  int n_ = 0;
  std::array<int, 16> brick_{};
  // Per active function: 1-D index in s and t (Hermite 0..3 or Lagrange 0..1) and whether
  // that direction is linear.
  std::array<int, 16> is_{}, it_{};
  bool s_linear_ = false, t_linear_ = false;
  MatX bezier_;
  std::array<int, 4> corners_{};
  std::array<std::array<double, 16>, 9> grid_{};
};

// The model dofs of a face vector: local entry 3 a + i takes coef times dof (one or two
// terms per entry: a collapsed apex maps one element parameter to two global ones).
struct FaceDofs {
  std::vector<Index> dofs;
  std::vector<double> coefs;
  std::vector<int> local;
};

// One face of a contact surface.
struct SurfaceFace {
  Index element = 0;
  BrickFace face = BrickFace::kTop;
  FaceDofs dofs;                    // into the model
  std::array<Index, 4> corners{};   // ply nodes at the corners (edge matching)
  std::array<bool, 4> free_edge{};  // edges s = 0, s = 1, t = 0, t = 1 on the surface's boundary
};

class ContactSurface {
 public:
  // The faces (element, face) of body `body` of `model`. Throws sf::InputError for an
  // element outside the body or an empty list.
  ContactSurface(const Model& model, int body, const std::vector<std::pair<Index, BrickFace>>& faces);
  // Every top (or bottom) face of the body.
  static ContactSurface whole_face(const Model& model, int body, bool top);

  int body() const { return body_; }
  Index n_faces() const { return static_cast<Index>(faces_.size()); }
  const SurfaceFace& face(Index f) const { return faces_[static_cast<std::size_t>(f)]; }
  const FaceBasis& basis(Index f) const { return bases_[kind_[static_cast<std::size_t>(f)]]; }
  // The face's positions (n_active x 3) for model positions x (n_dofs).
  MatX positions(Index f, const Eigen::Ref<const VecX>& x) const;
  // Thickness of the body's ply (mm): a length scale for tolerances.
  double thickness() const { return thickness_; }

 private:
  int body_ = 0;
  double thickness_ = 0.0;
  std::vector<FaceBasis> bases_;  // one per BrickFace kind, in enum order
  std::vector<SurfaceFace> faces_;
  std::vector<std::size_t> kind_;  // index into bases_ per face
};

// Axis-aligned box of a face's Bezier control points.
struct Box {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool contains(const Vec3& p, double margin) const {
    return (p.array() >= lo.array() - margin).all() && (p.array() <= hi.array() + margin).all();
  }
};
Box face_box(const FaceBasis& basis, const Eigen::Ref<const MatX>& positions);

}  // namespace sf::forming

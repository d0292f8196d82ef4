#include "forming/contact/contact_surface.hpp"

#include <algorithm>
#include <map>
#include <utility>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"

namespace sf::forming {
namespace {

// 1-D functions of a face direction at u: values and first, second derivatives
// (4 cubic Hermite functions, or 2 linear Lagrange ones padded with zeros).
struct Line1D {
  std::array<double, 4> v{}, d{}, dd{};
};

Line1D line_functions(double u, bool linear, bool second) {
  Line1D l;
  if (linear) {
    const auto v = basis::linear_lagrange(u, 0), d = basis::linear_lagrange(u, 1);
    l.v = {v[0], v[1], 0.0, 0.0};
    l.d = {d[0], d[1], 0.0, 0.0};
  } else {
    l.v = basis::cubic_hermite(u, 0);
    l.d = basis::cubic_hermite(u, 1);
    if (second) l.dd = basis::cubic_hermite(u, 2);
  }
  return l;
}

// Hermite (value 0, slope 0, value 1, slope 1) to Bezier control points of a cubic.
const double kHermiteToBezier[4][4] = {
    {1.0, 0.0, 0.0, 0.0}, {1.0, 1.0 / 3.0, 0.0, 0.0}, {0.0, 0.0, 1.0, -1.0 / 3.0}, {0.0, 0.0, 1.0, 0.0}};

double to_bezier(bool linear, int j, int i) {
  if (linear) return i == j ? 1.0 : 0.0;
  return kHermiteToBezier[j][i];
}

}  // namespace

FaceBasis::FaceBasis(BrickFace face) : face_(face) {
  const FaceMap ax = face_map(face);  // forming/model/loads.hpp: the faces pressure loads use
  s_linear_ = ax.s_dir == 2;
  t_linear_ = ax.t_dir == 2;
  for (int k = 0; k < kBrickFunctions; ++k) {
    const int node = k / 4, d = k % 4;
    const int a = node & 1, b = (node >> 1) & 1, c = node >> 2;
    const int k1 = d & 1, k2 = d >> 1;
    const std::array<int, 3> index = {2 * a + k1, 2 * b + k2, c};  // H in xi1, H in xi2, L in xi3
    // The fixed direction's factor: H_i(0) = [i == 0], H_i(1) = [i == 2], L_c(v) = [c == v].
    const int fixed = index[static_cast<std::size_t>(ax.fixed_dir)];
    const bool active =
        ax.fixed_dir == 2 ? fixed == static_cast<int>(ax.fixed_at) : fixed == (ax.fixed_at == 0.0 ? 0 : 2);
    if (!active) continue;
    brick_[static_cast<std::size_t>(n_)] = k;
    is_[static_cast<std::size_t>(n_)] = index[static_cast<std::size_t>(ax.s_dir)];
    it_[static_cast<std::size_t>(n_)] = index[static_cast<std::size_t>(ax.t_dir)];
    ++n_;
  }
  SF_ASSERT(n_ == 16 || n_ == 8, "a brick face has 16 or 8 active functions");
  const int ns = s_linear_ ? 2 : 4, nt = t_linear_ ? 2 : 4;
  bezier_ = MatX::Zero(ns * nt, n_);
  for (int jt = 0; jt < nt; ++jt)
    for (int js = 0; js < ns; ++js)
      for (int a = 0; a < n_; ++a)
        bezier_(js + ns * jt, a) = to_bezier(s_linear_, js, is_[static_cast<std::size_t>(a)]) *
                                   to_bezier(t_linear_, jt, it_[static_cast<std::size_t>(a)]);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) grid_[static_cast<std::size_t>(i + 3 * j)] = evaluate(0.5 * i, 0.5 * j, false).value;
  for (int c = 0; c < 4; ++c) {
    const Vec3 p = xi(c & 1, c >> 1);
    corners_[static_cast<std::size_t>(c)] =
        static_cast<int>(p[0] + 0.5) + 2 * static_cast<int>(p[1] + 0.5) + 4 * static_cast<int>(p[2] + 0.5);
  }
}

Vec3 FaceBasis::xi(double s, double t) const { return face_point(face_map(face_), s, t); }

FaceBasisValues FaceBasis::evaluate(double s, double t, bool second) const {
  const Line1D fs = line_functions(s, s_linear_, second), ft = line_functions(t, t_linear_, second);
  FaceBasisValues v;
  v.n = n_;
  for (int a = 0; a < n_; ++a) {
    const auto i = static_cast<std::size_t>(is_[static_cast<std::size_t>(a)]);
    const auto j = static_cast<std::size_t>(it_[static_cast<std::size_t>(a)]);
    const auto k = static_cast<std::size_t>(a);
    v.value[k] = fs.v[i] * ft.v[j];
    v.ds[k] = fs.d[i] * ft.v[j];
    v.dt[k] = fs.v[i] * ft.d[j];
    if (second) {
      v.dss[k] = fs.dd[i] * ft.v[j];
      v.dst[k] = fs.d[i] * ft.d[j];
      v.dtt[k] = fs.v[i] * ft.dd[j];
    }
  }
  return v;
}

ContactSurface::ContactSurface(const Model& model, int body, const std::vector<std::pair<Index, BrickFace>>& faces)
    : body_(body) {
  if (body < 0 || body >= model.n_bodies())
    throw InputError("contact surface: body " + std::to_string(body) + " is not in the model");
  if (faces.empty()) throw InputError("contact surface: no faces");
  const PlyMesh& ply = model.ply(body);
  thickness_ = ply.thickness();
  for (BrickFace f : {BrickFace::kBottom, BrickFace::kTop, BrickFace::kXi1Min, BrickFace::kXi1Max, BrickFace::kXi2Min,
                      BrickFace::kXi2Max})
    bases_.emplace_back(f);
  std::map<std::pair<Index, Index>, int> edge_count;
  for (const auto& [e, f] : faces) {
    if (e < 0 || e >= ply.n_elements())
      throw InputError("contact surface: element " + std::to_string(e) + " is not in body " + std::to_string(body));
    const std::size_t kind = static_cast<std::size_t>(f);
    const FaceBasis& fb = bases_[kind];
    SurfaceFace sf;
    sf.element = e;
    sf.face = f;
    const BrickMap map = ply.element_map(e);
    for (int a = 0; a < fb.n_active(); ++a) {
      const int k = fb.brick_function(a);
      for (int term = 0; term < map.n_terms[static_cast<std::size_t>(k)]; ++term) {
        const mesh::DofTerm& dt = map.terms[static_cast<std::size_t>(k)][static_cast<std::size_t>(term)];
        if (dt.coef == 0.0) continue;
        for (int i = 0; i < 3; ++i) {
          sf.dofs.dofs.push_back(model.offset(body) + 3 * dt.dof + i);
          sf.dofs.coefs.push_back(dt.coef);
          sf.dofs.local.push_back(3 * a + i);
        }
      }
    }
    const mesh::Element& el = ply.surface().element(e);
    for (int c = 0; c < 4; ++c) {
      const int node = fb.corner_nodes()[static_cast<std::size_t>(c)];
      sf.corners[static_cast<std::size_t>(c)] = ply.node(el.nodes[static_cast<std::size_t>(node % 4)], node / 4);
    }
    faces_.push_back(std::move(sf));
    kind_.push_back(kind);
  }
  // Edges s = 0 (corners 0, 2), s = 1 (1, 3), t = 0 (0, 1), t = 1 (2, 3).
  static constexpr int kEdgeCorners[4][2] = {{0, 2}, {1, 3}, {0, 1}, {2, 3}};
  const auto key = [](const SurfaceFace& sf, int edge) {
    const Index a = sf.corners[static_cast<std::size_t>(kEdgeCorners[edge][0])];
    const Index b = sf.corners[static_cast<std::size_t>(kEdgeCorners[edge][1])];
    return std::make_pair(std::min(a, b), std::max(a, b));
  };
  for (const SurfaceFace& sf : faces_)
    for (int edge = 0; edge < 4; ++edge) ++edge_count[key(sf, edge)];
  for (SurfaceFace& sf : faces_)
    for (int edge = 0; edge < 4; ++edge) {
      const auto k = key(sf, edge);
      sf.free_edge[static_cast<std::size_t>(edge)] = k.first != k.second && edge_count[k] == 1;  // apex: not free
    }
}

ContactSurface ContactSurface::whole_face(const Model& model, int body, bool top) {
  if (body < 0 || body >= model.n_bodies())
    throw InputError("contact surface: body " + std::to_string(body) + " is not in the model");
  std::vector<std::pair<Index, BrickFace>> faces;
  for (Index e = 0; e < model.ply(body).n_elements(); ++e)
    faces.emplace_back(e, top ? BrickFace::kTop : BrickFace::kBottom);
  return ContactSurface(model, body, faces);
}

MatX ContactSurface::positions(Index f, const Eigen::Ref<const VecX>& x) const {
  const SurfaceFace& sf = face(f);
  MatX p = MatX::Zero(basis(f).n_active(), 3);
  for (std::size_t j = 0; j < sf.dofs.dofs.size(); ++j) {
    const int l = sf.dofs.local[j];
    p(l / 3, l % 3) += sf.dofs.coefs[j] * x[sf.dofs.dofs[j]];
  }
  return p;
}

Box face_box(const FaceBasis& basis, const Eigen::Ref<const MatX>& positions) {
  const MatX control = basis.bezier() * positions;
  Box b;
  for (Index r = 0; r < control.rows(); ++r) b.add(control.row(r).transpose());
  return b;
}

}  // namespace sf::forming

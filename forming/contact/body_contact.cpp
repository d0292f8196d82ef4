#include "forming/contact/body_contact.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <limits>
#include <utility>

#include "common/core/error.hpp"
#include "forming/contact/box_tree.hpp"
#include "forming/contact/face_projection.hpp"

namespace sf::forming {

struct BodyContact::Search : Prepared {
  std::vector<MatX> positions;  // per master face, current
  std::vector<MatX> rates;      // per master face (when rates are wanted)
  std::vector<MatX> moved;      // per master face, displacement since the previous state
  BoxTree tree;
  mutable std::vector<Index> hits;
};

BodyContact::BodyContact(std::string name, const Model& model, ContactSurface slave, ContactSurface master,
                         ContactOptions options)
    : SurfaceContact(std::move(name), model, std::move(slave), options), master_(std::move(master)) {
  if (master_.body() == this->slave().body())
    throw InputError("contact " + this->name() + ": both surfaces belong to body " + std::to_string(master_.body()) +
                     " (self-contact is not supported)");
  reach_ = this->options().search_distance > 0.0 ? this->options().search_distance
                                                 : this->slave().thickness() + master_.thickness();
}

std::unique_ptr<SurfaceContact::Prepared> BodyContact::prepare(const Eigen::Ref<const VecX>& x,
                                                               const InteractionContext&, const VecX* rates,
                                                               const VecX* previous) const {
  auto s = std::make_unique<Search>();
  std::vector<Box> boxes;
  for (Index f = 0; f < master_.n_faces(); ++f) {
    s->positions.push_back(master_.positions(f, x));
    boxes.push_back(face_box(master_.basis(f), s->positions.back()));
    if (rates) s->rates.push_back(master_.positions(f, *rates));
    if (previous) s->moved.push_back(s->positions.back() - master_.positions(f, *previous));
  }
  s->tree = BoxTree(std::move(boxes));
  return s;
}

bool BodyContact::find_partner(const Prepared& prepared, const Vec3& xs, PointKinematics& k, Partner& partner) const {
  const auto& s = static_cast<const Search&>(prepared);
  s.tree.query(xs, reach_, s.hits);
  if (s.hits.empty()) return false;
  FaceFoot best;
  Index best_face = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (const Index f : s.hits) {
    const FaceFoot foot = project_on_face(master_.basis(f), s.positions[static_cast<std::size_t>(f)], xs);
    // Prefer a true closest point over one stopped at an edge, at equal distance.
    const double d = foot.distance * (foot.exit_edge >= 0 ? 1.0 + 1e-12 : 1.0);
    if (d < best_distance) {
      best_distance = d;
      best = foot;
      best_face = f;
    }
  }
  if (best_face < 0 || best.distance > reach_) return false;
  const SurfaceFace& mf = master_.face(best_face);
  if (best.exit_edge >= 0 && mf.free_edge[static_cast<std::size_t>(best.exit_edge)]) return false;
  const Vec3 a = best.x1.cross(best.x2);
  const double la = a.norm();
  if (!(la > 0.0)) return false;  // a degenerate point of the master (collapsed apex)
  const Vec3 n = a / la;
  k.tool = false;
  k.gap = (xs - best.x).dot(n);
  k.normal = n;
  k.gap_gradient = n;
  k.T.col(0) = best.x1;
  k.T.col(1) = best.x2;
  const Mat2 M = k.T.transpose() * k.T;
  k.kappa << n.dot(best.x11), n.dot(best.x12), n.dot(best.x12), n.dot(best.x22);
  const Mat2 H = M - k.gap * k.kappa;
  k.M_inv = M.inverse();
  // Past the centre of curvature the closest-point problem loses its minimum; the
  // Gauss-Newton matrix keeps the tangent usable there.
  k.H_inv = H.determinant() > 1e-12 * M.determinant() && H(0, 0) > 0.0 ? Mat2(H.inverse()) : k.M_inv;
  const FaceBasis& fb = master_.basis(best_face);
  const FaceBasisValues v = fb.evaluate(best.zeta[0], best.zeta[1], false);
  const int ns = k.n_slave;
  for (int b = 0; b < v.n; ++b) {
    const auto i = static_cast<std::size_t>(ns + b);
    const auto ib = static_cast<std::size_t>(b);
    k.phi[i] = -v.value[ib];
    k.rho1[i] = v.ds[ib];
    k.rho2[i] = v.dt[ib];
  }
  k.n = ns + v.n;
  partner.master_dofs = &mf.dofs;
  partner.master_face = best_face;
  const auto face_sum = [&](const MatX& rows, const std::array<double, 16>& w) {
    Vec3 out = Vec3::Zero();
    for (int b = 0; b < v.n; ++b) out += w[static_cast<std::size_t>(b)] * rows.row(b).transpose();
    return out;
  };
  if (!s.rates.empty()) {
    const MatX& r = s.rates[static_cast<std::size_t>(best_face)];
    partner.velocity = face_sum(r, v.value);
    partner.velocity_d1 = face_sum(r, v.ds);
    partner.velocity_d2 = face_sum(r, v.dt);
  }
  if (!s.moved.empty()) partner.displacement = face_sum(s.moved[static_cast<std::size_t>(best_face)], v.value);
  return true;
}

std::string BodyContact::describe() const {
  const auto side = [](const ContactSurface& s) {
    const BrickFace f = s.face(0).face;
    return f == BrickFace::kTop ? "top" : f == BrickFace::kBottom ? "bottom" : "side";
  };
  return "body " + std::to_string(slave().body()) + " " + side(slave()) + " against body " +
         std::to_string(master_.body()) + " " + side(master_);
}

}  // namespace sf::forming

#include "forming/model/loads.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <utility>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "common/quadrature/gauss.hpp"

namespace sf::forming {

FaceMap face_map(BrickFace f) {
  switch (f) {
    case BrickFace::kBottom:
      return {2, 0.0, 1, 0};
    case BrickFace::kTop:
      return {2, 1.0, 0, 1};
    case BrickFace::kXi1Min:
      return {0, 0.0, 2, 1};
    case BrickFace::kXi1Max:
      return {0, 1.0, 1, 2};
    case BrickFace::kXi2Min:
      return {1, 0.0, 0, 2};
    case BrickFace::kXi2Max:
      return {1, 1.0, 2, 0};
  }
  return {2, 1.0, 0, 1};
}

Vec3 face_point(const FaceMap& fm, double s, double t) {
  Vec3 xi;
  xi[fm.fixed_dir] = fm.fixed_at;
  xi[fm.s_dir] = s;
  xi[fm.t_dir] = t;
  return xi;
}

namespace {

constexpr int kFacePoints = 4;  // Gauss points per face direction

Mat3 cross_matrix(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

using BrickPositions = Eigen::Matrix<double, kBrickFunctions, 3>;

// Element positions of every body at x, computed once per assembly.
struct BodyFields {
  std::vector<MatX> current, reference;
};

BodyFields body_fields(const Model& model, const Eigen::Ref<const VecX>& x) {
  BodyFields f;
  for (int b = 0; b < model.n_bodies(); ++b) {
    f.current.push_back(PlyMesh::unflatten(x.segment(model.offset(b), model.ply(b).n_dofs())));
    f.reference.push_back(model.ply(b).reference());
  }
  return f;
}

// Scatters an element vector (96) and optionally an element matrix (96 x 96) to global.
void scatter(const Model::ElementDofs& ed, const Eigen::Matrix<double, kBrickDofs, 1>& fe, VecX& force,
             const Eigen::Matrix<double, kBrickDofs, kBrickDofs>* ke, linalg::TripletAssembler* k) {
  const int m = static_cast<int>(ed.dofs.size());
  for (int a = 0; a < m; ++a) force(ed.dofs[a]) += ed.coefs[a] * fe(ed.local[a]);
  if (!ke || !k) return;
  MatX block(m, m);
  for (int c = 0; c < m; ++c)
    for (int a = 0; a < m; ++a) block(a, c) = ed.coefs[a] * ed.coefs[c] * (*ke)(ed.local[a], ed.local[c]);
  k->add_block(ed.dofs, ed.dofs, block);
}

void check_face(const Model& model, const FaceRef& f) {
  if (f.body < 0 || f.body >= model.n_bodies() || f.element < 0 || f.element >= model.ply(f.body).n_elements())
    throw InputError("load on face of body " + std::to_string(f.body) + " element " + std::to_string(f.element) +
                     ": no such element");
}

}  // namespace

bool LoadSet::has_follower() const {
  for (const PressureLoad& p : pressures)
    if (p.follower && p.pressure != 0.0 && !p.faces.empty()) return true;
  return false;
}

ExternalLoad LoadSet::assemble(const Model& model, const Eigen::Ref<const VecX>& x, double factor,
                               bool want_tangent) const {
  SF_ASSERT(x.size() == model.n_dofs(), "positions must have n_dofs entries");
  ExternalLoad out;
  out.force = VecX::Zero(model.n_dofs());
  if (empty() || factor == 0.0) return out;
  const bool tangent = want_tangent && has_follower();
  linalg::TripletAssembler k(model.n_dofs(), model.n_dofs());
  const BodyFields fields = body_fields(model, x);
  const quadrature::Rule1D line = quadrature::gauss_legendre(kFacePoints);

  // Face integrals: pressure (follower or dead) and dead traction.
  auto face_integral = [&](const FaceRef& f, double pressure, bool follower, const Vec3* traction) {
    check_face(model, f);
    const PlyMesh& ply = model.ply(f.body);
    const BrickPositions Xe = ply.element_parameters(f.element, fields.reference[f.body]);
    const BrickPositions xe = ply.element_parameters(f.element, fields.current[f.body]);
    const BrickPositions& geo = (traction || !follower) ? Xe : xe;
    const FaceMap fm = face_map(f.face);
    Eigen::Matrix<double, kBrickDofs, 1> fe = Eigen::Matrix<double, kBrickDofs, 1>::Zero();
    Eigen::Matrix<double, kBrickDofs, kBrickDofs> ke = Eigen::Matrix<double, kBrickDofs, kBrickDofs>::Zero();
    const bool with_tangent = tangent && !traction && follower;
    for (std::size_t a = 0; a < line.points.size(); ++a)
      for (std::size_t b = 0; b < line.points.size(); ++b) {
        const Vec3 xi = face_point(fm, line.points[a], line.points[b]);
        const double w = line.weights[a] * line.weights[b];
        const basis::BrickValues bv = basis::BicubicHermiteLinear::evaluate(xi, basis::kValues | basis::kFirst);
        const Eigen::Matrix<double, kBrickFunctions, 1> ns = bv.first.col(fm.s_dir), nt = bv.first.col(fm.t_dir);
        const Vec3 xs = geo.transpose() * ns, xt = geo.transpose() * nt;
        Vec3 load;  // force per unit (s, t) area
        if (traction)
          load = *traction * xs.cross(xt).norm();
        else
          load = -pressure * xs.cross(xt);
        for (int kf = 0; kf < kBrickFunctions; ++kf) fe.segment<3>(3 * kf) += (w * bv.value[kf]) * load;
        if (!with_tangent) continue;
        const Mat3 cs = cross_matrix(xs), ct = cross_matrix(xt);
        for (int l = 0; l < kBrickFunctions; ++l) {
          const Mat3 dl = (-pressure * w) * (nt[l] * cs - ns[l] * ct);
          for (int kf = 0; kf < kBrickFunctions; ++kf) ke.block<3, 3>(3 * kf, 3 * l) += bv.value[kf] * dl;
        }
      }
    scatter(model.element_dofs(f.body, f.element), factor * fe, out.force, with_tangent ? &ke : nullptr,
            with_tangent ? &k : nullptr);
  };
  for (const PressureLoad& p : pressures)
    if (p.pressure != 0.0)
      for (const FaceRef& f : p.faces) face_integral(f, p.pressure, p.follower, nullptr);
  for (const TractionLoad& t : tractions)
    if (!t.traction.isZero(0.0))
      for (const FaceRef& f : t.faces) face_integral(f, 0.0, false, &t.traction);

  // Body forces over the reference volume.
  const quadrature::TensorRule<3> rule = model.rule().brick();
  for (const BodyForceLoad& bf : body_forces) {
    if (bf.force_density.isZero(0.0)) continue;
    if (bf.body < 0 || bf.body >= model.n_bodies())
      throw InputError("body force on body " + std::to_string(bf.body) + ": no such body");
    const PlyMesh& ply = model.ply(bf.body);
    for (Index e = 0; e < ply.n_elements(); ++e) {
      const BrickPositions Xe = ply.element_parameters(e, fields.reference[bf.body]);
      Eigen::Matrix<double, kBrickDofs, 1> fe = Eigen::Matrix<double, kBrickDofs, 1>::Zero();
      for (int q = 0; q < rule.size(); ++q) {
        const basis::BrickValues bv =
            basis::BicubicHermiteLinear::evaluate(rule.points[q], basis::kValues | basis::kFirst);
        const Mat3 g = Xe.transpose() * bv.first;
        const double dv = rule.weights[q] * g.determinant();
        for (int kf = 0; kf < kBrickFunctions; ++kf) fe.segment<3>(3 * kf) += (dv * bv.value[kf]) * bf.force_density;
      }
      scatter(model.element_dofs(bf.body, e), factor * fe, out.force, nullptr, nullptr);
    }
  }
  for (const NodalForce& nf : nodal) {
    if (nf.dof < 0 || nf.dof >= model.n_dofs())
      throw InputError("nodal force on dof " + std::to_string(nf.dof) + ": outside 0.." +
                       std::to_string(model.n_dofs() - 1));
    out.force(nf.dof) += factor * nf.value;
  }
  if (tangent) out.tangent = factor * k.compress();
  return out;
}

double LoadTable::at(double l) const {
  if (lambda.empty()) return 0.0;
  if (l <= lambda.front()) return factor.front();
  for (std::size_t k = 1; k < lambda.size(); ++k)
    if (l <= lambda[k]) {
      const double s = (l - lambda[k - 1]) / (lambda[k] - lambda[k - 1]);
      return factor[k - 1] + s * (factor[k] - factor[k - 1]);
    }
  return factor.back();
}

void RampedLoads::add(LoadTable table, LoadSet set) {
  follower = follower || set.has_follower();
  tabled.emplace_back(std::move(table), std::move(set));
}

void RampedLoads::add(Ramp ramp, LoadSet set) {
  follower = follower || set.has_follower();
  sets.emplace_back(ramp, std::move(set));
}

ExternalLoad RampedLoads::at(const Model& model, double lambda, const VecX& x, bool want_tangent) const {
  ExternalLoad out;
  out.force = VecX::Zero(model.n_dofs());
  const auto add = [&](const LoadSet& set, double factor) {
    if (factor == 0.0) return;
    ExternalLoad l = set.assemble(model, x, factor, want_tangent);
    out.force += l.force;
    if (l.tangent.size() == 0) return;
    if (out.tangent.size() == 0)
      out.tangent = std::move(l.tangent);
    else
      out.tangent += l.tangent;
  };
  for (const auto& [ramp, set] : sets) add(set, ramp_value(ramp, std::clamp(lambda, 0.0, 1.0)));
  for (const auto& [table, set] : tabled) add(set, table.at(std::clamp(lambda, 0.0, 1.0)));
  return out;
}

double face_area(const Model& model, const std::vector<FaceRef>& faces, const Eigen::Ref<const VecX>& x) {
  const BodyFields fields = body_fields(model, x);
  const quadrature::Rule1D line = quadrature::gauss_legendre(kFacePoints);
  double area = 0.0;
  for (const FaceRef& f : faces) {
    check_face(model, f);
    const BrickPositions xe = model.ply(f.body).element_parameters(f.element, fields.current[f.body]);
    const FaceMap fm = face_map(f.face);
    for (std::size_t a = 0; a < line.points.size(); ++a)
      for (std::size_t b = 0; b < line.points.size(); ++b) {
        const Vec3 xi = face_point(fm, line.points[a], line.points[b]);
        const basis::BrickValues bv = basis::BicubicHermiteLinear::evaluate(xi, basis::kFirst);
        const Vec3 xs = xe.transpose() * bv.first.col(fm.s_dir), xt = xe.transpose() * bv.first.col(fm.t_dir);
        area += line.weights[a] * line.weights[b] * xs.cross(xt).norm();
      }
  }
  return area;
}

}  // namespace sf::forming

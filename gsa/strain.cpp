#include "gsa/strain.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace sf::gsa {

double SurfaceStrain::true_strain(int i) const { return std::log(i == 0 ? lambda1 : lambda2); }

std::optional<SurfaceStrain> surface_strain(const Mat32& G, const Mat32& g) {
  const Mat2 M = G.transpose() * G;
  const Mat2 m = g.transpose() * g;
  const double detM = M.determinant(), detm = m.determinant();
  const double scaleM = M.trace() * M.trace(), scalem = m.trace() * m.trace();
  if (!(detM > 1e-14 * scaleM) || !(detm > 1e-14 * scalem) || !G.allFinite() || !g.allFinite()) return std::nullopt;
  // Generalised symmetric eigenproblem m v = l M v (M SPD); eigenvalues ascending.
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat2> es(m, M);
  if (es.info() != Eigen::Success) return std::nullopt;
  const Vec2 l2 = es.eigenvalues();
  if (!(l2[0] > 0.0)) return std::nullopt;
  SurfaceStrain s;
  s.lambda1 = std::sqrt(l2[1]);
  s.lambda2 = std::sqrt(l2[0]);
  // A principal direction is an axis; the eigen solver's sign of v is whatever round-off
  // gives, so on symmetric data neighbouring marks could point opposite ways. Convention:
  // the major direction on the deformed surface points to +x (to +y where it is across x,
  // then +z), and (major, minor, normal) is right-handed on each surface.
  Vec2 v1 = es.eigenvectors().col(1), v2 = es.eigenvectors().col(0);
  s.normal_undeformed = G.col(0).cross(G.col(1)).normalized();
  s.normal_deformed = g.col(0).cross(g.col(1)).normalized();
  const Vec3 d1 = (g * v1).normalized();
  constexpr double kAcross = 1e-9;  // a component this small is taken as 0
  const int lead = std::abs(d1.x()) > kAcross ? 0 : std::abs(d1.y()) > kAcross ? 1 : 2;
  if (d1(lead) < 0.0) v1 = -v1;
  if ((g * v1).cross(g * v2).dot(s.normal_deformed) < 0.0) v2 = -v2;
  s.dir1_deformed = (g * v1).normalized();
  s.dir2_deformed = (g * v2).normalized();
  s.dir1_undeformed = (G * v1).normalized();
  s.dir2_undeformed = (G * v2).normalized();
  return s;
}

std::optional<FibreState> fibre_state(const Mat32& G, const Mat32& g, const Vec3& a0) {
  const Mat2 M = G.transpose() * G;
  if (!(M.determinant() > 1e-14 * M.trace() * M.trace())) return std::nullopt;
  const Vec2 v = M.ldlt().solve(G.transpose() * a0);  // xi-components of a0
  const Vec3 a = g * v;
  const double len0 = (G * v).norm();
  if (!(len0 > 0.0) || !(a.norm() > 0.0)) return std::nullopt;
  return FibreState{a.normalized(), a.norm() / len0};
}

std::optional<Vec3> tangent_at_angle(const Mat32& G, const Vec3& reference_axis, double angle_deg) {
  const Vec3 n = G.col(0).cross(G.col(1));
  if (!(n.norm() > 0.0)) return std::nullopt;
  const Vec3 nn = n.normalized();
  Vec3 e1 = reference_axis - reference_axis.dot(nn) * nn;
  if (e1.norm() < 0.1 * reference_axis.norm()) e1 = G.col(0);
  e1.normalize();
  const Vec3 e2 = nn.cross(e1);
  const double a = angle_deg * kPi / 180.0;
  return (std::cos(a) * e1 + std::sin(a) * e2).normalized();
}

double trellis_shear_deg(double initial_deg, const Vec3& d0, const Vec3& d1) {
  return initial_deg - std::acos(std::clamp(d0.dot(d1), -1.0, 1.0)) * 180.0 / kPi;
}

FibrePair fibre_pair(const Mat32& G, const Mat32& g, double angle0_deg, double angle1_deg) {
  FibrePair out;
  const double angles[2] = {angle0_deg, angle1_deg};
  for (int k = 0; k < 2; ++k) {
    out.undeformed[k] = tangent_at_angle(G, Vec3::UnitX(), angles[k]);
    if (out.undeformed[k]) out.state[k] = fibre_state(G, g, *out.undeformed[k]);
  }
  if (out.state[0] && out.state[1])
    out.shear_angle_deg = trellis_shear_deg(std::abs(angle1_deg - angle0_deg), out.state[0]->direction_deformed,
                                            out.state[1]->direction_deformed);
  return out;
}

}  // namespace sf::gsa

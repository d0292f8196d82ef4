#include "gsa/plane.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sf::gsa {

// Best-fit plane of the rows of `pts` (PCA), axes oriented towards +X / +Z.
PlaneFrame best_fit_plane(const Points3& pts) {
  PlaneFrame f;
  f.centroid = pts.colwise().mean().transpose();
  const MatX c = pts.rowwise() - f.centroid.transpose();
  const Mat3 cov = (c.transpose() * c) / static_cast<double>(pts.rows());
  Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  f.a1 = es.eigenvectors().col(2);
  f.a2 = es.eigenvectors().col(1);
  f.spread1 = std::sqrt(std::max(0.0, es.eigenvalues()[2]));
  f.spread2 = std::sqrt(std::max(0.0, es.eigenvalues()[1]));
  f.spread_normal = std::sqrt(std::max(0.0, es.eigenvalues()[0]));
  // In-plane axes: for a clearly elongated part (a strip) the long axis; otherwise
  // (near-square or round parts, where PCA axes are arbitrary) the X axis projected
  // onto the plane, so the mesh lines up with the marks. a1 towards +X, normal towards +Z.
  f.normal = f.a1.cross(f.a2).normalized();
  if (f.spread1 < 1.5 * f.spread2) {
    Vec3 x = Vec3::UnitX() - Vec3::UnitX().dot(f.normal) * f.normal;
    if (x.norm() < 0.3) x = Vec3::UnitY() - Vec3::UnitY().dot(f.normal) * f.normal;
    f.a1 = x.normalized();
  }
  const Vec3 ref = std::abs(f.a1.x()) > 1e-3 ? Vec3::UnitX() : Vec3::UnitY();
  if (f.a1.dot(ref) < 0) f.a1 = -f.a1;
  f.a2 = f.normal.cross(f.a1).normalized();
  f.normal = f.a1.cross(f.a2);
  if (f.normal.z() < 0 || (std::abs(f.normal.z()) < 1e-12 && f.normal.y() < 0)) {
    f.a2 = -f.a2;
    f.normal = -f.normal;
  }
  return f;
}

RigidMotion best_rigid_motion(const Points3& from, const Points3& to, const VecX& weight) {
  double total = 0.0;
  Vec3 c_from = Vec3::Zero(), c_to = Vec3::Zero();
  for (Index i = 0; i < from.rows(); ++i) {
    if (!(weight[i] > 0.0)) continue;
    total += weight[i];
    c_from += weight[i] * from.row(i).transpose();
    c_to += weight[i] * to.row(i).transpose();
  }
  RigidMotion m;
  if (!(total > 0.0)) return m;
  c_from /= total;
  c_to /= total;
  Mat3 h = Mat3::Zero();  // sum w (to - c_to)(from - c_from)^T
  for (Index i = 0; i < from.rows(); ++i)
    if (weight[i] > 0.0)
      h += weight[i] * (to.row(i).transpose() - c_to) * (from.row(i).transpose() - c_from).transpose();
  const Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 s = svd.singularValues();
  if (s[1] > 1e-12 * s[0]) {
    Mat3 d = Mat3::Identity();
    d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
    m.rotation = svd.matrixU() * d * svd.matrixV().transpose();
  }
  m.translation = c_to - m.rotation * c_from;
  return m;
}

}  // namespace sf::gsa

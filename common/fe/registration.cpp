#include "common/fe/registration.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "common/fe/surface_field.hpp"

namespace sf::fe {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

// Diagonal of the bounding box of the finite rows.
double extent_of(const Eigen::Ref<const Points3>& p) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (Index i = 0; i < p.rows(); ++i) {
    const Vec3 x = p.row(i).transpose();
    if (!x.allFinite()) continue;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return lo.allFinite() ? (hi - lo).norm() : 0.0;
}

// Size of the change from a to b over a part of size `extent`.
double change_of(const RigidTransform& a, const RigidTransform& b, double extent) {
  return (a.rotation - b.rotation).norm() * extent + (a.translation - b.translation).norm();
}

// Huber weight with outlier cut-off.
double robust_weight(double r, double scale, const RobustOptions& o) {
  if (!std::isfinite(r)) return 0.0;
  if (r > o.outlier_k * scale) return 0.0;
  return r <= o.huber_k * scale ? 1.0 : o.huber_k * scale / r;
}

void validate(const RobustOptions& o) {
  if (!(o.huber_k > 0) || !(o.outlier_k > o.huber_k) || o.max_iterations < 1 || !(o.tolerance > 0) ||
      !(o.min_scale >= 0))
    throw std::invalid_argument(
        "RobustOptions: need huber_k > 0, outlier_k > huber_k, max_iterations >= 1, "
        "tolerance > 0, min_scale >= 0");
}
}  // namespace

Points3 RigidTransform::apply_all(const Eigen::Ref<const Points3>& points) const {
  Points3 out(points.rows(), 3);
  for (Index i = 0; i < points.rows(); ++i)
    out.row(i) = (rotation * points.row(i).transpose() + translation).transpose();
  return out;
}

RigidTransform RigidTransform::inverse() const {
  RigidTransform inv;
  inv.rotation = rotation.transpose();
  inv.translation = -(inv.rotation * translation);
  return inv;
}

RigidTransform operator*(const RigidTransform& a, const RigidTransform& b) {
  RigidTransform c;
  c.rotation = a.rotation * b.rotation;
  c.translation = a.rotation * b.translation + a.translation;
  return c;
}

double RigidTransform::angle_deg() const { return Eigen::AngleAxisd(rotation).angle() * 180.0 / kPi; }

Vec3 RigidTransform::axis() const {
  const Eigen::AngleAxisd aa(rotation);
  return aa.angle() > 0 ? Vec3(aa.axis()) : Vec3::UnitX();
}

const char* to_string(RegistrationReport::Status status) {
  switch (status) {
    case RegistrationReport::Status::kConverged:
      return "converged";
    case RegistrationReport::Status::kNotConverged:
      return "not_converged";
    case RegistrationReport::Status::kFailed:
      return "failed";
  }
  return "?";
}

std::string RegistrationReport::brief() const {
  std::ostringstream s;
  s << method << ": " << to_string(status) << ", rotation " << transform.angle_deg() << " deg, translation ("
    << transform.translation[0] << ", " << transform.translation[1] << ", " << transform.translation[2]
    << "), RMS distance " << rms << " over " << n_used << " of " << n_points << " points, " << iterations
    << " iterations";
  if (!message.empty()) s << " (" << message << ")";
  return s.str();
}

RigidTransform best_fit_rigid(const Eigen::Ref<const Points3>& from, const Eigen::Ref<const Points3>& to,
                              const std::vector<double>& weights) {
  if (from.rows() != to.rows() || (!weights.empty() && static_cast<Index>(weights.size()) != from.rows()))
    throw std::invalid_argument("best_fit_rigid: sizes of from, to and weights differ");
  double wsum = 0.0;
  Vec3 cf = Vec3::Zero(), ct = Vec3::Zero();
  for (Index i = 0; i < from.rows(); ++i) {
    const double w = weights.empty() ? 1.0 : weights[static_cast<std::size_t>(i)];
    if (!(w > 0)) continue;
    wsum += w;
    cf += w * from.row(i).transpose();
    ct += w * to.row(i).transpose();
  }
  RigidTransform t;
  if (!(wsum > 0)) return t;
  cf /= wsum;
  ct /= wsum;
  Mat3 h = Mat3::Zero();
  for (Index i = 0; i < from.rows(); ++i) {
    const double w = weights.empty() ? 1.0 : weights[static_cast<std::size_t>(i)];
    if (!(w > 0)) continue;
    h += w * (from.row(i).transpose() - cf) * (to.row(i).transpose() - ct).transpose();
  }
  const Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 d = Mat3::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) d(2, 2) = -1.0;
  t.rotation = svd.matrixV() * d * svd.matrixU().transpose();
  t.translation = ct - t.rotation * cf;
  return t;
}

RegistrationReport robust_rigid_fit(const Eigen::Ref<const Points3>& from, const Eigen::Ref<const Points3>& to,
                                    const RobustOptions& o) {
  validate(o);
  if (from.rows() != to.rows()) throw std::invalid_argument("robust_rigid_fit: from and to differ in length");
  RegistrationReport rep;
  rep.method = "ids";
  const Index n = from.rows();
  rep.n_points = n;
  std::vector<bool> finite(static_cast<std::size_t>(n));
  Index n_finite = 0;
  for (Index i = 0; i < n; ++i) {
    finite[static_cast<std::size_t>(i)] = from.row(i).allFinite() && to.row(i).allFinite();
    n_finite += finite[static_cast<std::size_t>(i)] ? 1 : 0;
  }
  rep.distances.assign(static_cast<std::size_t>(n), kNaN);
  rep.used.assign(static_cast<std::size_t>(n), false);
  if (n_finite < 3) {
    rep.message = "need at least 3 pairs of points, found " + std::to_string(n_finite);
    return rep;
  }
  const double extent = std::max(extent_of(from), extent_of(to));
  const double floor = o.min_scale > 0 ? o.min_scale : 1e-9 * std::max(extent, 1e-300);
  std::vector<double> w(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) w[static_cast<std::size_t>(i)] = finite[static_cast<std::size_t>(i)] ? 1.0 : 0.0;
  RigidTransform t = best_fit_rigid(from, to, w);
  rep.status = RegistrationReport::Status::kNotConverged;
  std::vector<double> r(static_cast<std::size_t>(n), kNaN), rf;
  for (int it = 1; it <= o.max_iterations; ++it) {
    rf.clear();
    for (Index i = 0; i < n; ++i) {
      if (!finite[static_cast<std::size_t>(i)]) continue;
      r[static_cast<std::size_t>(i)] = (t.apply(Vec3(from.row(i).transpose())) - to.row(i).transpose()).norm();
      rf.push_back(r[static_cast<std::size_t>(i)]);
    }
    rep.scale = std::max(1.4826 * median_of(rf), floor);
    Index n_used = 0;
    for (Index i = 0; i < n; ++i) {
      w[static_cast<std::size_t>(i)] = robust_weight(r[static_cast<std::size_t>(i)], rep.scale, o);
      n_used += w[static_cast<std::size_t>(i)] > 0 ? 1 : 0;
    }
    if (n_used < 3) {
      rep.status = RegistrationReport::Status::kFailed;
      rep.message = "fewer than 3 points left after removing outliers";
      return rep;
    }
    const RigidTransform next = best_fit_rigid(from, to, w);
    rep.iterations = it;
    const double change = change_of(next, t, extent);
    t = next;
    if (change <= o.tolerance * extent) {
      rep.status = RegistrationReport::Status::kConverged;
      break;
    }
  }
  if (rep.status == RegistrationReport::Status::kNotConverged)
    rep.message = "reweighting did not settle in " + std::to_string(o.max_iterations) + " passes";
  rep.transform = t;
  double s_used = 0, s_all = 0;
  for (Index i = 0; i < n; ++i) {
    if (!finite[static_cast<std::size_t>(i)]) continue;
    const double d = (t.apply(Vec3(from.row(i).transpose())) - to.row(i).transpose()).norm();
    rep.distances[static_cast<std::size_t>(i)] = d;
    s_all += d * d;
    if (w[static_cast<std::size_t>(i)] > 0) {
      rep.used[static_cast<std::size_t>(i)] = true;
      ++rep.n_used;
      s_used += d * d;
    }
  }
  rep.rms = std::sqrt(s_used / static_cast<double>(std::max<Index>(rep.n_used, 1)));
  rep.rms_all = std::sqrt(s_all / static_cast<double>(n_finite));
  return rep;
}

namespace {

struct IcpState {
  RigidTransform t;
  std::vector<mesh::Projection> feet;
  std::vector<double> weights;  // per point
  double score = std::numeric_limits<double>::infinity();
  double scale = 0;
  int iterations = 0;
  bool converged = false;
};

class Icp {
 public:
  Icp(const Eigen::Ref<const Points3>& points, const mesh::SurfaceMesh& mesh, const Eigen::Ref<const MatX>& parameters,
      const IcpOptions& o)
      : o_(o), projector_(mesh, parameters), field_(mesh, parameters) {
    for (Index i = 0; i < points.rows(); ++i)
      if (points.row(i).allFinite()) rows_.push_back(i);
    points_.resize(static_cast<Index>(rows_.size()), 3);
    for (std::size_t k = 0; k < rows_.size(); ++k) points_.row(static_cast<Index>(k)) = points.row(rows_[k]);
    extent_ = extent_of(points_);
    floor_ = o.robust.min_scale > 0 ? o.robust.min_scale : 1e-9 * std::max(extent_, 1e-300);
  }
  const Points3& points() const { return points_; }
  const std::vector<Index>& rows() const { return rows_; }
  double extent() const { return extent_; }

  // Foot points of the moved points (a fresh search, or refined from the last feet).
  // `probing`: only the trim fraction of the nearest feet count.
  void locate(IcpState& s, bool fresh, bool probing) const {
    const double trim = probing ? o_.trim : 1.0;
    const Points3 moved = s.t.apply_all(points_);
    if (fresh || s.feet.size() != rows_.size()) {
      s.feet = projector_.project_all(moved);
    } else {
      std::vector<Index> el(rows_.size());
      std::vector<Vec2> xi(rows_.size());
      for (std::size_t k = 0; k < rows_.size(); ++k) {
        el[k] = std::max<Index>(s.feet[k].element, 0);
        xi[k] = s.feet[k].xi;
      }
      s.feet = projector_.refine_all(moved, el, xi);
    }
    // Trimmed, Huber-weighted: the scale from the median distance of the usable feet.
    std::vector<double> d;
    for (const auto& f : s.feet)
      if (usable(f)) d.push_back(f.distance);
    s.weights.assign(rows_.size(), 0.0);
    if (d.size() < 6) {
      s.score = std::numeric_limits<double>::infinity();
      return;
    }
    std::vector<double> sorted = d;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t keep =
        std::max<std::size_t>(6, static_cast<std::size_t>(std::ceil(trim * static_cast<double>(sorted.size()))));
    const double cut = sorted[std::min(keep, sorted.size()) - 1];
    s.scale = std::max(1.4826 * sorted[sorted.size() / 2], floor_);
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t k = 0; k < rows_.size(); ++k) {
      const auto& f = s.feet[k];
      if (!usable(f) || f.distance > cut) continue;
      s.weights[k] = robust_weight(f.distance, s.scale, o_.robust);
      if (s.weights[k] > 0) sum += f.distance * f.distance, ++n;
    }
    s.score = n >= 6 ? std::sqrt(sum / static_cast<double>(n)) : std::numeric_limits<double>::infinity();
  }

  // One step: point-to-point (Kabsch on the feet) or point-to-plane (Gauss-Newton).
  // Returns the size of the step relative to the extent.
  double step(IcpState& s, bool point_to_plane) const {
    RigidTransform inc;
    const Points3 moved = s.t.apply_all(points_);
    if (!point_to_plane) {
      Points3 feet(moved.rows(), 3);
      for (std::size_t k = 0; k < rows_.size(); ++k) feet.row(static_cast<Index>(k)) = s.feet[k].point.transpose();
      inc = best_fit_rigid(moved, feet, s.weights);
    } else {
      Vec3 c = Vec3::Zero();
      double wsum = 0;
      for (std::size_t k = 0; k < rows_.size(); ++k)
        if (s.weights[k] > 0) c += s.weights[k] * moved.row(static_cast<Index>(k)).transpose(), wsum += s.weights[k];
      if (!(wsum > 0)) return 0.0;
      c /= wsum;
      Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
      const double len = std::max(extent_, 1e-300);
      for (std::size_t k = 0; k < rows_.size(); ++k) {
        if (!(s.weights[k] > 0)) continue;
        const auto& f = s.feet[k];
        const fe::SurfacePoint sp = field_.evaluate3(f.element, f.xi, basis::kFirst);
        Vec3 nrm = sp.dx.col(0).cross(sp.dx.col(1));
        const double nn = nrm.norm();
        const Vec3 p = moved.row(static_cast<Index>(k)).transpose();
        if (nn > 0) {
          nrm /= nn;
        } else {
          const Vec3 r = p - f.point;
          if (!(r.norm() > 0)) continue;
          nrm = r.normalized();
        }
        Eigen::Matrix<double, 6, 1> j;
        j.head<3>() = (p - c).cross(nrm) / len;  // rotation scaled by the extent
        j.tail<3>() = nrm;
        const double e = (p - f.point).dot(nrm);
        a.noalias() += s.weights[k] * j * j.transpose();
        b.noalias() -= s.weights[k] * j * e;
      }
      // Sliding along a surface that is invariant to it (a plane, a cylinder) is not
      // determined: damp it with a tiny multiple of the matrix's size.
      a.diagonal().array() += 1e-12 * a.trace() / 6.0 + 1e-300;
      Eigen::Matrix<double, 6, 1> d = a.ldlt().solve(b);
      Vec3 w = d.head<3>() / len, v = d.tail<3>();
      const double wn = w.norm();
      if (wn > 0.2) w *= 0.2 / wn, v *= 0.2 / wn;
      if (v.norm() > 0.2 * len) v *= 0.2 * len / v.norm();
      if (w.norm() > 0) inc.rotation = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      inc.translation = c + v - inc.rotation * c;
    }
    const RigidTransform before = s.t;
    s.t = inc * s.t;
    return change_of(s.t, before, extent_) / std::max(extent_, 1e-300);
  }

  // Runs `iterations` more steps from s: point-to-point for the first few of a start.
  void run(IcpState& s, int iterations) const {
    for (int it = 0; it < iterations && !s.converged; ++it, ++s.iterations) {
      const bool plane = s.iterations >= 5;
      locate(s, !plane || s.iterations % 10 == 0, s.iterations < o_.probe_iterations);
      if (!std::isfinite(s.score)) return;
      const double change = step(s, plane);
      // Converged: a step at round-off, or (noisy data, where the reweighting keeps the
      // steps from vanishing) a step a thousand times below the robust scale of the
      // distances (for exact data the scale is at its floor, so this is round-off too).
      const bool below_noise = change * extent_ <= 1e-3 * s.scale;
      if (plane && (change <= o_.tolerance || below_noise)) s.converged = true;
    }
  }

  static bool usable(const mesh::Projection& f) {
    return f.status == mesh::Projection::Status::kConverged && std::isfinite(f.distance);
  }

  const IcpOptions& options() const { return o_; }
  const fe::SurfaceField& field() const { return field_; }

 private:
  IcpOptions o_;
  mesh::SurfaceProjector projector_;
  fe::SurfaceField field_;
  std::vector<Index> rows_;
  Points3 points_;
  double extent_ = 0, floor_ = 0;
};

// Mean and principal axes (columns, by decreasing variance, right-handed) of the rows.
std::pair<Vec3, Mat3> principal_axes(const Eigen::Ref<const Points3>& p) {
  Vec3 c = Vec3::Zero();
  for (Index i = 0; i < p.rows(); ++i) c += p.row(i).transpose();
  c /= static_cast<double>(std::max<Index>(p.rows(), 1));
  Mat3 cov = Mat3::Zero();
  for (Index i = 0; i < p.rows(); ++i) cov += (p.row(i).transpose() - c) * (p.row(i) - c.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  Mat3 a;
  for (int k = 0; k < 3; ++k) a.col(k) = es.eigenvectors().col(2 - k);
  if (a.determinant() < 0) a.col(2) = -a.col(2);
  return {c, a};
}

}  // namespace

RegistrationReport register_to_surface(const Eigen::Ref<const Points3>& points, const mesh::SurfaceMesh& mesh,
                                       const Eigen::Ref<const MatX>& parameters, const IcpOptions& o) {
  validate(o.robust);
  if (o.max_iterations < 1 || !(o.tolerance > 0) || !(o.trim >= 0.5 && o.trim <= 1.0) || o.probe_iterations < 1)
    throw std::invalid_argument(
        "IcpOptions: need max_iterations >= 1, tolerance > 0, 0.5 <= trim <= 1, "
        "probe_iterations >= 1");
  RegistrationReport rep;
  rep.method = "surface (ICP)";
  rep.n_points = points.rows();
  rep.distances.assign(static_cast<std::size_t>(points.rows()), kNaN);
  rep.used.assign(static_cast<std::size_t>(points.rows()), false);
  rep.feet.assign(static_cast<std::size_t>(points.rows()), mesh::Projection{});
  const Icp icp(points, mesh, parameters, o);
  if (icp.rows().size() < 6) {
    rep.message = "need at least 6 points, found " + std::to_string(icp.rows().size());
    return rep;
  }
  // Starts: the identity, then the principal-axes alignments (4 proper sign choices).
  std::vector<std::pair<std::string, RigidTransform>> starts = {{"identity", RigidTransform{}}};
  if (o.principal_axes) {
    Points3 samples(mesh.n_elements() * 5, 3);
    const Vec2 at[5] = {Vec2(0.5, 0.5), Vec2(0.1, 0.1), Vec2(0.9, 0.1), Vec2(0.1, 0.9), Vec2(0.9, 0.9)};
    for (Index e = 0; e < mesh.n_elements(); ++e)
      for (int k = 0; k < 5; ++k) samples.row(5 * e + k) = icp.field().evaluate3(e, at[k], basis::kValues).x;
    const auto [cp, ap] = principal_axes(icp.points());
    const auto [cs, as] = principal_axes(samples);
    const double signs[4][3] = {{1, 1, 1}, {-1, -1, 1}, {-1, 1, -1}, {1, -1, -1}};
    for (const auto& sg : signs) {
      RigidTransform t;
      t.rotation = as * Vec3(sg[0], sg[1], sg[2]).asDiagonal() * ap.transpose();
      t.translation = cs - t.rotation * cp;
      std::ostringstream name;
      name << "principal axes (" << (sg[0] > 0 ? "+" : "-") << (sg[1] > 0 ? "+" : "-") << (sg[2] > 0 ? "+" : "-")
           << ")";
      starts.emplace_back(name.str(), t);
    }
  }
  IcpState best;
  std::string best_name;
  for (const auto& [name, t0] : starts) {
    IcpState s;
    s.t = t0;
    icp.run(s, o.probe_iterations);
    if (std::isfinite(s.score)) icp.locate(s, true, true);
    if (s.score < best.score) {
      best = s;
      best_name = name;
    }
    // A start that already fits to round-off cannot be bettered.
    if (best.score <= 1e-9 * icp.extent()) break;
  }
  if (!std::isfinite(best.score)) {
    rep.message = "fewer than 6 points found a foot point inside the surface from any start";
    return rep;
  }
  icp.run(best, o.max_iterations - best.iterations);
  icp.locate(best, true, false);
  rep.status = best.converged ? RegistrationReport::Status::kConverged : RegistrationReport::Status::kNotConverged;
  if (!best.converged) rep.message = "step still above tolerance after " + std::to_string(best.iterations) + " steps";
  rep.transform = best.t;
  rep.iterations = best.iterations;
  rep.start = best_name;
  rep.scale = best.scale;
  double s_used = 0, s_all = 0;
  Index n_all = 0;
  for (std::size_t k = 0; k < icp.rows().size(); ++k) {
    const std::size_t row = static_cast<std::size_t>(icp.rows()[k]);
    const auto& f = best.feet[k];
    rep.feet[row] = f;
    if (!f.ok()) continue;
    rep.distances[row] = f.distance;
    if (Icp::usable(f)) s_all += f.distance * f.distance, ++n_all;
    if (best.weights[k] > 0) {
      rep.used[row] = true;
      ++rep.n_used;
      s_used += f.distance * f.distance;
    }
  }
  rep.rms = std::sqrt(s_used / static_cast<double>(std::max<Index>(rep.n_used, 1)));
  rep.rms_all = std::sqrt(s_all / static_cast<double>(std::max<Index>(n_all, 1)));
  return rep;
}

}  // namespace sf::fe

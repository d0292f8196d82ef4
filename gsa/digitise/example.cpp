#include "gsa/digitise/example.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <map>

namespace sf::gsa::digitise::synth {

namespace {

double deg(double d) { return d * kPi / 180.0; }

// A camera at `position` looking at `target`, image rows running roughly along -Y (so the
// sheet appears with X to the right and Y up).
Camera look_at(const Vec3& position, const Vec3& target, double roll_deg) {
  Camera c;
  const Vec3 z = (target - position).normalized();
  Vec3 down(0, -1, 0);
  Vec3 y = (down - down.dot(z) * z).normalized();
  Vec3 x = y.cross(z);
  const Eigen::AngleAxisd roll(deg(roll_deg), z);
  x = roll * x;
  y = roll * y;
  c.R.row(0) = x.transpose();
  c.R.row(1) = y.transpose();
  c.R.row(2) = z.transpose();
  c.t = -c.R * position;
  return c;
}

}  // namespace

std::vector<Camera> example_cameras(const ExampleOptions& o) {
  std::vector<Camera> cams;
  const double s = o.width / 1632.0;  // focal length scales with the sensor's pixel count
  const Vec3 target(0, 0, 15);
  const double D = 430.0, tilt = deg(14.0);
  for (int k = 0; k < o.n_cameras; ++k) {
    // Baseline at 20 degrees to the grid lines (3 cameras: 120 degrees apart).
    const double az = deg(20.0 + k * 360.0 / o.n_cameras);
    const Vec3 pos = target + D * Vec3(std::sin(tilt) * std::cos(az), std::sin(tilt) * std::sin(az), std::cos(tilt));
    Camera c = look_at(pos, target, k == 0 ? 1.5 : -2.0 + k);
    c.name = "cam" + std::to_string(k);
    c.width = o.width;
    c.height = o.height;
    c.fx = (2400.0 + 25.0 * k) * s;
    c.fy = c.fx * (1.0 + 0.0008 * (k + 1));
    c.cx = 0.5 * (o.width - 1) + (7.3 - 11.0 * k) * s;
    c.cy = 0.5 * (o.height - 1) + (-4.1 + 6.0 * k) * s;
    c.distortion = {-0.09 + 0.02 * k, 0.12 - 0.03 * k, 3e-4 - 2e-4 * k, -2e-4 + 1e-4 * k, 0.0};
    cams.push_back(c);
  }
  return cams;
}

Scene example_part(const ExampleOptions& o, SheetShape shape) {
  Scene sc;
  sc.sheet.shape = shape;
  // One pitch of bare sheet beyond the outermost marks.
  sc.sheet.half_width = sc.sheet.half_height = (o.half_marks + 1.0) * o.pitch;
  sc.pattern.kind = o.marks;
  sc.pattern.pitch = o.pitch;
  sc.pattern.i_min = sc.pattern.j_min = -o.half_marks;
  sc.pattern.i_max = sc.pattern.j_max = o.half_marks;
  sc.pattern.reference = o.reference;
  sc.pattern.dot_diameter = 0.4 * o.pitch;
  sc.pattern.reference_diameter = o.marks == PatternKind::kDots ? 0.4 * o.pitch * std::sqrt(2.0) : 0.4 * o.pitch;
  sc.pattern.line_width = 0.1 * o.pitch;
  if (o.uneven_lighting) {
    sc.lighting.gradient = 0.3;
    sc.lighting.vignetting = 0.25;
  }
  if (o.occlusion) {
    // The corner X + Y > 24.04 pitches is cut away: the marks with i + j = 24 are cut just
    // past their centres (marks off the part's edge).
    sc.sheet.trim = (2 * o.half_marks - 6 + 0.04) * o.pitch;
    // A flap 6 mm above the part near (-40, -55): it hides some marks and cuts others in
    // each view (a fold of the sheet, a clamp).
    const Vec2 m0(-45.0 * o.pitch / 5.0, -58.0 * o.pitch / 5.0);
    const Vec3 p0 = sc.sheet.position(m0) + Vec3(0, 0, 6.0);
    sc.occluders.push_back({p0, Vec3(22.0, 3.0, 2.0) * (o.pitch / 5.0), Vec3(-2.0, 9.0, 0.5) * (o.pitch / 5.0), 0.55});
  }
  return sc;
}

BoardSpec example_board(const ExampleOptions& o) {
  (void)o;
  return {11, 8, 12.0};
}

std::vector<Scene> example_calibration_boards(const ExampleOptions& o) {
  const BoardSpec b = example_board(o);
  const std::vector<Camera> cams = example_cameras(o);
  // Candidate poses: tilt about x, tilt about y, turn about z (degrees), shift (mm).
  struct Pose {
    double ax, ay, az, sx, sy, sz;
  };
  const std::vector<Pose> poses = {
      {0, 0, 0, 0, 0, -20},          {30, 0, 5, 0, 5, -10},       {-30, 0, -5, 0, -5, -10},
      {0, 30, 10, 5, 0, -20},        {0, -30, -10, -5, 0, -20},   {22, 22, 30, 8, 5, -30},
      {-22, 22, -25, 5, -8, -25},    {22, -22, 60, -8, 5, -35},   {-22, -22, -60, -5, -5, -30},
      {35, 10, 90, 0, 0, -40},       {10, -35, 15, 10, 5, -40},   {-15, 30, 45, -10, -3, -30},
      {28, -12, -35, 3, 10, -20},    {-28, 12, 80, -3, -10, -30}, {15, 15, 0, 12, 8, 0},
      {-15, -15, 170, -12, -8, -40},
  };

  std::vector<Scene> out;
  for (const Pose& p : poses) {
    if (static_cast<int>(out.size()) >= o.calibration_views) break;
    Scene sc;
    sc.pattern.kind = PatternKind::kChessboard;
    sc.pattern.pitch = b.square;
    sc.pattern.cols = b.cols;
    sc.pattern.rows = b.rows;
    sc.pattern.ink = 0.06;
    sc.pattern.paper = 0.85;
    // Squares span [-p, cols p] x [-p, rows p]; a white margin of one square around them.
    sc.sheet.centre = Vec2(0.5 * (b.cols - 1) * b.square, 0.5 * (b.rows - 1) * b.square);
    sc.sheet.half_width = 0.5 * (b.cols + 1) * b.square + 1.0 * b.square;
    sc.sheet.half_height = 0.5 * (b.rows + 1) * b.square + 1.0 * b.square;
    const Mat3 R = (Eigen::AngleAxisd(deg(p.az), Vec3::UnitZ()) * Eigen::AngleAxisd(deg(p.ay), Vec3::UnitY()) *
                    Eigen::AngleAxisd(deg(p.ax), Vec3::UnitX()))
                       .toRotationMatrix();
    sc.sheet.R = R;
    const Vec3 c(sc.sheet.centre.x(), sc.sheet.centre.y(), 0.0);
    sc.sheet.t = Vec3(p.sx, p.sy, 15.0 + p.sz) - R * c;
    if (o.uneven_lighting) sc.lighting.gradient = 0.2;
    // Keep the pose only when the whole board (with its margin) is inside every image
    // and faces every camera.
    bool ok = true;
    for (const Camera& cam : cams) {
      for (double sx : {-1.0, 1.0})
        for (double sy : {-1.0, 1.0}) {
          const Vec3 X = sc.sheet.position(sc.sheet.centre + Vec2(sx * sc.sheet.half_width, sy * sc.sheet.half_height));
          if (!cam.in_front(X)) {
            ok = false;
            continue;
          }
          const Vec2 uv = cam.project(X);
          ok = ok && uv.x() > 15 && uv.y() > 15 && uv.x() < cam.width - 16 && uv.y() < cam.height - 16;
        }
      ok = ok && sc.sheet.normal(sc.sheet.centre).dot(cam.centre() - sc.sheet.position(sc.sheet.centre)) > 0;
    }
    if (ok) out.push_back(sc);
  }
  return out;
}

std::vector<NamedImage> render_views(const std::vector<Camera>& cameras, const Scene& scene, const Effects& effects,
                                     unsigned seed) {
  std::vector<NamedImage> out;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    Effects e = effects;
    e.seed = seed + 31 * static_cast<unsigned>(c);
    out.push_back({cameras[c].name, render(cameras[c], scene, e)});
  }
  return out;
}

std::vector<TrueMark> true_marks(const Scene& scene) {
  std::vector<TrueMark> out;
  for (const Pattern::Mark& mk : scene.pattern.marks()) {
    if (!scene.sheet.contains(mk.m)) continue;
    const auto [l1, l2] = scene.sheet.stretches(mk.m);
    out.push_back({mk.i, mk.j, scene.sheet.position(mk.m), l1, l2});
  }
  return out;
}

std::pair<int, int> material_index(const Label& label, PatternKind marks, const Label& shift) {
  const Label l = label + shift;
  return {l.x(), (marks == PatternKind::kLines ? 1 : 0) - l.y()};
}

Comparison compare_marks(const std::vector<DigitisedMark>& marks, const Scene& scene, PatternKind kind,
                         const Eigen::Isometry3d& to_frame, const Label& shift) {
  std::map<std::pair<int, int>, Vec3> truth;
  for (const TrueMark& t : true_marks(scene)) truth[{t.i, t.j}] = to_frame * t.position;
  Comparison c;
  std::vector<Vec3> A, B;
  double ss = 0;
  for (const DigitisedMark& m : marks) {
    const auto it = truth.find(material_index(m.ij, kind, shift));
    if (it == truth.end() || (m.X - it->second).norm() > 0.25 * scene.pattern.pitch) {
      ++c.mislabelled;
      continue;
    }
    const double e = (m.X - it->second).norm();
    ss += e * e;
    c.max = std::max(c.max, e);
    A.push_back(m.X);
    B.push_back(it->second);
  }
  c.n = static_cast<Index>(A.size());
  if (c.n < 3) return c;
  c.rms = std::sqrt(ss / c.n);
  // Best rigid motion A -> B (Kabsch).
  Vec3 ca = Vec3::Zero(), cb = Vec3::Zero();
  for (Index k = 0; k < c.n; ++k) {
    ca += A[k];
    cb += B[k];
  }
  ca /= static_cast<double>(c.n);
  cb /= static_cast<double>(c.n);
  Mat3 H = Mat3::Zero();
  for (Index k = 0; k < c.n; ++k) H += (A[k] - ca) * (B[k] - cb).transpose();
  const Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() > 0 ? 1.0 : -1.0;
  const Mat3 R = svd.matrixV() * D * svd.matrixU().transpose();
  double sr = 0;
  for (Index k = 0; k < c.n; ++k) {
    const double e = (R * (A[k] - ca) + cb - B[k]).norm();
    sr += e * e;
    c.max_rigid = std::max(c.max_rigid, e);
  }
  c.rms_rigid = std::sqrt(sr / c.n);
  return c;
}

}  // namespace sf::gsa::digitise::synth

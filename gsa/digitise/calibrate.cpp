#include "gsa/digitise/calibrate.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>
#include <cmath>
#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "common/core/error.hpp"

namespace sf::gsa::digitise {

std::vector<Vec3> CalibrationTarget::points() const {
  std::vector<Vec3> out;
  for (int l = 0; l < rows; ++l)
    for (int k = 0; k < cols; ++k) {
      const double x = kind == TargetKind::kAsymmetricCircles ? (2 * k + l % 2) * spacing : k * spacing;
      out.emplace_back(x, l * spacing, 0.0);
    }
  return out;
}

std::string CalibrationTarget::describe(const std::string& units) const {
  switch (kind) {
    case TargetKind::kChessboard:
      return fmt::format("chessboard {}x{} inner corners, {} {} squares", cols, rows, spacing, units);
    case TargetKind::kCircles:
      return fmt::format("symmetric circle grid {}x{}, spacing {} {}", cols, rows, spacing, units);
    case TargetKind::kAsymmetricCircles:
      return fmt::format("asymmetric circle grid {}x{}, spacing {} {}", cols, rows, spacing, units);
  }
  return "";
}

void CalibrateOptions::validate() const {
  if (target.cols < 2 || target.rows < 2)
    throw UsageError("--pattern: expected COLSxROWS with at least 2 x 2 points (inner corners of a chessboard)");
  if (target.kind == TargetKind::kChessboard && target.cols == target.rows)
    throw UsageError("--pattern: a square chessboard (" + std::to_string(target.cols) + "x" +
                     std::to_string(target.rows) +
                     ") has no defined orientation; use one with different numbers of inner corners per side");
  if (!(target.spacing > 0)) throw UsageError("--spacing: expected the square size / circle spacing, > 0");
  if (min_views < 3) throw UsageError("--min-views: at least 3 views are needed");
}

namespace {

using Points2 = std::vector<cv::Point2f>;

cv::Mat to_u8(const GreyImage& g) {
  cv::Mat f(g.height, g.width, CV_32F, const_cast<float*>(g.pixels.data()));
  cv::Mat u8;
  f.convertTo(u8, CV_8U, 255.0);
  return u8;
}

bool find_target(const cv::Mat& img, const CalibrationTarget& t, Points2& pts, std::string& note) {
  const cv::Size size(t.cols, t.rows);
  bool ok = false;
  try {
    if (t.kind == TargetKind::kChessboard) {
      // FAST_CHECK: an image without a board is given up on quickly instead of searched for
      // seconds.
      ok = cv::findChessboardCorners(
          img, size, pts, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
      if (ok) {
        // Refinement window: a quarter of the smallest corner spacing.
        double spacing = 1e9;
        for (int l = 0; l < t.rows; ++l)
          for (int k = 0; k + 1 < t.cols; ++k) {
            const cv::Point2f d = pts[l * t.cols + k + 1] - pts[l * t.cols + k];
            spacing = std::min(spacing, static_cast<double>(std::hypot(d.x, d.y)));
          }
        const int w = std::clamp(static_cast<int>(spacing / 4), 3, 15);
        cv::cornerSubPix(img, pts, cv::Size(w, w), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-5));
      }
    } else {
      cv::SimpleBlobDetector::Params p;
      p.minArea = 10;
      p.maxArea = static_cast<float>(0.05 * img.cols * img.rows);
      p.minDistBetweenBlobs = 3;
      const auto detector = cv::SimpleBlobDetector::create(p);
      const int flags = t.kind == TargetKind::kCircles ? cv::CALIB_CB_SYMMETRIC_GRID : cv::CALIB_CB_ASYMMETRIC_GRID;
      ok = cv::findCirclesGrid(img, size, pts, flags, detector);
    }
  } catch (const cv::Exception& e) {
    note = "OpenCV: " + e.msg;
    return false;
  }
  if (!ok) note = "target not found (all " + std::to_string(t.cols * t.rows) + " points must be in view)";
  return ok;
}

double view_rms(const std::vector<cv::Point3f>& obj, const Points2& img, const cv::Mat& rvec, const cv::Mat& tvec,
                const cv::Mat& K, const cv::Mat& D) {
  Points2 proj;
  cv::projectPoints(obj, rvec, tvec, K, D, proj);
  double ss = 0;
  for (std::size_t k = 0; k < img.size(); ++k) {
    const cv::Point2f d = proj[k] - img[k];
    ss += d.x * d.x + d.y * d.y;
  }
  return std::sqrt(ss / img.size());
}

Mat3 to_eigen(const cv::Mat& R) {
  Mat3 out;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) out(a, b) = R.at<double>(a, b);
  return out;
}

double angle_deg(const Mat3& a, const Mat3& b) {
  const double c = std::clamp(((a * b.transpose()).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / kPi;
}

struct CameraData {
  CameraReport report;
  cv::Mat K, D;
  std::vector<int> views;             // image index of each used view
  std::vector<Points2> points;        // per used view
  std::vector<cv::Mat> rvecs, tvecs;  // per used view
  Camera camera;
};

}  // namespace

CalibrationResult calibrate_rig(const std::vector<std::vector<NamedImage>>& images, const CalibrateOptions& o) {
  std::vector<std::vector<std::string>> names(images.size());
  for (std::size_t c = 0; c < images.size(); ++c)
    for (const NamedImage& ni : images[c]) names[c].push_back(ni.name);
  return calibrate_rig(
      names, [&](std::size_t c, std::size_t k) { return images[c][k].image; }, o);
}

CalibrationResult calibrate_rig(const std::vector<std::vector<std::string>>& images, const ImageLoader& load,
                                const CalibrateOptions& o, int threads) {
  o.validate();
  if (images.empty()) throw UsageError("calibrate: give the images of at least one camera");
  const std::vector<Vec3> target = o.target.points();
  std::vector<cv::Point3f> obj;
  for (const Vec3& p : target)
    obj.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));

  std::vector<CameraData> cams(images.size());
  for (std::size_t c = 0; c < images.size(); ++c) {
    CameraData& cd = cams[c];
    cd.report.name = "cam" + std::to_string(c);
    if (images[c].empty()) throw InputError(cd.report.name + ": no images");
    // Detection, in parallel; sizes checked against the first image.
    const std::size_t n = images[c].size();
    std::vector<ImageReport> reports(n);
    std::vector<Points2> found(n);
    std::vector<std::pair<int, int>> sizes(n, {0, 0});
    std::vector<std::exception_ptr> errors(n);
    std::size_t next = 0;
    std::mutex mu;
    auto work = [&] {
      for (;;) {
        std::size_t k;
        {
          std::lock_guard<std::mutex> lock(mu);
          if (next >= n) return;
          k = next++;
        }
        try {
          const GreyImage img = load(c, k);
          sizes[k] = {img.width, img.height};
          reports[k].name = images[c][k];
          reports[k].found = find_target(to_u8(img), o.target, found[k], reports[k].note);
        } catch (...) {
          errors[k] = std::current_exception();
        }
      }
    };
    {
      const int nt = std::max(1, threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency()));
      std::vector<std::thread> pool;
      for (int t = 0; t < std::min<int>(nt, static_cast<int>(n)); ++t) pool.emplace_back(work);
      for (auto& t : pool) t.join();
    }
    for (auto& e : errors)
      if (e) std::rethrow_exception(e);
    for (std::size_t k = 1; k < n; ++k)
      if (sizes[k] != sizes[0])
        throw InputError(fmt::format(
            "{}: {} x {} pixels, but {} (the first image of camera {}) is {} x {}: one camera's "
            "images must all have the same size",
            images[c][k], sizes[k].first, sizes[k].second, images[c][0], c, sizes[0].first, sizes[0].second));
    cd.report.width = sizes[0].first;
    cd.report.height = sizes[0].second;
    for (std::size_t k = 0; k < n; ++k) {
      if (reports[k].found) {
        cd.views.push_back(static_cast<int>(k));
        cd.points.push_back(found[k]);
      }
      cd.report.images.push_back(reports[k]);
    }
    if (static_cast<int>(cd.views.size()) < o.min_views) {
      std::string missing;
      for (const ImageReport& ir : cd.report.images)
        if (!ir.found) missing += (missing.empty() ? "" : ", ") + ir.name;
      throw InputError(fmt::format("camera {}: the target ({}) was found in {} of {} images; need {}{}", c,
                                   o.target.describe(), cd.views.size(), n, o.min_views,
                                   missing.empty() ? "" : "; not found in: " + missing));
    }
    // Calibration, then once more without views that fit much worse than the others.
    int flags = 0;
    if (o.fix_k3) flags |= cv::CALIB_FIX_K3;
    if (o.zero_tangential) flags |= cv::CALIB_ZERO_TANGENT_DIST;
    if (o.fix_aspect) flags |= cv::CALIB_FIX_ASPECT_RATIO;
    const cv::Size size(cd.report.width, cd.report.height);
    const cv::TermCriteria crit(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 200, 1e-12);
    for (int round = 0; round < 2; ++round) {
      std::vector<std::vector<cv::Point3f>> objs(cd.points.size(), obj);
      cd.K = cv::Mat::eye(3, 3, CV_64F);
      cd.D = cv::Mat::zeros(5, 1, CV_64F);
      try {
        cd.report.rms_px = cv::calibrateCamera(objs, cd.points, size, cd.K, cd.D, cd.rvecs, cd.tvecs, flags, crit);
      } catch (const cv::Exception& e) {
        throw InputError(
            fmt::format("camera {}: the calibration failed ({}); are the target views varied enough "
                        "(tilted boards, different positions)?",
                        c, e.msg));
      }
      std::vector<double> rms;
      for (std::size_t v = 0; v < cd.points.size(); ++v)
        rms.push_back(view_rms(obj, cd.points[v], cd.rvecs[v], cd.tvecs[v], cd.K, cd.D));
      std::vector<double> sorted = rms;
      std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
      const double limit = std::max(0.5, 4.0 * sorted[sorted.size() / 2]);
      std::vector<int> keep_views;
      std::vector<Points2> keep_points;
      for (std::size_t v = 0; v < rms.size(); ++v) {
        ImageReport& ir = cd.report.images[cd.views[v]];
        ir.rms_px = rms[v];
        if (round == 0 && rms[v] > limit) {
          ir.note = fmt::format("left out: reprojection error {:.3f} px > {:.3f} px (4 x the median)", rms[v], limit);
          continue;
        }
        keep_views.push_back(cd.views[v]);
        keep_points.push_back(cd.points[v]);
      }
      if (keep_views.size() == cd.views.size() || static_cast<int>(keep_views.size()) < o.min_views) break;
      cd.views = keep_views;
      cd.points = keep_points;
    }
    cd.report.n_used = static_cast<int>(cd.views.size());
    Camera& cam = cd.camera;
    cam.name = cd.report.name;
    cam.width = cd.report.width;
    cam.height = cd.report.height;
    cam.fx = cd.K.at<double>(0, 0);
    cam.fy = cd.K.at<double>(1, 1);
    cam.cx = cd.K.at<double>(0, 2);
    cam.cy = cd.K.at<double>(1, 2);
    cam.distortion = {cd.D.at<double>(0), cd.D.at<double>(1), cd.D.at<double>(2), cd.D.at<double>(3),
                      cd.D.at<double>(4)};
  }

  CalibrationResult res;
  for (const CameraData& cd : cams) {
    res.rig.cameras.push_back(cd.camera);
    res.cameras.push_back(cd.report);
  }
  // Stereo: each camera relative to camera 0.
  const CameraData& c0 = cams[0];
  for (std::size_t c = 1; c < cams.size(); ++c) {
    const CameraData& cc = cams[c];
    StereoReport sr;
    sr.camera = static_cast<Index>(c);
    if (images[c].size() != images[0].size())
      throw InputError(
          fmt::format("camera {} has {} images and camera 0 has {}: the cameras' images are paired by "
                      "their sorted order, so each camera needs one image per pose",
                      c, images[c].size(), images[0].size()));
    // Pairs: views found in both, with their board poses.
    struct Pair {
      int image;
      std::size_t v0, vc;
      Mat3 rel;
      Points2 pts_c;
    };
    std::vector<Pair> pairs;
    for (std::size_t a = 0; a < c0.views.size(); ++a)
      for (std::size_t b = 0; b < cc.views.size(); ++b)
        if (c0.views[a] == cc.views[b]) {
          cv::Mat R0, Rc;
          cv::Rodrigues(c0.rvecs[a], R0);
          cv::Rodrigues(cc.rvecs[b], Rc);
          pairs.push_back({c0.views[a], a, b, to_eigen(Rc) * to_eigen(R0).transpose(), cc.points[b]});
        }
    if (pairs.empty())
      throw InputError(fmt::format("camera {}: no image in which both camera 0 and camera {} found the target", c, c));
    // Consensus of the relative rotations; disagreeing pairs tried with the corner order reversed.
    std::size_t best = 0, best_n = 0;
    for (std::size_t a = 0; a < pairs.size(); ++a) {
      std::size_t n = 0;
      for (const Pair& q : pairs) n += angle_deg(pairs[a].rel, q.rel) < 2.0 ? 1 : 0;
      if (n > best_n) {
        best_n = n;
        best = a;
      }
    }
    const Mat3 consensus = pairs[best].rel;
    std::vector<std::vector<cv::Point3f>> objs;
    std::vector<Points2> p0, pc;
    for (Pair& q : pairs) {
      if (angle_deg(q.rel, consensus) >= 2.0) {
        Points2 rev(q.pts_c.rbegin(), q.pts_c.rend());
        cv::Mat rvec, tvec, Rr;
        bool agrees = false;
        if (cv::solvePnP(obj, rev, cc.K, cc.D, rvec, tvec)) {
          cv::Rodrigues(rvec, Rr);
          cv::Mat R0;
          cv::Rodrigues(c0.rvecs[q.v0], R0);
          agrees = angle_deg(to_eigen(Rr) * to_eigen(R0).transpose(), consensus) < 2.0;
        }
        if (!agrees) {
          sr.dropped.push_back(images[c][q.image] + ": the two cameras' board poses disagree with the other pairs");
          continue;
        }
        q.pts_c = rev;
      }
      objs.push_back(obj);
      p0.push_back(c0.points[q.v0]);
      pc.push_back(q.pts_c);
    }
    if (p0.empty()) throw InputError(fmt::format("camera {}: no consistent image pair with camera 0", c));
    cv::Mat R, T, E, F;
    cv::Mat K0 = c0.K.clone(), D0 = c0.D.clone(), Kc = cc.K.clone(), Dc = cc.D.clone();
    try {
      sr.rms_px = cv::stereoCalibrate(objs, p0, pc, K0, D0, Kc, Dc, cv::Size(c0.camera.width, c0.camera.height), R, T,
                                      E, F, cv::CALIB_FIX_INTRINSIC,
                                      cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 200, 1e-12));
    } catch (const cv::Exception& e) {
      throw InputError(fmt::format("camera {}: the stereo calibration with camera 0 failed ({})", c, e.msg));
    }
    sr.n_pairs = static_cast<int>(p0.size());
    Camera& cam = res.rig.cameras[c];
    cam.R = to_eigen(R);
    cam.t = Vec3(T.at<double>(0), T.at<double>(1), T.at<double>(2));
    sr.baseline = cam.centre().norm();
    res.stereo.push_back(sr);
  }
  return res;
}

nlohmann::json calibration_report(const CalibrationResult& r, const CalibrateOptions& o) {
  nlohmann::json j;
  const char* kinds[] = {"chessboard", "circles", "asymmetric-circles"};
  j["target"] = {{"kind", kinds[static_cast<int>(o.target.kind)]},
                 {"pattern", {o.target.cols, o.target.rows}},
                 {"spacing", o.target.spacing}};
  j["model"] = {{"k3", o.fix_k3 ? "fixed at 0" : "estimated"},
                {"tangential", o.zero_tangential ? "fixed at 0" : "estimated"},
                {"aspect", o.fix_aspect ? "fx = fy" : "fx, fy free"}};
  nlohmann::json cams = nlohmann::json::array();
  for (const CameraReport& c : r.cameras) {
    nlohmann::json cj;
    cj["name"] = c.name;
    cj["rms_reprojection_px"] = c.rms_px;
    cj["views_used"] = c.n_used;
    nlohmann::json ims = nlohmann::json::array();
    for (const ImageReport& ir : c.images) {
      nlohmann::json ij{{"image", ir.name}, {"found", ir.found}};
      if (ir.found) ij["rms_reprojection_px"] = ir.rms_px;
      if (!ir.note.empty()) ij["note"] = ir.note;
      ims.push_back(ij);
    }
    cj["images"] = ims;
    cams.push_back(cj);
  }
  j["cameras"] = cams;
  nlohmann::json st = nlohmann::json::array();
  for (const StereoReport& s : r.stereo)
    st.push_back({{"camera", s.camera},
                  {"pairs", s.n_pairs},
                  {"rms_reprojection_px", s.rms_px},
                  {"baseline", s.baseline},
                  {"dropped", s.dropped}});
  j["stereo"] = st;
  return j;
}

}  // namespace sf::gsa::digitise

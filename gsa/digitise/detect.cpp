#include "gsa/digitise/detect.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <unordered_map>

#include "common/core/error.hpp"

namespace sf::gsa::digitise {

void DetectOptions::validate() const {
  auto need = [](bool ok, const char* option, const std::string& what) {
    if (!ok) throw UsageError(std::string(option) + ": " + what);
  };
  need(threshold > 0 && threshold < 1, "--threshold", "expected a contrast between 0 and 1");
  need(min_contrast >= 0 && min_contrast < 1, "--min-contrast", "expected a contrast between 0 and 1");
  need(mark_size_px >= 0, "--mark-size", "expected a size in pixels >= 0 (0: measured)");
  need(min_area_px >= 1, "--min-area", "expected an area of at least 1 pixel");
  need(area_low > 0 && area_low < 1 && area_high > 1, "--area-range", "expected LOW < 1 < HIGH");
  need(max_outline_residual > 0, "--max-outline-residual", "expected a positive fraction");
  need(min_axis_ratio > 0 && min_axis_ratio <= 1, "--min-axis-ratio", "expected a ratio in (0, 1]");
  need(reference_area_ratio > 1, "--reference-ratio", "expected an area ratio > 1");
  need(partial_area_change > 0 && partial_area_change < 1, "--partial-change", "expected a fraction in (0, 1)");
  need(lattice_tolerance > 0.05 && lattice_tolerance < 0.5, "--lattice-tolerance",
       "expected a fraction of the grid step in (0.05, 0.5)");
}

namespace {

constexpr int kMinMarks = 9;

std::string px(const Vec2& p) { return fmt::format("({:.1f}, {:.1f})", p.x(), p.y()); }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

// Bilinear sample of a CV_32F image at pixel coordinates (x, y); NaN outside.
double bilinear(const cv::Mat& m, double x, double y) {
  if (!(x >= 0 && y >= 0 && x <= m.cols - 1 && y <= m.rows - 1)) return std::numeric_limits<double>::quiet_NaN();
  const int x0 = std::min(static_cast<int>(x), m.cols - 2), y0 = std::min(static_cast<int>(y), m.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = m.ptr<float>(y0);
  const float* r1 = m.ptr<float>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

// The image with marks dark, its contrast C = (B - I) / B and the mark size in pixels.
struct Prepared {
  cv::Mat I, C;
  double size = 0;  // dots: diameter; lines: cell size (pitch)
};

Prepared prepare(const GreyImage& image, const std::string& name, const DetectOptions& o) {
  Prepared p;
  cv::Mat src(image.height, image.width, CV_32F, const_cast<float*>(image.pixels.data()));
  // Dark marks: the image itself, not a copy (it is only read; large buffers cost page
  // faults).
  p.I = o.dark_marks ? src : cv::Mat(1.0f - src);
  p.size = o.mark_size_px;
  if (!(p.size > 0)) {
    // Otsu's global threshold on the image at half size is enough to measure the typical
    // mark (or cell) size.
    cv::Mat half, u8, bin;
    cv::resize(p.I, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    half.convertTo(u8, CV_8U, 255.0);
    cv::threshold(u8, bin, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);  // dark = 255
    if (o.kind == MarkKind::kLines) bin = 255 - bin;                          // light cells
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(bin, labels, stats, centroids, o.kind == MarkKind::kLines ? 4 : 8);
    std::vector<double> areas;  // full-size pixels
    const double max_area = 0.01 * image.width * image.height;
    for (int k = 1; k < n; ++k) {
      const double a = 4.0 * stats.at<int>(k, cv::CC_STAT_AREA);
      if (a >= std::max(o.min_area_px, 8.0) && a < max_area) areas.push_back(a);
    }
    if (static_cast<int>(areas.size()) < kMinMarks)
      throw InputError(name + ": no grid found (" + std::to_string(areas.size()) +
                       (o.kind == MarkKind::kDots ? " dot-like blobs" : " grid cells") +
                       "; is the sheet in view, in focus and lit, and are --marks and --light-marks right?)");
    const double a = median(areas);
    p.size = o.kind == MarkKind::kDots ? 2.0 * std::sqrt(a / kPi) : std::sqrt(a);
  }
  // Local sheet brightness: closing wider than a mark removes the marks and keeps the light.
  int k = o.kind == MarkKind::kDots ? static_cast<int>(2.0 * p.size) + 3 : static_cast<int>(p.size / 2.5) + 3;
  k |= 1;
  k = std::min(k, (std::min(image.width, image.height) / 2) | 1);
  // No smoothing of B: it would spread the sheet's brightness over the dark surroundings
  // and raise the contrast in a band along the part's edge. C is computed in B's buffer.
  cv::morphologyEx(p.I, p.C, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  for (int y = 0; y < p.I.rows; ++y) {
    const float* i = p.I.ptr<float>(y);
    float* c = p.C.ptr<float>(y);
    for (int x = 0; x < p.I.cols; ++x) {
      const float bb = std::max(c[x], 0.02f);
      c[x] = (bb - i[x]) / bb;
    }
  }
  return p;
}

// Second moments of a pixel set: centre, semi-axes (a >= b), angle and the outline residual.
struct Shape {
  Vec2 centre = Vec2::Zero();
  double a = 0, b = 0, angle = 0;
  double outline_residual = 0;  // RMS relative deviation of the outline from the ellipse
  Mat2 cov = Mat2::Identity();
};

template <class InSet>
Shape pixel_shape(const cv::Rect& box, InSet in) {
  Shape s;
  double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x)
      if (in(x, y)) {
        n += 1;
        sx += x;
        sy += y;
        sxx += double(x) * x;
        syy += double(y) * y;
        sxy += double(x) * y;
      }
  if (n < 1) return s;
  s.centre = Vec2(sx / n, sy / n);
  s.cov << sxx / n - s.centre.x() * s.centre.x() + 1.0 / 12, sxy / n - s.centre.x() * s.centre.y(),
      sxy / n - s.centre.x() * s.centre.y(), syy / n - s.centre.y() * s.centre.y() + 1.0 / 12;
  Eigen::SelfAdjointEigenSolver<Mat2> es(s.cov);
  s.a = 2.0 * std::sqrt(std::max(es.eigenvalues()(1), 1e-12));
  s.b = 2.0 * std::sqrt(std::max(es.eigenvalues()(0), 1e-12));
  s.angle = std::atan2(es.eigenvectors()(1, 1), es.eigenvectors()(0, 1));
  // Outline: pixels of the set with a 4-neighbour outside it; rho = 1 on the moment ellipse.
  const Mat2 inv = (4.0 * s.cov).inverse();
  std::vector<double> rho;
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x)
      if (in(x, y) && (!in(x - 1, y) || !in(x + 1, y) || !in(x, y - 1) || !in(x, y + 1))) {
        const Vec2 d = Vec2(x, y) - s.centre;
        rho.push_back(std::sqrt(d.dot(inv * d)));
      }
  if (rho.size() >= 3) {
    const double mean = std::accumulate(rho.begin(), rho.end(), 0.0) / rho.size();
    double ss = 0;
    for (double r : rho) ss += (r - mean) * (r - mean);
    s.outline_residual = std::sqrt(ss / rho.size()) / std::max(mean, 1e-9);
  }
  return s;
}

struct Blob {
  int label = 0;
  cv::Rect box;
  Shape shape;
  double area = 0;             // pixels above the threshold
  double contrast = 0;         // median C over the blob
  double peak = 0;             // 90th percentile of C over the blob: the ink's contrast
  Vec2 centre = Vec2::Zero();  // refined
  double grey_area = 0;        // sum of (P - I) / P over the window: the dot's area times its contrast
  double rim_residual = 0;     // RMS deviation of the window's rim from a plane / sheet level
};

// Grey-level centroid of a dot: weights (P - I) / P over a window that follows the blob's
// moment ellipse at a constant distance (so it stays on the sheet beside a foreshortened
// dot near the part's edge); P is a plane fitted to the window's rim, the local sheet level.
bool grey_centroid(const Prepared& p, const cv::Mat& labels, Blob& b, std::string& why) {
  const double m_in = 2.0, m_out = 3.5;  // rim: this many pixels outside the blob's ellipse
  const int m = static_cast<int>(std::ceil(m_out)) + 1;
  const cv::Rect win = (b.box + cv::Size(2 * m, 2 * m) - cv::Point(m, m)) & cv::Rect(0, 0, p.I.cols, p.I.rows);
  const Mat2 inv = (4.0 * b.shape.cov).inverse();
  const double cx = b.shape.centre.x(), cy = b.shape.centre.y();
  // 0: outside the window, 1: inside, 2: rim.
  auto zone = [&](int x, int y) {
    const int l = labels.at<int>(y, x);
    if (l != 0 && l != b.label) return 0;
    const Vec2 d(x - cx, y - cy);
    const double rho = std::sqrt(d.dot(inv * d));
    const double out = rho <= 1.0 ? 0.0 : (rho - 1.0) * d.norm() / rho;  // pixels beyond the ellipse
    if (out > m_out) return 0;
    return out >= m_in ? 2 : 1;
  };
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Vec3 rhs = Vec3::Zero();
  int n_rim = 0;
  for (int y = win.y; y < win.y + win.height; ++y)
    for (int x = win.x; x < win.x + win.width; ++x) {
      if (zone(x, y) != 2) continue;
      const Vec3 row(1.0, x - cx, y - cy);
      A += row * row.transpose();
      rhs += row * p.I.at<float>(y, x);
      ++n_rim;
    }
  if (n_rim < 12 || std::abs(A.determinant()) < 1e-9) {
    why = "no clean sheet around it (neighbouring blobs too close)";
    return false;
  }
  const Vec3 plane = A.ldlt().solve(rhs);
  // How well the rim is a plane: an edge, an occluder or a shadow beside the dot shows.
  double rr = 0, sw = 0, swx = 0, swy = 0;
  for (int y = win.y; y < win.y + win.height; ++y)
    for (int x = win.x; x < win.x + win.width; ++x) {
      const int z = zone(x, y);
      if (z == 0) continue;
      const double P = plane(0) + plane(1) * (x - cx) + plane(2) * (y - cy);
      const double I = p.I.at<float>(y, x);
      if (z == 2) rr += (I - P) * (I - P);
      if (!(P > 1e-3)) continue;
      const double w = (P - I) / P;
      sw += w;
      swx += w * (x - cx);
      swy += w * (y - cy);
    }
  b.rim_residual = std::sqrt(rr / n_rim) / std::max(plane(0), 1e-3);
  if (!(sw > 0.25 * b.area * b.contrast)) {
    why = "too faint against the sheet around it";
    return false;
  }
  b.centre = Vec2(cx + swx / sw, cy + swy / sw);
  b.grey_area = sw;
  return true;
}

// Centre of an ellipse through sub-pixel edge points at half the dot's contrast.
bool ellipse_centre(const Prepared& p, Blob& b, std::string& why) {
  const double r = std::sqrt(b.shape.a * b.shape.b);
  const double level = 0.5 * b.contrast;
  std::vector<cv::Point2f> edge;
  for (int k = 0; k < 72; ++k) {
    const double t = 2 * kPi * k / 72;
    const Vec2 d(std::cos(t), std::sin(t));
    double prev = bilinear(p.C, b.shape.centre.x(), b.shape.centre.y());
    for (double s = 0.25; s < 2.5 * r + 3; s += 0.25) {
      const Vec2 q = b.shape.centre + s * d;
      const double c = bilinear(p.C, q.x(), q.y());
      if (std::isnan(c)) break;
      if (prev >= level && c < level) {
        const double f = (prev - level) / (prev - c);
        const Vec2 e = b.shape.centre + (s - 0.25 + 0.25 * f) * d;
        edge.emplace_back(static_cast<float>(e.x()), static_cast<float>(e.y()));
        break;
      }
      prev = c;
    }
  }
  if (edge.size() < 12) {
    why = "no clear edge for the ellipse fit";
    return false;
  }
  const cv::RotatedRect e = cv::fitEllipse(edge);
  b.centre = Vec2(e.center.x, e.center.y);
  if ((b.centre - b.shape.centre).norm() > 0.5 * r) {
    why = "the ellipse fit strayed from the blob";
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------
// Dots

struct DotDetection {
  std::vector<Blob> dots;
  Index n_blobs = 0;
  int reference = -1;  // index into dots
  std::string reference_note;
};

DotDetection detect_dots(const Prepared& p, const DetectOptions& o, ViewMarks& v) {
  DotDetection out;
  cv::Mat mask = p.C > o.threshold;
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<Blob> cand;
  const int W = p.I.cols, H = p.I.rows;
  const double huge = 0.02 * W * H;
  for (int k = 1; k < n; ++k) {
    Blob b;
    b.label = k;
    b.box = cv::Rect(stats.at<int>(k, cv::CC_STAT_LEFT), stats.at<int>(k, cv::CC_STAT_TOP),
                     stats.at<int>(k, cv::CC_STAT_WIDTH), stats.at<int>(k, cv::CC_STAT_HEIGHT));
    b.area = stats.at<int>(k, cv::CC_STAT_AREA);
    if (b.area < o.min_area_px || b.area > huge) continue;  // noise specks; the part's outline
    ++out.n_blobs;
    const Vec2 c(centroids.at<double>(k, 0), centroids.at<double>(k, 1));
    if (b.box.x == 0 || b.box.y == 0 || b.box.x + b.box.width == W || b.box.y + b.box.height == H) {
      v.rejected.push_back({c, "touches the image border"});
      continue;
    }
    cand.push_back(b);
  }
  std::vector<double> areas;
  for (const Blob& b : cand) areas.push_back(b.area);
  const double med = median(areas);
  v.median_area_px = med;
  for (Blob& b : cand) {
    const Vec2 c(centroids.at<double>(b.label, 0), centroids.at<double>(b.label, 1));
    if (b.area < o.area_low * med || b.area > o.area_high * med) {
      v.rejected.push_back({c, fmt::format("area {:.0f} px outside [{:.0f}, {:.0f}] px ({} to {} x the median)", b.area,
                                           o.area_low * med, o.area_high * med, o.area_low, o.area_high)});
      continue;
    }
    const int lab = b.label;
    b.shape = pixel_shape(
        b.box, [&](int x, int y) { return x >= 0 && y >= 0 && x < W && y < H && labels.at<int>(y, x) == lab; });
    const double radius = std::sqrt(b.shape.a * b.shape.b);
    const double allowed = o.max_outline_residual + 0.35 / std::max(radius, 1.0);
    if (b.shape.outline_residual > allowed) {
      v.rejected.push_back({c, fmt::format("outline not an ellipse (residual {:.3f} > {:.3f} of the radius)",
                                           b.shape.outline_residual, allowed)});
      continue;
    }
    if (b.shape.b < o.min_axis_ratio * b.shape.a) {
      v.rejected.push_back(
          {c, fmt::format("too elongated (axis ratio {:.2f} < {})", b.shape.b / b.shape.a, o.min_axis_ratio)});
      continue;
    }
    std::vector<double> cs;
    for (int y = b.box.y; y < b.box.y + b.box.height; ++y)
      for (int x = b.box.x; x < b.box.x + b.box.width; ++x)
        if (labels.at<int>(y, x) == lab) cs.push_back(p.C.at<float>(y, x));
    b.contrast = median(cs);
    std::nth_element(cs.begin(), cs.begin() + (cs.size() * 9) / 10, cs.end());
    b.peak = cs[(cs.size() * 9) / 10];
    if (b.contrast < o.min_contrast) {
      v.rejected.push_back({c, fmt::format("contrast {:.2f} < {}", b.contrast, o.min_contrast)});
      continue;
    }
    std::string why;
    if (!grey_centroid(p, labels, b, why) || (o.centre == CentreMethod::kEllipse && !ellipse_centre(p, b, why))) {
      v.rejected.push_back({c, why});
      continue;
    }
    out.dots.push_back(b);
  }
  // Dots whose surroundings are not a clean plane of sheet (an occluder's or the part's
  // edge, a shadow beside them): their centroids would be pulled. Measured against the
  // image's typical rim residual (noise and shading).
  {
    std::vector<double> rims;
    for (const Blob& b : out.dots) rims.push_back(b.rim_residual);
    const double limit = std::max(4.0 * median(rims), 0.01);
    v.thresholds["max_rim_residual"] = limit;
    std::vector<Blob> clean;
    for (const Blob& b : out.dots) {
      if (b.rim_residual > limit)
        v.rejected.push_back({b.centre, fmt::format("uneven sheet around the dot (an edge or shadow beside it: rim "
                                                    "residual {:.3f} > {:.3f})",
                                                    b.rim_residual, limit)});
      else
        clean.push_back(b);
    }
    out.dots.swap(clean);
  }
  // The reference: one dot with reference_area_ratio x its neighbours' area.
  std::vector<Vec2> pts;
  for (const Blob& b : out.dots) pts.push_back(b.centre);
  if (pts.size() >= 7) {
    const PointGrid grid(pts, std::max(1.0, median_spacing(pts)));
    const double sp = median_spacing(pts);
    std::vector<int> refs;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      std::vector<std::pair<double, double>> nb;  // distance, area
      for (Index q : grid.within(pts[k], 2.5 * sp))
        if (q != static_cast<Index>(k)) nb.push_back({(pts[q] - pts[k]).squaredNorm(), out.dots[q].grey_area});
      std::sort(nb.begin(), nb.end());
      if (nb.size() > 8) nb.resize(8);
      std::vector<double> a;
      for (const auto& e : nb) a.push_back(e.second);
      if (a.size() >= 3 && out.dots[k].grey_area >= o.reference_area_ratio * median(a))
        refs.push_back(static_cast<int>(k));
    }
    if (refs.size() == 1)
      out.reference = refs[0];
    else if (refs.size() > 1) {
      out.reference_note = std::to_string(refs.size()) + " dots are reference-sized (at " + px(pts[refs[0]]) + ", " +
                           px(pts[refs[1]]) + "...): none used as the reference";
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Line grids

struct ArmFit {
  bool ok = false;
  double c0 = 0, c1 = 0, c2 = 0;  // q = c0 + c1 s + c2 s^2 (pixels)
  double rms = 0;
  double signal = 0;  // median line strength (contrast x width, pixels)
};

// Centre line of the line through p0 running along `along`, as offsets q along `across`
// measured on cross-sections at s in +-[r_in, r_out].
ArmFit fit_arm(const cv::Mat& C, const Vec2& p0, const Vec2& along, const Vec2& across, double r_in, double r_out,
               double h) {
  ArmFit f;
  std::vector<double> S, Q, G;
  int n_neg = 0, n_pos = 0;
  const double dq = 0.25;
  const int nq = static_cast<int>(h / dq);
  std::vector<double> prof(2 * nq + 1);
  // Sections every pixel, every half pixel where the line's arm is short (a compressed
  // grid on a steep slope).
  const double ds = r_out - r_in < 6.0 ? 0.5 : 1.0;
  for (double s = -r_out; s <= r_out + 1e-9; s += ds) {
    if (std::abs(s) < r_in) continue;
    bool inside = true;
    for (int k = -nq; k <= nq && inside; ++k) {
      const Vec2 q = p0 + s * along + (k * dq) * across;
      prof[k + nq] = bilinear(C, q.x(), q.y());
      inside = !std::isnan(prof[k + nq]);
    }
    if (!inside) continue;
    // Baseline: the outer quarter of the section on both sides.
    double base = 0;
    int nb = 0;
    for (int k = -nq; k <= nq; ++k)
      if (std::abs(k) > 0.75 * nq) {
        base += prof[k + nq];
        ++nb;
      }
    base /= std::max(nb, 1);
    // The line's extent at half its peak contrast; then the centroid over that extent plus
    // 1.5 pixels on each side (the blurred flanks), re-centred once: a narrow window keeps
    // the noise of the bare sheet out of the centroid.
    int kp = -nq;
    for (int k = -nq; k <= nq; ++k)
      if (prof[k + nq] > prof[kp + nq]) kp = k;
    const double half = 0.5 * (prof[kp + nq] + base);
    int kl = kp, kr = kp;
    while (kl > -nq && prof[kl - 1 + nq] > half) --kl;
    while (kr < nq && prof[kr + 1 + nq] > half) ++kr;
    if (kl == -nq || kr == nq) continue;  // no line inside the section
    double centre = 0.5 * (kl + kr) * dq;
    const double hw = 0.5 * (kr - kl + 1) * dq + 1.5;
    double sw = 0, swq = 0;
    for (int pass = 0; pass < 2; ++pass) {
      sw = swq = 0;
      for (int k = -nq; k <= nq; ++k) {
        const double q = k * dq;
        if (std::abs(q - centre) > hw) continue;
        const double w = prof[k + nq] - base;
        sw += w;
        swq += w * q;
      }
      if (!(sw > 0)) break;
      centre = swq / sw;
    }
    if (!(sw * dq > 0.2)) continue;
    S.push_back(s);
    Q.push_back(centre);
    G.push_back(sw * dq);
    (s < 0 ? n_neg : n_pos)++;
  }
  if (n_neg < 3 || n_pos < 3) return f;
  // Drop sections much weaker than the line's median (a partly hidden arm).
  const double gmed = median(G);
  std::vector<double> s2, q2;
  for (std::size_t k = 0; k < S.size(); ++k)
    if (G[k] >= 0.5 * gmed) {
      s2.push_back(S[k]);
      q2.push_back(Q[k]);
    }
  n_neg = static_cast<int>(std::count_if(s2.begin(), s2.end(), [](double s) { return s < 0; }));
  n_pos = static_cast<int>(s2.size()) - n_neg;
  if (n_neg < 3 || n_pos < 3) return f;
  const bool quad = n_neg >= 4 && n_pos >= 4;
  const int nc = quad ? 3 : 2;
  Eigen::MatrixXd A(s2.size(), nc);
  Eigen::VectorXd b(s2.size());
  for (std::size_t k = 0; k < s2.size(); ++k) {
    A(k, 0) = 1;
    A(k, 1) = s2[k];
    if (quad) A(k, 2) = s2[k] * s2[k];
    b(k) = q2[k];
  }
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  f.c0 = c(0);
  f.c1 = c(1);
  f.c2 = quad ? c(2) : 0.0;
  f.rms = std::sqrt((A * c - b).squaredNorm() / s2.size());
  f.signal = gmed;
  f.ok = true;
  return f;
}

// Junction of the i-line (running along axis_j) and the j-line (along axis_i) near p0.
bool refine_junction(const cv::Mat& C, Vec2& p, const Vec2& ai, const Vec2& aj, std::string& why) {
  const Vec2 u = ai.normalized(), v = aj.normalized();
  const double li = ai.norm(), lj = aj.norm();
  const Vec2 start = p;
  for (int pass = 0; pass < 3; ++pass) {
    // Line A: constant j, runs along u; sections along v. Line B: constant i, along v.
    // Sections run parallel to the other line, so even those close to the junction only see
    // the other line as a constant along them (removed with the baseline).
    const ArmFit A = fit_arm(C, p, u, v, std::min(3.0, 0.12 * li), 0.42 * li, 0.4 * lj);
    const ArmFit B = fit_arm(C, p, v, u, std::min(3.0, 0.12 * lj), 0.42 * lj, 0.4 * li);
    if (!A.ok || !B.ok) {
      why = "the four arms of the junction are not all visible";
      return false;
    }
    if (A.rms > 0.5 || B.rms > 0.5) {
      why = fmt::format("the arms are not straight lines (fit residual {:.2f} px)", std::max(A.rms, B.rms));
      return false;
    }
    // Solve s = qB(t), t = qA(s) (A: p + s u + qA(s) v; B: p + t v + qB(t) u).
    double s = B.c0, t = A.c0;
    for (int it = 0; it < 20; ++it) {
      const double s_new = B.c0 + B.c1 * t + B.c2 * t * t;
      const double t_new = A.c0 + A.c1 * s_new + A.c2 * s_new * s_new;
      const bool done = std::abs(s_new - s) < 1e-6 && std::abs(t_new - t) < 1e-6;
      s = s_new;
      t = t_new;
      if (done) break;
    }
    p += s * u + t * v;
    if (std::abs(s) < 1e-3 && std::abs(t) < 1e-3) break;
  }
  if ((p - start).norm() > 0.3 * std::min(li, lj)) {
    why = "the refined junction strayed from the cells around it";
    return false;
  }
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// find_marks

namespace {

Index seed_index(const std::vector<Vec2>& pts, const std::optional<Vec2>& seed, const std::string& name) {
  if (seed) {
    const double sp = median_spacing(pts);
    Index best = -1;
    double bd = 0.5 * sp;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const double d = (pts[k] - *seed).norm();
      if (d <= bd) {
        bd = d;
        best = static_cast<Index>(k);
      }
    }
    if (best < 0)
      throw InputError(name + ": --seed " + px(*seed) + ": no grid mark within half a grid step of that pixel");
    return best;
  }
  Vec2 mean = Vec2::Zero();
  for (const Vec2& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Index best = 0;
  for (std::size_t k = 1; k < pts.size(); ++k)
    if ((pts[k] - mean).squaredNorm() < (pts[best] - mean).squaredNorm()) best = static_cast<Index>(k);
  return best;
}

void report_unlabelled(const LatticeResult& lr, const std::vector<Vec2>& pts, const char* what, ViewMarks& v) {
  std::vector<char> noted(pts.size(), 0);
  for (Index k : lr.ambiguous) {
    v.rejected.push_back({pts[k], std::string(what) + ": two candidates for one grid position (not labelled)"});
    noted[k] = 1;
  }
  for (Index k : lr.conflicting) {
    v.rejected.push_back({pts[k], std::string(what) + ": paths through the grid disagree on its label (not labelled)"});
    noted[k] = 1;
  }
  for (std::size_t k = 0; k < pts.size(); ++k)
    if (!lr.labels[k] && !noted[k])
      v.rejected.push_back({pts[k], std::string(what) + ": not connected to the grid around the seed mark"});
}

// Points whose area differs by more than `change` from what their labelled neighbours
// predict -- interpolated between the two sides along the row or the column, or
// extrapolated from two on one side (foreshortening changes quickly toward a steep edge) --
// compared with the largest prediction for a small area and the smallest for a large one (a
// mark cut along its column has neighbours cut alike in that direction, not in the other).
// `ratio` receives area / prediction.
std::vector<char> area_outliers(const LatticeResult& lr, const std::vector<double>& area, Index exempt, double change,
                                std::vector<double>& ratio) {
  auto key = [](const Label& l) {
    return (static_cast<std::int64_t>(l.x()) << 32) ^ static_cast<std::uint32_t>(l.y());
  };
  std::unordered_map<std::int64_t, Index> at;
  for (std::size_t k = 0; k < area.size(); ++k)
    if (lr.labels[k]) at[key(*lr.labels[k])] = static_cast<Index>(k);
  auto area_at = [&](const Label& l) -> double {
    auto it = at.find(key(l));
    return it == at.end() || it->second == exempt ? -1.0 : area[it->second];
  };
  std::vector<char> out(area.size(), 0);
  ratio.assign(area.size(), 1.0);
  for (std::size_t k = 0; k < area.size(); ++k) {
    if (!lr.labels[k] || static_cast<Index>(k) == exempt) continue;
    const Label L = *lr.labels[k];
    std::vector<double> est;
    for (const Label& e : {Label(1, 0), Label(0, 1)}) {
      const double f1 = area_at(L + e), b1 = area_at(L - e), f2 = area_at(L + 2 * e), b2 = area_at(L - 2 * e);
      if (f1 > 0 && b1 > 0) est.push_back(0.5 * (f1 + b1));
      if (f1 > 0 && f2 > 0) est.push_back(2 * f1 - f2);
      if (b1 > 0 && b2 > 0) est.push_back(2 * b1 - b2);
    }
    if (est.size() < 2) continue;
    const double r_lo = area[k] / *std::max_element(est.begin(), est.end());
    const double r_hi = area[k] / *std::min_element(est.begin(), est.end());
    ratio[k] = r_lo < 1.0 - change ? r_lo : r_hi;
    out[k] = r_lo < 1.0 - change || r_hi > 1.0 + change;
  }
  return out;
}

void find_dots(const Prepared& p, const std::string& name, const DetectOptions& o, ViewMarks& v) {
  const DotDetection det = detect_dots(p, o, v);
  v.n_candidates = det.n_blobs;
  if (static_cast<int>(det.dots.size()) < kMinMarks)
    throw InputError(
        fmt::format("{}: too few grid marks ({} dots pass the size, shape and contrast tests out of {} "
                    "blobs; need {})",
                    name, det.dots.size(), det.n_blobs, kMinMarks));
  std::vector<Vec2> pts;
  for (const Blob& b : det.dots) pts.push_back(b.centre);
  if (!det.reference_note.empty()) v.thresholds["reference"] = det.reference_note;
  Index seed;
  if (det.reference >= 0) {
    seed = det.reference;
    v.has_reference = true;
    v.reference_pixel = pts[seed];
  } else {
    seed = seed_index(pts, o.seed, name);
  }
  LatticeOptions lo;
  lo.tolerance = o.lattice_tolerance;
  // Pass 1 labels every dot; dots whose area differs from what their labelled neighbours
  // predict are partly hidden or cut, and their biased centres would mislead the
  // extrapolation, so pass 2 labels the others again.
  const LatticeResult first = grow_lattice(pts, seed, lo);
  std::vector<double> dot_area, ratio;
  for (const Blob& b : det.dots) dot_area.push_back(b.grey_area);
  const std::vector<char> partial = area_outliers(first, dot_area, det.reference, o.partial_area_change, ratio);
  for (std::size_t k = 0; k < pts.size(); ++k)
    if (partial[k])
      v.rejected.push_back({pts[k], fmt::format("dot ({}, {}): area {:.0f}% of what its neighbours predict "
                                                "(partly hidden or cut by the part's edge)",
                                                first.labels[k]->x(), first.labels[k]->y(), 100.0 * ratio[k])});
  std::vector<Vec2> kept;
  std::vector<Index> from;
  Index seed2 = -1;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (partial[k]) continue;
    if (static_cast<Index>(k) == seed) seed2 = static_cast<Index>(kept.size());
    kept.push_back(pts[k]);
    from.push_back(static_cast<Index>(k));
  }
  const LatticeResult lr = grow_lattice(kept, seed2, lo);
  report_unlabelled(lr, kept, "dot", v);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    if (!lr.labels[k]) continue;
    v.centres.push_back(kept[k]);
    v.labels.push_back(*lr.labels[k]);
    // The dot's image area: its grey-level area over its ink contrast.
    v.areas.push_back(det.dots[from[k]].grey_area / std::max(det.dots[from[k]].peak, 1e-3));
    v.axis_i.push_back(lr.axis_i[k]);
    v.axis_j.push_back(lr.axis_j[k]);
  }
}

void find_lines(const Prepared& p, const std::string& name, const DetectOptions& o, ViewMarks& v) {
  const int W = p.I.cols, H = p.I.rows;
  cv::Mat ink = p.C > o.threshold;
  cv::Mat paper = p.C <= o.threshold;
  cv::Mat plab, pstats, pcent, ilab, istats, icent;
  const int np = cv::connectedComponentsWithStats(paper, plab, pstats, pcent, 4, CV_32S);
  const int ni = cv::connectedComponentsWithStats(ink, ilab, istats, icent, 8, CV_32S);
  auto touches = [&](const cv::Mat& st, int k) {
    const int x = st.at<int>(k, cv::CC_STAT_LEFT), y = st.at<int>(k, cv::CC_STAT_TOP);
    return x == 0 || y == 0 || x + st.at<int>(k, cv::CC_STAT_WIDTH) == W || y + st.at<int>(k, cv::CC_STAT_HEIGHT) == H;
  };
  std::vector<double> areas;
  for (int k = 1; k < np; ++k) {
    const double a = pstats.at<int>(k, cv::CC_STAT_AREA);
    if (a >= std::max(o.min_area_px, 20.0) && !touches(pstats, k) && a < 0.02 * W * H) areas.push_back(a);
  }
  const double med = median(areas);
  v.median_area_px = med;
  // Dots inside cells (the reference): small ink blobs with one cell all around them.
  std::unordered_map<int, int> dot_of_cell;  // paper label -> ink label
  for (int k = 1; k < ni; ++k) {
    const double a = istats.at<int>(k, cv::CC_STAT_AREA);
    if (a < o.min_area_px || a > 0.5 * med || touches(istats, k)) continue;
    const Vec2 c(icent.at<double>(k, 0), icent.at<double>(k, 1));
    const double r = std::sqrt(a / kPi) + 2.5;
    int cell = -1;
    bool one = true;
    for (int d = 0; d < 8 && one; ++d) {
      const double t = 2 * kPi * d / 8;
      const int x = static_cast<int>(std::lround(c.x() + r * std::cos(t))),
                y = static_cast<int>(std::lround(c.y() + r * std::sin(t)));
      if (x < 0 || y < 0 || x >= W || y >= H) {
        one = false;
        break;
      }
      const int l = plab.at<int>(y, x);
      if (l == 0 || (cell >= 0 && l != cell)) one = false;
      cell = l;
    }
    if (one && cell > 0) dot_of_cell[cell] = k;
  }
  struct Cell {
    int label;  // negative: the cell holds the reference dot
    Vec2 centre;
    double area;
  };
  std::vector<Cell> cells;
  Index n_cand = 0;
  for (int k = 1; k < np; ++k) {
    double a = pstats.at<int>(k, cv::CC_STAT_AREA);
    if (a < std::max(o.min_area_px, 20.0) || a > 0.02 * W * H) continue;
    ++n_cand;
    const Vec2 c(pcent.at<double>(k, 0), pcent.at<double>(k, 1));
    if (touches(pstats, k)) {
      v.rejected.push_back({c, "cell touches the image border"});
      continue;
    }
    auto it = dot_of_cell.find(k);
    const int dot = it == dot_of_cell.end() ? -1 : it->second;
    if (dot >= 0) a += istats.at<int>(dot, cv::CC_STAT_AREA);
    if (a < o.area_low * med || a > o.area_high * med) {
      v.rejected.push_back(
          {c, fmt::format("cell area {:.0f} px outside [{:.0f}, {:.0f}] px", a, o.area_low * med, o.area_high * med)});
      continue;
    }
    const cv::Rect box(pstats.at<int>(k, cv::CC_STAT_LEFT), pstats.at<int>(k, cv::CC_STAT_TOP),
                       pstats.at<int>(k, cv::CC_STAT_WIDTH), pstats.at<int>(k, cv::CC_STAT_HEIGHT));
    const Shape s = pixel_shape(box, [&](int x, int y) {
      return x >= 0 && y >= 0 && x < W && y < H && (plab.at<int>(y, x) == k || (dot >= 0 && ilab.at<int>(y, x) == dot));
    });
    // A convex quadrilateral fills 0.955 of its moment ellipse (any parallelogram exactly).
    const double fill = a / (kPi * s.a * s.b);
    if (fill < 0.85 || fill > 1.02) {
      v.rejected.push_back({c, fmt::format("cell is not a quadrilateral (fills {:.2f} of its moment ellipse; a "
                                           "parallelogram fills 0.955)",
                                           fill)});
      continue;
    }
    cells.push_back({dot >= 0 ? -k : k, s.centre, a});
  }
  v.n_candidates = n_cand;
  if (static_cast<int>(cells.size()) < kMinMarks)
    throw InputError(fmt::format("{}: too few grid cells ({} pass the size and shape tests out of {}; need {})", name,
                                 cells.size(), n_cand, kMinMarks));
  std::vector<Vec2> pts;
  Index ref = -1;
  int n_refs = 0;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    pts.push_back(cells[k].centre);
    if (cells[k].label < 0) {
      ref = static_cast<Index>(k);
      ++n_refs;
    }
  }
  Index seed;
  if (n_refs == 1) {
    seed = ref;
    v.has_reference = true;
    v.reference_pixel = pts[ref];
    v.reference_lattice = Vec2(0.5, 0.5);
  } else {
    if (n_refs > 1)
      v.thresholds["reference"] = std::to_string(n_refs) + " cells hold a dot: none used as the reference";
    seed = seed_index(pts, o.seed, name);
  }
  LatticeOptions lo;
  lo.tolerance = o.lattice_tolerance;
  // Pass 1 labels every cell; a cell whose area differs from what its neighbours predict
  // is two cells merged (a line lost) or a cut one, and its centre would mislead both the
  // labels and the junctions: pass 2 labels the others again.
  std::vector<double> cell_area;
  for (const Cell& c : cells) cell_area.push_back(c.area);
  const LatticeResult first = grow_lattice(pts, seed, lo);
  std::vector<double> ratio;
  const std::vector<char> odd = area_outliers(first, cell_area, -1, 0.25, ratio);
  std::vector<Vec2> kept;
  Index seed2 = -1;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (odd[k]) {
      v.rejected.push_back({pts[k], fmt::format("cell ({}, {}): area {:.0f}% of what its neighbours predict (merged "
                                                "with a neighbour, or cut)",
                                                first.labels[k]->x(), first.labels[k]->y(), 100 * ratio[k])});
      continue;
    }
    if (static_cast<Index>(k) == seed) seed2 = static_cast<Index>(kept.size());
    kept.push_back(pts[k]);
  }
  pts.swap(kept);
  const LatticeResult lr = grow_lattice(pts, seed2, lo);
  report_unlabelled(lr, pts, "cell", v);
  // Junction estimates from the labelled cells around each.
  struct Acc {
    Vec2 sum = Vec2::Zero(), ai = Vec2::Zero(), aj = Vec2::Zero();
    int n = 0;
  };
  std::map<std::pair<int, int>, Acc> acc;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (!lr.labels[k]) continue;
    const Label L = *lr.labels[k];
    for (int db = 0; db <= 1; ++db)
      for (int da = 0; da <= 1; ++da) {
        Acc& a = acc[{L.x() + da, L.y() + db}];
        a.sum += pts[k] + (da - 0.5) * lr.axis_i[k] + (db - 0.5) * lr.axis_j[k];
        a.ai += lr.axis_i[k];
        a.aj += lr.axis_j[k];
        ++a.n;
      }
  }
  struct Junction {
    Vec2 q, ai, aj;
  };
  std::map<std::pair<int, int>, Junction> found;
  for (const auto& [ij, a] : acc) {
    Vec2 q = a.sum / a.n;
    const Vec2 ai = a.ai / a.n, aj = a.aj / a.n;
    if (a.n < 2) {  // a grid corner: one cell alone places it too loosely to trust its label
      v.rejected.push_back(
          {q, fmt::format("junction ({}, {}): only one labelled cell next to it", ij.first, ij.second)});
      continue;
    }
    std::string why;
    if (!refine_junction(p.C, q, ai, aj, why)) {
      v.rejected.push_back({q, fmt::format("junction ({}, {}): {}", ij.first, ij.second, why)});
      continue;
    }
    found[ij] = {q, ai, aj};
  }
  // Each junction must sit where its neighbours along the row and the column put it (within
  // a quarter of a step): a junction refined onto its neighbour's crossing is caught here.
  for (const auto& [ij, jn] : found) {
    bool bad = false;
    for (const auto& [di, dj] : {std::pair<int, int>{1, 0}, {0, 1}}) {
      auto f = found.find({ij.first + di, ij.second + dj}), b = found.find({ij.first - di, ij.second - dj});
      if (f == found.end() || b == found.end()) continue;
      const Vec2 mid = 0.5 * (f->second.q + b->second.q);
      bad = bad || (jn.q - mid).norm() > 0.25 * 0.5 * (f->second.q - b->second.q).norm();
    }
    if (bad) {
      v.rejected.push_back(
          {jn.q, fmt::format("junction ({}, {}): off the lines through its neighbours", ij.first, ij.second)});
      continue;
    }
    v.centres.push_back(jn.q);
    v.labels.push_back(Label(ij.first, ij.second));
    v.areas.push_back(0.0);
    v.axis_i.push_back(jn.ai);
    v.axis_j.push_back(jn.aj);
  }
}

}  // namespace

ViewMarks find_marks(const GreyImage& image, const std::string& name, const DetectOptions& o) {
  if (image.width < 16 || image.height < 16)
    throw InputError(name + ": image too small (" + std::to_string(image.width) + " x " + std::to_string(image.height) +
                     " pixels)");
  ViewMarks v;
  v.name = name;
  v.width = image.width;
  v.height = image.height;
  v.kind = o.kind;
  const Prepared p = prepare(image, name, o);
  v.mark_size_px = p.size;
  v.thresholds = {{"threshold", o.threshold},
                  {"min_contrast", o.min_contrast},
                  {"mark_size_px", p.size},
                  {"min_area_px", o.min_area_px},
                  {"area_range", {o.area_low, o.area_high}},
                  {"max_outline_residual", o.max_outline_residual},
                  {"min_axis_ratio", o.min_axis_ratio},
                  {"reference_area_ratio", o.reference_area_ratio},
                  {"partial_area_change", o.partial_area_change},
                  {"lattice_tolerance", o.lattice_tolerance}};
  if (o.kind == MarkKind::kDots)
    find_dots(p, name, o, v);
  else
    find_lines(p, name, o, v);
  if (static_cast<int>(v.centres.size()) < kMinMarks)
    throw InputError(
        fmt::format("{}: too few labelled grid marks ({}; need {}). {} candidates were found; see the "
                    "report for why the others were dropped",
                    name, v.centres.size(), kMinMarks, v.n_candidates));
  return v;
}

}  // namespace sf::gsa::digitise

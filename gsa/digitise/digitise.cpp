#include "gsa/digitise/digitise.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <fmt/format.h>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/io/grid_file.hpp"

namespace sf::gsa::digitise {

void DigitiseOptions::validate() const {
  detect.validate();
  if (!(match.tolerance_px > 0)) throw UsageError("--epipolar-tolerance: expected a distance in pixels > 0");
  if (!(triangulation.max_reprojection_px > 0))
    throw UsageError("--max-reprojection: expected a distance in pixels > 0");
  if (!(dot_diameter_mm >= 0)) throw UsageError("--dot-diameter: expected a diameter in mm >= 0 (0: measured)");
  if (threads < 0) throw UsageError("digitise: the thread count must be >= 0");
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::int64_t key(const Label& l) {
  return (static_cast<std::int64_t>(l.x()) << 32) ^ static_cast<std::uint32_t>(l.y());
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

nlohmann::json px(const Vec2& p) { return {std::round(p.x() * 100) / 100, std::round(p.y() * 100) / 100}; }

}  // namespace

std::vector<NamedImage> read_image_set(const Rig& rig, const std::vector<std::string>& paths, const std::string& option,
                                       const std::string& rig_name) {
  if (static_cast<Index>(paths.size()) != rig.n_cameras())
    throw InputError(
        fmt::format("{}: {} image{} given, but the rig {} has {} camera{} (one image per camera, in the "
                    "rig's order: {})",
                    option, paths.size(), paths.size() == 1 ? "" : "s", rig_name, rig.n_cameras(),
                    rig.n_cameras() == 1 ? "" : "s", [&] {
                      std::string s;
                      for (const Camera& c : rig.cameras) s += (s.empty() ? "" : ", ") + c.name;
                      return s;
                    }()));
  // Read (decode) in parallel, one thread per image; errors reported in the rig's order.
  std::vector<NamedImage> out(paths.size());
  std::vector<std::exception_ptr> errors(paths.size());
  {
    std::vector<std::thread> pool;
    for (std::size_t k = 0; k < paths.size(); ++k)
      pool.emplace_back([&, k] {
        try {
          out[k] = {paths[k], read_image(paths[k])};
        } catch (...) {
          errors[k] = std::current_exception();
        }
      });
    for (auto& t : pool) t.join();
  }
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
  for (std::size_t k = 0; k < paths.size(); ++k) {
    const NamedImage& ni = out[k];
    const Camera& c = rig.cameras[k];
    if (ni.image.width != c.width || ni.image.height != c.height)
      throw InputError(
          fmt::format("{}: {} x {} pixels, but camera {} of {} was calibrated at {} x {} (is it the "
                      "right camera, in the rig's order, and the full uncropped image?)",
                      paths[k], ni.image.width, ni.image.height, c.name, rig_name, c.width, c.height));
  }
  return out;
}

SetResult digitise_set(const Rig& rig, const std::vector<NamedImage>& images, const DigitiseOptions& o) {
  const auto t0 = Clock::now();
  SetResult res;
  res.kind = o.detect.kind;
  const std::size_t nv = images.size();
  if (nv < 2) throw InputError("digitise: need images from at least two calibrated cameras");
  if (static_cast<Index>(nv) != rig.n_cameras())
    throw InputError(fmt::format("digitise: {} images for a rig of {} cameras", nv, rig.n_cameras()));

  // 1. Marks of each view, in parallel.
  std::vector<ViewMarks> marks(nv);
  std::vector<std::exception_ptr> errors(nv);
  std::vector<double> secs(nv, 0.0);
  {
    const int n_threads = o.threads > 0 ? o.threads : std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::thread> pool;
    std::size_t next = 0;
    std::mutex mu;
    auto work = [&] {
      for (;;) {
        std::size_t k;
        {
          std::lock_guard<std::mutex> lock(mu);
          if (next >= nv) return;
          k = next++;
        }
        try {
          const auto tv = Clock::now();
          DetectOptions d = o.detect;
          if (k != 0) d.seed.reset();  // a seed pixel belongs to camera 0's image
          marks[k] = find_marks(images[k].image, images[k].name, d);
          secs[k] = since(tv);
        } catch (...) {
          errors[k] = std::current_exception();
        }
      }
    };
    for (int t = 0; t < std::min<int>(n_threads, static_cast<int>(nv)); ++t) pool.emplace_back(work);
    for (auto& t : pool) t.join();
    for (auto& e : errors)
      if (e) std::rethrow_exception(e);
  }
  res.has_reference = marks[0].has_reference;
  res.reference_lattice = marks[0].reference_lattice;

  // 2. Every view's labels in camera 0's.
  res.views.resize(nv);
  std::vector<char> use(nv, 1);
  for (std::size_t v = 0; v < nv; ++v) {
    ViewReport& r = res.views[v];
    r.name = images[v].name;
    r.n_candidates = marks[v].n_candidates;
    r.n_labelled = static_cast<Index>(marks[v].centres.size());
    r.has_reference = marks[v].has_reference;
    r.reference_pixel = marks[v].reference_pixel;
    r.thresholds = marks[v].thresholds;
    r.rejected = marks[v].rejected;
    r.seconds = secs[v];
    r.transform = LabelTransform::identity(marks[0].reference_lattice);
    if (v == 0) continue;
    const MatchResult m = match_view(rig.cameras[0], marks[0], rig.cameras[v], marks[v], o.match);
    r.n_consistent = m.n_consistent;
    r.n_runner_up = m.n_second;
    if (!m.ok) {
      if (nv == 2) throw InputError(images[v].name + ": " + m.message);
      r.dropped = m.message;
      use[v] = 0;
      continue;
    }
    r.transform = m.transform;
  }
  Index n_used_views = 0;
  for (char u : use) n_used_views += u;
  if (n_used_views < 2)
    throw InputError(images[0].name + ": no other view's labels match camera 0's (see the report for each view)");

  // 3. Observations per label; marks off their epipolar line are dropped from that view.
  std::unordered_map<std::int64_t, std::size_t> at0;
  for (std::size_t k = 0; k < marks[0].labels.size(); ++k) at0[key(marks[0].labels[k])] = k;
  std::map<std::pair<int, int>, std::vector<Observation>> obs;
  std::map<std::pair<int, int>, std::vector<double>> areas;  // per observation, for the dot size
  for (std::size_t v = 0; v < nv; ++v) {
    if (!use[v]) continue;
    const Camera& cam = rig.cameras[v];
    const Mat3 E = essential_matrix(cam, rig.cameras[0]);
    Index used = 0;
    for (std::size_t k = 0; k < marks[v].labels.size(); ++k) {
      const Label L = res.views[v].transform.apply(marks[v].labels[k]);
      if (v != 0) {
        auto it = at0.find(key(L));
        if (it != at0.end()) {
          const double d =
              epipolar_distance_px(E, cam.pixel_to_normalised(marks[v].centres[k]),
                                   rig.cameras[0].pixel_to_normalised(marks[0].centres[it->second]), rig.cameras[0]);
          if (d > o.match.tolerance_px) {
            res.views[v].rejected.push_back(
                {marks[v].centres[k], fmt::format("mark ({}, {}): {:.2f} px off the epipolar line of camera 0's mark "
                                                  "(> {} px)",
                                                  L.x(), L.y(), d, o.match.tolerance_px)});
            continue;
          }
        }
      }
      obs[{L.x(), L.y()}].push_back({static_cast<Index>(v), marks[v].centres[k]});
      areas[{L.x(), L.y()}].push_back(marks[v].areas[k]);
      ++used;
    }
    res.views[v].n_used = used;
  }

  // 4. Triangulation.
  std::map<std::pair<int, int>, TriangulatedPoint> pts;
  for (const auto& [ij, ob] : obs) {
    if (ob.size() < 2) {  // reported below, with no position
      TriangulatedPoint one;
      one.why = "seen by one camera only (hidden or left out in the others)";
      pts[ij] = one;
      continue;
    }
    pts[ij] = triangulate(rig, ob, o.triangulation);
  }

  // 5. Perspective bias of dot centroids: normals from the neighbours, then again.
  if (o.detect.kind == MarkKind::kDots && o.bias_correction) {
    auto X_at = [&](int i, int j) -> const Vec3* {
      auto it = pts.find({i, j});
      return it != pts.end() && it->second.ok ? &it->second.X : nullptr;
    };
    auto axis = [&](int i, int j, int di, int dj) -> std::optional<Vec3> {
      const Vec3 *f = X_at(i + di, j + dj), *b = X_at(i - di, j - dj), *c = X_at(i, j);
      if (f && b) return *f - *b;
      if (f && c) return *f - *c;
      if (b && c) return *c - *b;
      return std::nullopt;
    };
    std::map<std::pair<int, int>, Vec3> normals;
    for (const auto& [ij, p] : pts) {
      if (!p.ok) continue;
      const auto a = axis(ij.first, ij.second, 1, 0), b = axis(ij.first, ij.second, 0, 1);
      if (a && b && a->cross(*b).norm() > 1e-12) normals[ij] = a->cross(*b).normalized();
    }
    double radius = 0.5 * o.dot_diameter_mm;
    if (!(radius > 0)) {
      // The dots' size from their image areas against a unit disc's.
      std::vector<double> r;
      for (const auto& [ij, n] : normals) {
        const TriangulatedPoint& p = pts[ij];
        const std::vector<Observation>& ob = obs[ij];
        for (std::size_t k = 0; k < ob.size(); ++k) {
          const double a1 = disc_image_area(rig.cameras[ob[k].camera], p.X, n, 1.0);
          if (a1 > 0 && areas[ij][k] > 0) r.push_back(std::sqrt(areas[ij][k] / a1));
        }
      }
      radius = median(r);
    }
    if (radius > 0) {
      res.dot_diameter_mm = 2 * radius;
      for (auto& [ij, p] : pts) {
        auto nit = normals.find(ij);
        if (!p.ok || nit == normals.end()) continue;
        std::vector<Observation> corrected = obs[ij];
        for (Observation& ob : corrected) {
          const Vec2 off = disc_centroid_offset(rig.cameras[ob.camera], p.X, nit->second, radius);
          res.max_bias_px = std::max(res.max_bias_px, off.norm());
          ob.pixel -= off;
        }
        p = triangulate(rig, corrected, o.triangulation);
      }
    }
  }

  // 6. Results, ordered by (j, i).
  std::vector<std::pair<std::pair<int, int>, const TriangulatedPoint*>> sorted;
  for (const auto& [ij, p] : pts) sorted.push_back({ij, &p});
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
    return std::make_pair(a.first.second, a.first.first) < std::make_pair(b.first.second, b.first.first);
  });
  double ss = 0;
  for (const auto& [ij, p] : sorted) {
    if (!p->ok) {
      res.failed.push_back({Label(ij.first, ij.second), p->why});
      continue;
    }
    res.marks.push_back({Label(ij.first, ij.second), p->X, p->rms_px, static_cast<int>(p->used.size())});
    ss += p->rms_px * p->rms_px;
    res.max_rms_px = std::max(res.max_rms_px, p->rms_px);
  }
  if (!res.marks.empty()) res.rms_px = std::sqrt(ss / res.marks.size());
  if (res.marks.size() < 4)
    throw InputError(
        fmt::format("{}: too few marks triangulated ({}; need 4): the views share too few labelled "
                    "marks",
                    images[0].name, res.marks.size()));
  res.seconds = since(t0);
  return res;
}

nlohmann::json SetResult::to_json() const {
  nlohmann::json j;
  j["marks"] = marks.size();
  j["mark_kind"] = kind == MarkKind::kDots ? "dots" : "lines";
  j["reference_mark"] = has_reference;
  j["rms_reprojection_px"] = rms_px;
  j["max_reprojection_px"] = max_rms_px;
  j["perspective_bias"] = {{"dot_diameter_mm", dot_diameter_mm}, {"max_correction_px", max_bias_px}};
  j["seconds"] = seconds;
  nlohmann::json vs = nlohmann::json::array();
  for (const ViewReport& v : views) {
    nlohmann::json vj;
    vj["image"] = v.name;
    vj["candidates"] = v.n_candidates;
    vj["labelled"] = v.n_labelled;
    vj["used"] = v.n_used;
    vj["reference_mark"] = v.has_reference;
    if (v.has_reference) vj["reference_pixel"] = px(v.reference_pixel);
    vj["labels_to_camera0"] = {{"symmetry", v.transform.symmetry},
                               {"offset", {v.transform.offset.x(), v.transform.offset.y()}}};
    vj["epipolar_votes"] = {{"best", v.n_consistent}, {"runner_up", v.n_runner_up}};
    if (!v.dropped.empty()) vj["dropped"] = v.dropped;
    vj["thresholds"] = v.thresholds;
    vj["seconds"] = v.seconds;
    nlohmann::json rj = nlohmann::json::array();
    for (const Rejection& r : v.rejected) rj.push_back({{"pixel", px(r.where)}, {"reason", r.reason}});
    vj["rejected"] = rj;
    vs.push_back(vj);
  }
  j["views"] = vs;
  nlohmann::json fj = nlohmann::json::array();
  for (const Failure& f : failed) fj.push_back({{"i", f.ij.x()}, {"j", f.ij.y()}, {"reason", f.why}});
  j["not_triangulated"] = fj;
  return j;
}

// ---------------------------------------------------------------------------------------
// Grid files

Eigen::Isometry3d grid_frame(const SetResult& set, const Vec3& toward) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (set.marks.size() < 3) return T;
  Vec3 centroid = Vec3::Zero();
  for (const DigitisedMark& m : set.marks) centroid += m.X;
  centroid /= static_cast<double>(set.marks.size());
  Mat3 cov = Mat3::Zero();
  for (const DigitisedMark& m : set.marks) cov += (m.X - centroid) * (m.X - centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  Vec3 z = es.eigenvectors().col(0);
  if (z.dot(toward - centroid) < 0) z = -z;
  // +i: the mean step between marks (i, j) and (i + 1, j).
  std::unordered_map<std::int64_t, Vec3> at;
  for (const DigitisedMark& m : set.marks) at[key(m.ij)] = m.X;
  Vec3 di = Vec3::Zero();
  for (const DigitisedMark& m : set.marks) {
    auto it = at.find(key(m.ij + Label(1, 0)));
    if (it != at.end()) di += it->second - m.X;
  }
  Vec3 x = di - di.dot(z) * z;
  if (x.norm() < 1e-12) x = es.eigenvectors().col(2);
  x.normalize();
  const Vec3 y = z.cross(x);
  auto origin_it = at.find(key(Label(0, 0)));
  const Vec3 origin = origin_it != at.end() ? origin_it->second : centroid;
  Mat3 Rw;  // rows: the frame's axes in rig coordinates
  Rw.row(0) = x.transpose();
  Rw.row(1) = y.transpose();
  Rw.row(2) = z.transpose();
  T.linear() = Rw;
  T.translation() = -Rw * origin;
  return T;
}

std::vector<GridRow> join_sets(const SetResult* und, const Eigen::Isometry3d& Tu, const SetResult& def,
                               const Eigen::Isometry3d& Td, double pitch) {
  std::map<std::pair<int, int>, GridRow> rows;
  auto row = [&](const Label& l) -> GridRow& {
    GridRow& r = rows[{l.y(), l.x()}];
    r.ij = l;
    return r;
  };
  if (und) {
    for (const DigitisedMark& m : und->marks) {
      GridRow& r = row(m.ij);
      r.undeformed = Tu * m.X;
      r.views_undeformed = m.n_views;
      r.rms_undeformed = m.rms_px;
    }
  }
  for (const DigitisedMark& m : def.marks) {
    GridRow& r = row(m.ij);
    r.deformed = Td * m.X;
    r.views_deformed = m.n_views;
    r.rms_deformed = m.rms_px;
    if (!und && pitch > 0) r.undeformed = Vec3(m.ij.x() * pitch, -m.ij.y() * pitch, 0.0);
  }
  std::vector<GridRow> out;
  for (auto& [k, r] : rows) out.push_back(r);
  return out;
}

std::string mark_id(long i, long j) { return fmt::format("i{}_j{}", i, j); }

GridData grid_data(const std::vector<GridRow>& rows) {
  GridData g;
  const Index n = static_cast<Index>(rows.size());
  g.undeformed.resize(n, 3);
  g.deformed.resize(n, 3);
  g.has_ij = true;
  g.sources = {"gsa digitise"};
  for (Index k = 0; k < n; ++k) {
    const GridRow& r = rows[k];
    g.ids.push_back(mark_id(r.ij.x(), r.ij.y()));
    g.undeformed.row(k) = r.undeformed.transpose();
    g.deformed.row(k) = r.deformed.transpose();
    g.i.push_back(r.ij.x());
    g.j.push_back(r.ij.y());
    g.where.push_back("mark " + g.ids.back());
  }
  return g;
}

void write_grid(std::ostream& out, const std::vector<GridRow>& rows, const std::vector<std::string>& comments,
                const std::string& units) {
  io::GridWriteOptions o;
  o.comments = comments;
  o.units = units;
  o.with_ij = true;
  o.extra_columns = {"views_undeformed", "reproj_undeformed_px", "views_deformed", "reproj_deformed_px"};
  io::GridFileWriter w(out, o);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  auto round_um = [](const Vec3& v) { return Vec3(((v * 1e5).array().round() / 1e5).matrix()); };  // 0.01 um; NaN stays
  auto round_px = [](double v) { return std::round(v * 1e4) / 1e4; };
  for (const GridRow& r : rows) {
    const bool u = r.views_undeformed > 0, d = r.views_deformed > 0;  // 0: not measured (empty cells)
    w.add(mark_id(r.ij.x(), r.ij.y()), round_um(r.undeformed), round_um(r.deformed), r.ij.x(), r.ij.y(),
          {u ? r.views_undeformed : kNaN, u ? round_px(r.rms_undeformed) : kNaN, d ? r.views_deformed : kNaN,
           d ? round_px(r.rms_deformed) : kNaN});
  }
}

}  // namespace sf::gsa::digitise

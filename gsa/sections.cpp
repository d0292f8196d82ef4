#include "gsa/sections.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/fe/surface_field.hpp"
#include "common/io/csv.hpp"
#include "common/mesh/projection.hpp"
#include "gsa/measured_region.hpp"

namespace sf::gsa {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string trim(const std::string& t) {
  const auto a = t.find_first_not_of(" \t"), b = t.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : t.substr(a, b - a + 1);
}

std::vector<double> numbers(const std::string& text, const std::string& option, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    const std::string c = trim(cell);
    std::size_t used = 0;
    double x = kNaN;
    try {
      x = std::stod(c, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (c.empty() || used != c.size() || !std::isfinite(x))
      throw UsageError(option + ": '" + c + "' in " + what + " is not a finite number");
    v.push_back(x);
  }
  return v;
}

// A point of a section with everything sampled there.
struct Location {
  Index element = -1;
  Vec2 xi = Vec2::Zero();
};

std::size_t cell_index(Index e, const Vec2& xi, int ns) {
  const int i = std::clamp(static_cast<int>(xi[0] * ns), 0, ns - 1);
  const int j = std::clamp(static_cast<int>(xi[1] * ns), 0, ns - 1);
  return static_cast<std::size_t>((e * ns + j) * ns + i);
}

// Plane cut: branches of locations.
std::vector<std::vector<Location>> plane_branches(const AnalysisResult& r, const SectionSpec& spec, int ns,
                                                  const std::vector<bool>& measured, double& dmin, double& dmax) {
  const fe::SurfaceField fd(r.mesh, r.deformed_parameters);
  const Vec3 n = spec.normal.normalized();
  auto dist = [&](Index e, const Vec2& xi) { return (fd.evaluate3(e, xi, basis::kValues).x - spec.point).dot(n); };
  struct Node {
    Location at;
    Vec3 x;
  };
  std::vector<Node> nodes;
  std::vector<std::pair<int, int>> segments;
  // Merge equal points (the same crossing seen from two cells, or two elements).
  double size = 0;
  {
    const fe::SurfaceField f(r.mesh, r.deformed_parameters);
    Vec3 lo = Vec3::Constant(HUGE_VAL), hi = -lo;
    for (Index e = 0; e < r.mesh.n_elements(); ++e)
      for (const Vec2& xi : {Vec2(0, 0), Vec2(1, 1)}) {
        const Vec3 x = f.evaluate3(e, xi, basis::kValues).x;
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
      }
    size = (hi - lo).norm();
  }
  const double tol = 1e-7 * std::max(size, 1e-300);
  std::unordered_map<long long, std::vector<int>> grid;
  auto key = [&](long long a, long long b, long long c) {
    return (a * 73856093LL) ^ (b * 19349663LL) ^ (c * 83492791LL);
  };
  auto node_of = [&](const Location& at, const Vec3& x) {
    const long long a = std::llround(x[0] / tol), b = std::llround(x[1] / tol), c = std::llround(x[2] / tol);
    for (long long da = -1; da <= 1; ++da)
      for (long long db = -1; db <= 1; ++db)
        for (long long dc = -1; dc <= 1; ++dc) {
          const auto it = grid.find(key(a + da, b + db, c + dc));
          if (it == grid.end()) continue;
          for (int id : it->second)
            if ((nodes[static_cast<std::size_t>(id)].x - x).norm() <= 2 * tol) return id;
        }
    nodes.push_back({at, x});
    grid[key(a, b, c)].push_back(static_cast<int>(nodes.size() - 1));
    return static_cast<int>(nodes.size() - 1);
  };
  dmin = HUGE_VAL;
  dmax = -HUGE_VAL;
  const int np = ns + 1;
  std::vector<double> d(static_cast<std::size_t>(np * np));
  for (Index e = 0; e < r.mesh.n_elements(); ++e) {
    auto xi_of = [&](int i, int j) { return Vec2(static_cast<double>(i) / ns, static_cast<double>(j) / ns); };
    for (int j = 0; j < np; ++j)
      for (int i = 0; i < np; ++i) d[static_cast<std::size_t>(j * np + i)] = dist(e, xi_of(i, j));
    for (int j = 0; j < ns; ++j)
      for (int i = 0; i < ns; ++i) {
        if (!measured[static_cast<std::size_t>((e * ns + j) * ns + i)]) continue;
        const int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
        for (int c = 0; c < 4; ++c) {
          const double v = d[static_cast<std::size_t>(cj[c] * np + ci[c])];
          dmin = std::min(dmin, v);
          dmax = std::max(dmax, v);
        }
        std::vector<int> crossing;
        for (int c = 0; c < 4; ++c) {
          // Canonical edge direction (lower corner first): both cells of an edge agree exactly.
          int a = c, b = (c + 1) % 4;
          if (std::make_pair(cj[b], ci[b]) < std::make_pair(cj[a], ci[a])) std::swap(a, b);
          double da = d[static_cast<std::size_t>(cj[a] * np + ci[a])],
                 db = d[static_cast<std::size_t>(cj[b] * np + ci[b])];
          if ((da >= 0) == (db >= 0)) continue;
          Vec2 xa = xi_of(ci[a], cj[a]), xb = xi_of(ci[b], cj[b]);
          Vec2 xi = xa;
          for (int it = 0; it < 40; ++it) {  // regula falsi (Illinois) along the edge
            xi = xa + (da / (da - db)) * (xb - xa);
            const double dx = dist(e, xi);
            if (std::abs(dx) <= 1e-12 * std::max(size, 1.0) || (xb - xa).norm() < 1e-13) break;
            if ((dx >= 0) == (da >= 0)) {
              xa = xi;
              da = dx;
              db *= 0.5;
            } else {
              xb = xi;
              db = dx;
              da *= 0.5;
            }
          }
          const Location at{e, xi};
          crossing.push_back(node_of(at, fd.evaluate3(e, xi, basis::kValues).x));
        }
        for (std::size_t k = 0; k + 1 < crossing.size(); k += 2)
          if (crossing[k] != crossing[k + 1]) segments.emplace_back(crossing[k], crossing[k + 1]);
      }
  }
  // Chain the segments into branches (open chains from their ends first, then loops).
  std::vector<std::vector<int>> adj(nodes.size());
  for (std::size_t s = 0; s < segments.size(); ++s) {
    adj[static_cast<std::size_t>(segments[s].first)].push_back(static_cast<int>(s));
    adj[static_cast<std::size_t>(segments[s].second)].push_back(static_cast<int>(s));
  }
  std::vector<bool> used(segments.size(), false);
  std::vector<std::vector<int>> chains;
  auto walk = [&](int start) {
    std::vector<int> chain = {start};
    int cur = start;
    for (;;) {
      int next_seg = -1;
      for (int s : adj[static_cast<std::size_t>(cur)])
        if (!used[static_cast<std::size_t>(s)]) {
          next_seg = s;
          break;
        }
      if (next_seg < 0) break;
      used[static_cast<std::size_t>(next_seg)] = true;
      const auto& sg = segments[static_cast<std::size_t>(next_seg)];
      cur = sg.first == cur ? sg.second : sg.first;
      chain.push_back(cur);
    }
    if (chain.size() >= 2) chains.push_back(std::move(chain));
  };
  for (std::size_t v = 0; v < nodes.size(); ++v)
    if (adj[v].size() == 1) walk(static_cast<int>(v));
  for (std::size_t v = 0; v < nodes.size(); ++v)
    while (std::any_of(adj[v].begin(), adj[v].end(), [&](int s) { return !used[static_cast<std::size_t>(s)]; }))
      walk(static_cast<int>(v));
  std::vector<std::vector<Location>> out;
  for (const auto& c : chains) {
    std::vector<Location> b;
    for (int id : c) b.push_back(nodes[static_cast<std::size_t>(id)].at);
    out.push_back(std::move(b));
  }
  return out;
}

std::vector<std::vector<Location>> curve_branches(const AnalysisResult& r, const SectionSpec& spec, int ns,
                                                  const std::vector<bool>& measured) {
  const mesh::SurfaceProjector proj(r.mesh, r.undeformed_parameters);
  const double spacing = r.mark_spacing > 0 ? r.mark_spacing : 1.0;
  const double step = spacing / 8.0;
  std::vector<Vec3> pts = spec.curve;
  for (Vec3& p : pts)
    if (!std::isfinite(p[2])) p[2] = r.centroid[2];
  std::vector<std::vector<Location>> out(1);
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    const Vec3 a = pts[k], b = pts[k + 1];
    const int m = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int q = (k == 0 ? 0 : 1); q <= m; ++q) {
      const Vec3 p = a + (b - a) * (static_cast<double>(q) / m);
      const mesh::Projection pr = proj.project(p);
      const bool on = pr.ok() && (pr.status == mesh::Projection::Status::kConverged || pr.distance < 0.25 * spacing) &&
                      measured[cell_index(pr.element, pr.xi, ns)];
      if (on)
        out.back().push_back({pr.element, pr.xi});
      else if (!out.back().empty())
        out.emplace_back();
    }
  }
  std::vector<std::vector<Location>> kept;
  for (auto& b : out)
    if (b.size() >= 2) kept.push_back(std::move(b));
  return kept;
}
}  // namespace

SectionSpec parse_section(const std::string& text_in, const std::string& option) {
  const std::string text = trim(text_in);
  const auto colon = text.find_first_of(":=");
  const std::string kind = colon == std::string::npos ? text : trim(text.substr(0, colon));
  const std::string rest = colon == std::string::npos ? std::string() : text.substr(colon + 1);
  SectionSpec s;
  s.text = text;
  const std::string expected =
      "expected plane:X,Y,Z,NX,NY,NZ (a point and a normal) or curve:X,Y[,Z];X,Y[,Z];... (points on the "
      "undeformed blank), found '" +
      text_in + "'";
  if (kind == "plane") {
    const std::vector<double> v = numbers(rest, option, "the plane");
    if (v.size() != 6)
      throw UsageError(option + ": a plane needs 6 numbers (point X,Y,Z and normal NX,NY,NZ), found " +
                       std::to_string(v.size()) + " in '" + text_in + "'");
    s.kind = SectionSpec::Kind::kPlane;
    s.point = Vec3(v[0], v[1], v[2]);
    s.normal = Vec3(v[3], v[4], v[5]);
    if (!(s.normal.norm() > 0)) throw UsageError(option + ": the plane's normal is zero in '" + text_in + "'");
    return s;
  }
  if (kind == "curve") {
    s.kind = SectionSpec::Kind::kCurve;
    std::stringstream ss(rest);
    std::string pt;
    while (std::getline(ss, pt, ';')) {
      if (trim(pt).empty()) continue;
      const std::vector<double> v = numbers(pt, option, "the curve's point '" + trim(pt) + "'");
      if (v.size() != 2 && v.size() != 3)
        throw UsageError(option + ": a curve point needs 2 (X,Y) or 3 (X,Y,Z) numbers, found " +
                         std::to_string(v.size()) + " in '" + trim(pt) + "'");
      s.curve.emplace_back(v[0], v[1], v.size() == 3 ? v[2] : kNaN);
    }
    if (s.curve.size() < 2)
      throw UsageError(option + ": a curve needs at least 2 points separated by ';', " + expected);
    return s;
  }
  throw UsageError(option + ": " + expected);
}

Section cut_section(const AnalysisResult& r, const SectionSpec& spec, const SectionOptions& o,
                    const std::string& option) {
  if (r.method != Method::kSurface) throw UsageError(option + ": sections need the surface method (fitted surfaces)");
  Section sec;
  sec.spec = spec;
  const int ns = std::max(2, o.subdiv);
  const std::vector<bool> measured = measured_cells(r, ns);
  std::vector<std::vector<Location>> branches;
  if (spec.kind == SectionSpec::Kind::kPlane) {
    double dmin = 0, dmax = 0;
    branches = plane_branches(r, spec, ns, measured, dmin, dmax);
    if (branches.empty()) {
      std::ostringstream m;
      m << option << ": the plane '" << spec.text << "' does not cut the measured part";
      if (std::isfinite(dmin)) m << " (the part lies " << dmin << " to " << dmax << " from it along its normal)";
      m << "; give a point on the formed part and a normal across it";
      throw UsageError(m.str());
    }
  } else {
    branches = curve_branches(r, spec, ns, measured);
    if (branches.empty())
      throw UsageError(option + ": the curve '" + spec.text +
                       "' does not cross the measured blank (its points are off the undeformed surface where the "
                       "marks are)");
  }
  const fe::SurfaceField fu(r.mesh, r.undeformed_parameters), fd(r.mesh, r.deformed_parameters);
  const unsigned all = basis::kValues | basis::kFirst | basis::kSecond;
  std::vector<std::vector<SectionPoint>> sampled;
  for (const auto& b : branches) {
    std::vector<SectionPoint> pts;
    for (const Location& at : b) {
      const fe::SurfacePoint pu = fu.evaluate3(at.element, at.xi, all), pd = fd.evaluate3(at.element, at.xi, all);
      SectionPoint p;
      p.element = at.element;
      p.xi = at.xi;
      p.X = pu.x;
      p.x = pd.x;
      const auto s = surface_strain(pu.dx, pd.dx);
      p.major = s ? principal_strain(*s, 0, o.measure) : kNaN;
      p.minor = s ? principal_strain(*s, 1, o.measure) : kNaN;
      p.thickness_change_pct = s ? s->thickness_change_pct() : kNaN;
      p.thickness_strain = s ? strain_of_stretch(s->thickness_stretch(), o.measure) : kNaN;
      if (o.mid.enabled()) {
        const auto m = mid_surface_strain(pu, pd, o.mid);
        if (m) {
          p.mid_major = principal_strain(m->strain, 0, o.measure);
          p.mid_minor = principal_strain(m->strain, 1, o.measure);
          p.thickness = m->thickness;
          p.thickness_strain = strain_of_stretch(m->thickness / o.mid.thickness, o.measure);
        }
      }
      pts.push_back(p);
    }
    // A fixed direction: along the branch's longest extent on the formed part, increasing.
    Vec3 lo = Vec3::Constant(HUGE_VAL), hi = -lo;
    for (const auto& p : pts) lo = lo.cwiseMin(p.x), hi = hi.cwiseMax(p.x);
    Index axis = 0;
    (hi - lo).maxCoeff(&axis);
    if (spec.kind == SectionSpec::Kind::kPlane && pts.front().x[axis] > pts.back().x[axis])
      std::reverse(pts.begin(), pts.end());
    for (std::size_t i = 1; i < pts.size(); ++i) {
      pts[i].s_undeformed = pts[i - 1].s_undeformed + (pts[i].X - pts[i - 1].X).norm();
      pts[i].s_deformed = pts[i - 1].s_deformed + (pts[i].x - pts[i - 1].x).norm();
    }
    sampled.push_back(std::move(pts));
  }
  std::stable_sort(sampled.begin(), sampled.end(),
                   [](const auto& a, const auto& b) { return a.back().s_deformed > b.back().s_deformed; });
  sec.n_branches = static_cast<int>(sampled.size());
  for (std::size_t b = 0; b < sampled.size(); ++b)
    for (SectionPoint& p : sampled[b]) {
      p.branch = static_cast<int>(b);
      sec.points.push_back(p);
    }
  if (o.neck) {
    std::vector<double> s, e1, e2;
    for (const SectionPoint& p : sampled.front()) {
      s.push_back(p.s_undeformed);
      e1.push_back(o.mid.enabled() ? p.mid_major : p.major);
      e2.push_back(o.mid.enabled() ? p.mid_minor : p.minor);
    }
    sec.neck = evaluate_neck(s, e1, e2);
  }
  return sec;
}

void write_section_csv(const std::string& path, const Section& sec, const SectionOptions& o, const std::string& units) {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot write");
  out << "# gsa section " << sec.name << ": " << sec.spec.text << "; " << sec.n_branches << " branch"
      << (sec.n_branches == 1 ? "" : "es") << " (branch 0 the longest)\n";
  out << "# lengths and arc lengths (s_undeformed along the blank, s_deformed along the formed part) in " << units
      << "; strains " << measure_name(o.measure)
      << "; major/minor on the marked face; thickness_change_pct incompressible from the face strains";
  if (o.mid.enabled())
    out << "; mid_major/mid_minor at the mid-surface (initial thickness " << o.mid.thickness << " " << units
        << ", grid on the " << (o.mid.face == GridFace::kTop ? "top" : "bottom") << " face), thickness_" << units
        << " the current thickness (" << units << ")";
  out << "; thickness_strain = strain of the thickness stretch h/h0\n";
  if (sec.neck) {
    const NeckResult& n = *sec.neck;
    if (n.ok)
      out << "# neck (ISO 12004-2 style, branch 0, " << (o.mid.enabled() ? "mid-surface" : "surface")
          << " strains vs s_undeformed): limit major " << n.limit_major << ", limit minor " << n.limit_minor
          << " at s = " << n.apex_position << "; peak measured " << n.peak_major << " at s = " << n.peak_position
          << "; fit windows " << n.outer_left << ".." << n.inner_left << " and " << n.inner_right << ".."
          << n.outer_right << " (" << n.fit_points << " points, RMS misfit " << n.fit_rms << ")\n";
    else
      out << "# neck: not evaluated: " << n.message << "\n";
  }
  std::vector<std::string> cols = {"branch",
                                   "s_undeformed",
                                   "s_deformed",
                                   "X",
                                   "Y",
                                   "Z",
                                   "x",
                                   "y",
                                   "z",
                                   "element",
                                   "xi1",
                                   "xi2",
                                   "major",
                                   "minor",
                                   "thickness_change_pct",
                                   "thickness_strain"};
  if (o.mid.enabled())
    for (const std::string& c : {std::string("mid_major"), std::string("mid_minor"), "thickness_" + units})
      cols.push_back(c);
  io::CsvWriter cw(out, cols);
  for (const SectionPoint& p : sec.points) {
    cw.begin_row().add(p.branch).add(p.s_undeformed).add(p.s_deformed);
    for (int c = 0; c < 3; ++c) cw.add(p.X[c]);
    for (int c = 0; c < 3; ++c) cw.add(p.x[c]);
    cw.add(p.element)
        .add(p.xi[0])
        .add(p.xi[1])
        .add(p.major)
        .add(p.minor)
        .add(p.thickness_change_pct)
        .add(p.thickness_strain);
    if (o.mid.enabled()) cw.add(p.mid_major).add(p.mid_minor).add(p.thickness);
    cw.end_row();
  }
  if (!out) throw Error(path + ": write failed");
}

}  // namespace sf::gsa

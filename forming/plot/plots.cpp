#include "forming/plot/plots.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"
#include "common/io/vtk_xml.hpp"
#include "common/io/xml_escape.hpp"
#include "common/render/chart.hpp"
#include "common/render/colour.hpp"
#include "common/render/display.hpp"
#include "forming/plot/animation.hpp"

namespace sf::forming {
namespace {

namespace fs = std::filesystem;

struct DataSet {
  double time = 0.0;
  int part = 0;
  std::string file;
};

std::vector<DataSet> read_pvd(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open file (expected the result.pvd of a simform run)");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  static const std::regex re(R"re(<DataSet\s+timestep="([^"]*)"[^>]*part="(\d+)"[^>]*file="([^"]*)")re");
  std::vector<DataSet> out;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back({std::stod((*it)[1].str()), std::stoi((*it)[2].str()), (*it)[3].str()});
  if (out.empty()) throw InputError(path.string() + ": no DataSet entries (expected the result.pvd of a simform run)");
  return out;
}

const io::FieldArray* find_field(const std::vector<io::FieldArray>& fields, const std::string& name) {
  for (const io::FieldArray& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

// The cells of a ply frame grouped per body, with the layout of frames.cpp: per brick
// ns x ns x nt cells, k (thickness) outermost, then j, then i.
struct PlyFrame {
  io::VolumeMesh mesh;
  int ns = 4, nt = 2;
  std::vector<std::vector<std::size_t>> cells;  // per body, in file order
  const io::FieldArray& cell(const std::string& name, const std::string& file) const {
    const io::FieldArray* f = find_field(mesh.cell_data, name);
    if (!f) throw InputError(file + ": no cell data '" + name + "' (written by an older simform?)");
    return *f;
  }
  const io::FieldArray* point(const std::string& name) const { return find_field(mesh.point_data, name); }
  Vec3 at(Index p) const { return mesh.points.row(p).transpose(); }
  // Local (k, j, i) of the n-th cell of a body.
  std::array<int, 3> kji(std::size_t n) const {
    const int q = static_cast<int>(n % static_cast<std::size_t>(ns * ns * nt));
    return {q / (ns * ns), (q / ns) % ns, q % ns};
  }
};

PlyFrame read_frame(const fs::path& path, int ns, int nt) {
  PlyFrame f;
  f.mesh = io::read_vtu(path.string());
  f.ns = ns;
  f.nt = nt;
  const io::FieldArray* ply = find_field(f.mesh.cell_data, "ply");
  if (!ply) throw InputError(path.string() + ": no cell data 'ply' (expected a simform frame)");
  for (std::size_t c = 0; c < f.mesh.n_cells(); ++c) {
    const std::size_t b = static_cast<std::size_t>(ply->values[c]);
    if (f.cells.size() <= b) f.cells.resize(b + 1);
    f.cells[b].push_back(c);
  }
  return f;
}

// Quads of the top faces of a body (cell index, its top points, the points of the bottom
// face below them).
struct Face {
  std::size_t cell;
  std::array<Index, 4> top, bottom;
};
std::vector<Face> top_faces(const PlyFrame& f, int body) {
  std::vector<Face> out;
  const auto& cells = f.cells[static_cast<std::size_t>(body)];
  const std::size_t layer = static_cast<std::size_t>(f.ns * f.ns);
  for (std::size_t n = 0; n < cells.size(); ++n) {
    if (f.kji(n)[0] != f.nt - 1) continue;
    const std::size_t c = cells[n], cb = cells[n - static_cast<std::size_t>(f.nt - 1) * layer];
    const Index* t = &f.mesh.connectivity[static_cast<std::size_t>(f.mesh.offsets[c])];
    const Index* b = &f.mesh.connectivity[static_cast<std::size_t>(f.mesh.offsets[cb])];
    out.push_back({c, {t[4], t[5], t[6], t[7]}, {b[0], b[1], b[2], b[3]}});
  }
  return out;
}

struct Box {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Vec3 size() const { return hi - lo; }
};

struct Tool {
  std::string name;
  io::VolumeMesh mesh;
};

// The tools of the frame `step_file` (same step number), from the collection.
std::vector<Tool> read_tools(const fs::path& dir, const std::vector<DataSet>& sets, const std::string& step_file) {
  std::vector<Tool> out;
  const std::string number = step_file.size() >= 8 ? step_file.substr(step_file.size() - 8) : "";  // NNNN.vtu
  for (const DataSet& d : sets) {
    const std::string name = fs::path(d.file).filename().string();
    if (d.part == 0 || name.rfind("tool_", 0) != 0 || name.size() < 8 || name.substr(name.size() - 8) != number)
      continue;
    out.push_back({name.substr(5, name.size() - 5 - 9), io::read_vtu((dir / d.file).string())});
  }
  return out;
}

const render::Colour kToolSolid{0.62, 0.70, 0.80};
const render::Colour kToolLine{0.10, 0.20, 0.55};

// The tool's triangles near the plies: centroid within the plies' plan box enlarged by
// 15 % of its size and within 30 % of that size above or below them.
std::vector<std::size_t> tool_cells_near(const Tool& t, const Vec3& lo, const Vec3& hi) {
  const double l = (hi - lo).head<2>().norm();
  const Vec3 pad(0.15 * l, 0.15 * l, 0.2 * l);
  std::vector<std::size_t> out;
  for (std::size_t c = 0; c < t.mesh.n_cells(); ++c) {
    Vec3 m = Vec3::Zero();
    const Index a = t.mesh.offsets[c], b = t.mesh.offsets[c + 1];
    for (Index i = a; i < b; ++i) m += t.mesh.points.row(t.mesh.connectivity[static_cast<std::size_t>(i)]).transpose();
    m /= static_cast<double>(std::max<Index>(1, b - a));
    if (((m - lo).array() >= -pad.array()).all() && ((hi - m).array() >= -pad.array()).all()) out.push_back(c);
  }
  return out;
}

// Where the polygons `cells` of m (a tool's triangles) cross the plane through c with
// normal n: one segment per polygon that the plane cuts in two points.
std::vector<std::array<Vec3, 2>> plane_cuts(const io::VolumeMesh& m, const std::vector<std::size_t>& cells,
                                            const Vec3& c, const Vec3& n) {
  std::vector<std::array<Vec3, 2>> out;
  for (const std::size_t cell : cells) {
    const Index a = m.offsets[cell], e = m.offsets[cell + 1];
    std::vector<Vec3> cut;
    for (Index i = a; i < e; ++i) {
      const Vec3 p = m.points.row(m.connectivity[static_cast<std::size_t>(i)]).transpose();
      const Vec3 q = m.points.row(m.connectivity[static_cast<std::size_t>(i + 1 < e ? i + 1 : a)]).transpose();
      const double dp = (p - c).dot(n), dq = (q - c).dot(n);
      if ((dp < 0.0) != (dq < 0.0)) cut.push_back(p + (dp / (dp - dq)) * (q - p));
    }
    if (cut.size() == 2) out.push_back({cut[0], cut[1]});
  }
  return out;
}

// Tools below the plies' mean level as solid surfaces, the others as wireframes; only
// their part near the plies (lo, hi: the plies' box).
void add_tools(render::Scene& scene, const std::vector<Tool>& tools, double ply_level, double width, const Vec3& lo,
               const Vec3& hi) {
  for (const Tool& t : tools) {
    const std::vector<std::size_t> near = tool_cells_near(t, lo, hi);
    if (near.empty()) continue;
    double z = 0.0;
    for (Index p = 0; p < t.mesh.points.rows(); ++p) z += t.mesh.points(p, 2);
    z /= std::max<Index>(1, t.mesh.points.rows());
    if (z < ply_level) {
      render::Surface& s = scene.surfaces.emplace_back();
      s.points = t.mesh.points;
      for (std::size_t c : near) {
        std::vector<Index> poly(t.mesh.connectivity.begin() + t.mesh.offsets[c],
                                t.mesh.connectivity.begin() + t.mesh.offsets[c + 1]);
        s.polygons.push_back(poly);
      }
      s.colour = kToolSolid;
      s.outline = true;
    } else {
      render::GlyphSet g;
      g.kind = render::GlyphSet::Kind::kSegment;
      g.colour = kToolLine;
      g.width = width;
      std::set<std::pair<Index, Index>> edges;
      for (std::size_t c : near) {
        const Index a = t.mesh.offsets[c], b = t.mesh.offsets[c + 1];
        for (Index i = a; i < b; ++i) {
          Index p = t.mesh.connectivity[static_cast<std::size_t>(i)];
          Index q = t.mesh.connectivity[static_cast<std::size_t>(i + 1 < b ? i + 1 : a)];
          if (p > q) std::swap(p, q);
          if (!edges.insert({p, q}).second) continue;
          g.tails.push_back(t.mesh.points.row(p).transpose());
          g.heads.push_back(t.mesh.points.row(q).transpose());
        }
      }
      scene.glyphs.push_back(std::move(g));
    }
    scene.legend.push_back({z < ply_level ? render::LegendEntry::Kind::kSwatch : render::LegendEntry::Kind::kLine,
                            z < ply_level ? kToolSolid : kToolLine, "tool '" + t.name + "'"});
  }
}

// The edges of the quads used once (points compared by position, the quads have their
// own copies): the plies' outlines, as 2-point polylines.
std::vector<std::vector<Index>> outline_lines(const std::vector<Vec3>& pts,
                                              const std::vector<std::vector<Index>>& polys, double scale) {
  const double q = 1e-6 * std::max(scale, 1e-12);
  const auto key = [&](Index i) {
    const Vec3& p = pts[static_cast<std::size_t>(i)];
    return std::array<long long, 3>{std::llround(p[0] / q), std::llround(p[1] / q), std::llround(p[2] / q)};
  };
  std::map<std::pair<std::array<long long, 3>, std::array<long long, 3>>, std::pair<int, std::pair<Index, Index>>>
      count;
  for (const auto& poly : polys)
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const Index a = poly[k], b = poly[(k + 1) % poly.size()];
      auto ka = key(a), kb = key(b);
      if (kb < ka) std::swap(ka, kb);
      auto& e = count[{ka, kb}];
      ++e.first;
      e.second = {a, b};
    }
  std::vector<std::vector<Index>> out;
  for (const auto& [k, e] : count)
    if (e.first == 1) out.push_back({e.second.first, e.second.second});
  return out;
}

std::string fmt(double v, const char* f = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// A per-ply field on the plies' top faces, the plies side by side in plan (bottom ply
// first), `value(face)` per face (NaN: grey) or per point (`point_value`).
struct FieldPicture {
  std::string file, title, units, caption;
  bool symmetric = false;
  double min_span = 0.0;  // the colour range spans at least this (round-off is not a pattern)
};

class Plotter {
 public:
  Plotter(const fs::path& dir, const PlotOptions& options) : dir_(dir), options_(options) {
    if (!fs::is_directory(dir)) throw InputError(dir.string() + ": not a folder (expected a simform results folder)");
    const fs::path summary = dir / "summary.json";
    if (!fs::exists(summary))
      throw InputError(summary.string() + ": cannot open file (expected the summary.json of a simform run)");
    summary_ = io::read_json(summary.string());
    const nlohmann::json& out = summary_["parameters"]["output"]["samples"];
    if (out.is_array() && out.size() == 2) {
      ns_ = out[0].get<int>();
      nt_ = out[1].get<int>();
    }
    for (const auto& p : summary_["parameters"]["plies"]) {
      names_.push_back(p.value("name", std::string("ply")));
      plane_strain_ = plane_strain_ || p.value("plane_strain", false);
      angles_.push_back(p.value("angle", 0.0));
    }
    sets_ = read_pvd(dir / "result.pvd");
    for (const DataSet& d : sets_)
      if (d.part == 0) frames_.push_back(d);
    std::stable_sort(frames_.begin(), frames_.end(),
                     [](const DataSet& a, const DataSet& b) { return a.time < b.time; });
    last_ = read_frame(dir / frames_.back().file, ns_, nt_);
    tools_ = read_tools(dir, sets_, frames_.back().file);
    for (std::size_t b = 0; b < last_.cells.size(); ++b)
      for (const Face& f : top_faces(last_, static_cast<int>(b)))
        for (Index p : f.top) box_.add(last_.at(p));
    fs::create_directories(dir / "plots");
  }

  PlotReport run() {
    PlotReport report;
    lap("read results");
    const auto guard = render::acquire_display();
    lap("display");
    shape(report);
    if (plane_strain_)
      section(report);
    else
      section_3d(report);
    field(report,
          {"fibre_stress.png", "Fibre stress", "MPa",
           "Cauchy stress along the fibres (a . sigma . a) on each ply's top face, plies side by side "
           "(bottom ply on the left).",
           true, 0.01},
          [&](const Face& f) { return fibre_stress(f.cell); });
    const io::FieldArray* trellis = find_field(last_.mesh.cell_data, "trellis_shear_angle");
    bool any_trellis = false;
    if (trellis)
      for (double v : trellis->values) any_trellis = any_trellis || std::isfinite(v);
    field(report,
          {"shear_angle.png", any_trellis ? "Trellis shear angle" : "In-ply shear angle", "deg",
           any_trellis ? "Trellis shear angle between the fibres of each ply and its partner ply (the nearest ply "
                         "with other fibre directions); grey where a ply has no partner."
                       : "Shear angle between each ply's fibres and the material line across them (no ply has a "
                         "partner with other fibre directions).",
           true, 1.0},
          [&](const Face& f) {
            const double t = trellis ? trellis->values[f.cell] : std::nan("");
            return any_trellis ? t : last_.cell("ply_shear_angle", frame_name()).values[f.cell];
          });
    field(report,
          {"thickness.png", "Ply thickness", "mm",
           "Ply thickness measured along the deformed normal (reference thickness in the summary).", false, 0.01},
          [&](const Face& f) { return last_.cell("thickness", frame_name()).values[f.cell]; });
    if (const io::FieldArray* p = last_.point("contact_pressure")) {
      field_points(report,
                   {"contact_pressure.png", "Contact pressure", "MPa",
                    "Contact pressure on each ply's faces (the larger of top and bottom face), from the tools and "
                    "the neighbouring plies.",
                    false, 0.01},
                   *p);
    }
    fibres(report);
    force_chart(report);
    if (options_.frames > 0) sequence(report);
    write_report(report);
    lap("report.html");
    if (std::getenv("SF_PLOT_TIMING")) {
      // Where the time goes (wall and process CPU s per piece), on stderr.
      double wall = 0.0, cpu = 0.0;
      for (const Lap& l : laps_) {
        std::fprintf(stderr, "simform plot: %-28s wall %6.3f s  cpu %6.3f s\n", l.what.c_str(), l.wall, l.cpu);
        wall += l.wall;
        cpu += l.cpu;
      }
      std::fprintf(stderr, "simform plot: %-28s wall %6.3f s  cpu %6.3f s\n", "total (listed)", wall, cpu);
    }
    return report;
  }

 private:
  std::string frame_name() const { return (dir_ / frames_.back().file).string(); }

  double fibre_stress(std::size_t c) const {
    const auto& s = last_.cell("cauchy_stress", frame_name()).values;
    const auto& a = last_.cell("fibre_direction", frame_name()).values;
    const double* v = &s[6 * c];
    Mat3 S;
    S << v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2];
    const Vec3 f(a[3 * c], a[3 * c + 1], a[3 * c + 2]);
    return f.dot(S * f);
  }

  int n_bodies() const { return static_cast<int>(last_.cells.size()); }
  std::string ply_label(int b) const {
    std::string s = static_cast<std::size_t>(b) < names_.size() ? names_[b] : std::to_string(b);
    if (static_cast<std::size_t>(b) < angles_.size()) s += " (" + fmt(angles_[b], "%g") + "\u00b0)";
    return s;
  }

  // Offset of body b in the side-by-side plan layout.
  Vec3 offset(int b) const {
    const int n = n_bodies();
    const int cols = n <= 4 ? n : static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
    const Vec3 s = box_.size();
    const double gx = s[0] * 1.12, gy = s[1] * 1.25;
    return Vec3((b % cols) * gx, -(b / cols) * gy, 0.0);
  }

  std::string plies_subtitle() const {
    std::string s = "left to right: ";
    for (int b = 0; b < n_bodies(); ++b) s += (b ? ", " : "") + ply_label(b);
    return s;
  }

  std::string footnote() const {
    return "simform plot " + dir_.filename().string() + "; frame " + frames_.back().file + " (load factor " +
           fmt(frames_.back().time, "%.4g") + ")";
  }

  render::ScalarColouring colouring(const FieldPicture& p, std::vector<double> values) const {
    double lo = 1e300, hi = -1e300;
    for (double v : values)
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    if (lo > hi) lo = hi = 0.0;
    if (hi - lo < p.min_span) {
      if (p.symmetric) {  // about 0, the values included
        lo = std::min(lo, -0.5 * p.min_span);
        hi = std::max(hi, 0.5 * p.min_span);
      } else {
        const double m = 0.5 * (lo + hi);
        lo = m - 0.5 * p.min_span;
        hi = m + 0.5 * p.min_span;
      }
    }
    render::ScalarColouring c;
    c.title = p.title;
    c.units = p.units;
    c.values = std::move(values);
    c.map = p.symmetric ? render::ColourMap::kDiverging : render::ColourMap::kViridis;
    c.bands = render::nice_bands(lo, hi, 10, p.symmetric);
    return c;
  }

  // A field on the plies' top faces, the plies side by side in plan; `corners(face)`
  // gives the values at the face's four top points. `smooth`: a continuous colour map
  // (point data) rather than bands with iso-lines.
  template <class Corners>
  void plan_field(PlotReport& report, const FieldPicture& p, Corners corners, bool smooth) {
    render::Scene scene;
    scene.title = p.title + " [" + p.units + "]";
    scene.subtitle = plies_subtitle();
    scene.footnote = footnote();
    scene.view.kind = plane_strain_ ? render::ViewKind::kIso : render::ViewKind::kTop;
    render::Surface& s = scene.surfaces.emplace_back();
    std::vector<double> values;
    std::vector<Vec3> pts;
    for (int b = 0; b < n_bodies(); ++b)
      for (const Face& f : top_faces(last_, b)) {
        std::vector<Index> poly;
        const std::array<double, 4> v = corners(f);
        for (int k = 0; k < 4; ++k) {
          poly.push_back(static_cast<Index>(pts.size()));
          pts.push_back(last_.at(f.top[static_cast<std::size_t>(k)]) + offset(b));
          values.push_back(v[static_cast<std::size_t>(k)]);
        }
        s.polygons.push_back(poly);
      }
    s.points.resize(static_cast<Index>(pts.size()), 3);
    for (std::size_t i = 0; i < pts.size(); ++i) s.points.row(static_cast<Index>(i)) = pts[i].transpose();
    s.lines = outline_lines(pts, s.polygons, box_.size().norm());
    s.line_colour = {0.25, 0.25, 0.25};
    s.colouring = colouring(p, std::move(values));
    if (smooth) {
      s.colouring->banded = false;
      s.colouring->iso_lines = false;
    }
    s.outline = false;
    write(report, scene, p.file, p.caption);
  }

  // A cell field, `value(face)` per face (NaN: grey).
  template <class Value>
  void field(PlotReport& report, const FieldPicture& p, Value value) {
    plan_field(
        report, p,
        [&](const Face& f) {
          const double v = value(f);
          return std::array<double, 4>{v, v, v, v};
        },
        false);
  }

  // A point field given on both faces of a ply: the larger of the top and the bottom value.
  void field_points(PlotReport& report, const FieldPicture& p, const io::FieldArray& data) {
    plan_field(
        report, p,
        [&](const Face& f) {
          std::array<double, 4> v;
          for (std::size_t k = 0; k < 4; ++k)
            v[k] = std::max(data.values[static_cast<std::size_t>(f.top[k])],
                            data.values[static_cast<std::size_t>(f.bottom[k])]);
          return v;
        },
        true);
  }

  // The plies stacked as they are, with the tools, coloured by |u|.
  render::Scene shape_scene(const PlyFrame& f, const std::vector<Tool>& tools, const render::Bands* bands) const {
    render::Scene scene;
    scene.view.kind = plane_strain_ ? render::ViewKind::kFront : render::ViewKind::kIso;
    render::Surface& s = scene.surfaces.emplace_back();
    std::vector<double> values;
    std::vector<Vec3> pts;
    const io::FieldArray* u = f.point("displacement");
    double level = 0.0;
    for (int b = 0; b < static_cast<int>(f.cells.size()); ++b)
      for (const Face& face : top_faces(f, b)) {
        std::vector<Index> poly;
        for (Index q : face.top) {
          poly.push_back(static_cast<Index>(pts.size()));
          pts.push_back(f.at(q));
          level += f.at(q)[2];
          values.push_back(u ? Vec3(u->values[3 * q], u->values[3 * q + 1], u->values[3 * q + 2]).norm() : 0.0);
        }
        s.polygons.push_back(poly);
      }
    level /= std::max<std::size_t>(1, pts.size());
    s.points.resize(static_cast<Index>(pts.size()), 3);
    for (std::size_t i = 0; i < pts.size(); ++i) s.points.row(static_cast<Index>(i)) = pts[i].transpose();
    FieldPicture p{"", "Displacement", "mm", "", false};
    double hi = 0.0;
    for (double v : values) hi = std::max(hi, v);
    s.colouring = colouring(p, std::move(values));
    s.colouring->bands = bands ? *bands : render::nice_bands(0.0, hi, 10);
    Box b;
    for (Index q = 0; q < f.mesh.points.rows(); ++q) b.add(f.at(q));
    add_tools(scene, tools, level, 0.0015 * box_.size().norm(), b.lo, b.hi);
    return scene;
  }

  void shape(PlotReport& report) {
    render::Scene scene = shape_scene(last_, tools_, nullptr);
    scene.title = "Formed plies and tools";
    scene.subtitle = "displacement magnitude on the top faces; " + std::to_string(n_bodies()) +
                     (n_bodies() == 1 ? " ply" : " plies");
    scene.footnote = footnote();
    write(report, scene, "shape.png",
          "The deformed plies (top faces, coloured by the displacement magnitude) with the tools: tools below the "
          "plies solid, tools above them as a wireframe.");
  }

  // Front section (y = the plies' smallest y) of every ply, and the tools' section lines.
  void section(PlotReport& report) {
    render::Scene scene;
    scene.title = "Section: every ply and the tools";
    scene.subtitle = "front view (from -y) of the section y = const";
    scene.footnote = footnote();
    scene.view.kind = render::ViewKind::kFront;
    const double y0 = box_.lo[1];
    static const std::array<render::Colour, 6> palette = {
        render::Colour::from_rgb8(0xd9, 0x5f, 0x02), render::Colour::from_rgb8(0x1b, 0x9e, 0x77),
        render::Colour::from_rgb8(0x75, 0x70, 0xb3), render::Colour::from_rgb8(0xe7, 0x29, 0x8a),
        render::Colour::from_rgb8(0x66, 0xa6, 0x1e), render::Colour::from_rgb8(0xe6, 0xab, 0x02)};
    const double tol = 1e-6 * std::max(1.0, box_.size().norm());
    Box plies;
    for (int b = 0; b < n_bodies(); ++b) {
      render::Surface& s = scene.surfaces.emplace_back();
      std::vector<Vec3> pts;
      const auto& cells = last_.cells[static_cast<std::size_t>(b)];
      for (std::size_t n = 0; n < cells.size(); ++n) {
        if (last_.kji(n)[1] != 0) continue;
        const Index* c = &last_.mesh.connectivity[static_cast<std::size_t>(last_.mesh.offsets[cells[n]])];
        const std::array<Index, 4> q = {c[0], c[1], c[5], c[4]};
        bool front = true;
        for (Index i : q) front = front && std::abs(last_.at(i)[1] - y0) < tol + 1e-9 * std::abs(y0);
        if (!front) continue;
        std::vector<Index> poly;
        for (Index i : q) {
          poly.push_back(static_cast<Index>(pts.size()));
          pts.push_back(last_.at(i));
        }
        s.polygons.push_back(poly);
      }
      s.points.resize(static_cast<Index>(pts.size()), 3);
      for (std::size_t i = 0; i < pts.size(); ++i) s.points.row(static_cast<Index>(i)) = pts[i].transpose();
      s.colour = palette[static_cast<std::size_t>(b) % palette.size()];
      s.shading = false;
      s.outline = true;
      scene.legend.push_back({render::LegendEntry::Kind::kSwatch, s.colour, ply_label(b)});
      for (const Vec3& p : pts) plies.add(p);
    }
    // The picture is framed on the plies: the tools are drawn within a margin of a third of
    // the plies' larger extent around them (a long die wall or a big frame would otherwise
    // shrink the laminate to a sliver of the picture).
    const double margin = plies.lo[0] <= plies.hi[0] ? std::max(plies.size()[0], plies.size()[2]) / 3.0 : 0.0;
    const std::array<double, 4> frame = {plies.lo[0] - margin, plies.lo[2] - margin, plies.hi[0] + margin,
                                         plies.hi[2] + margin};
    // Tool sections: each triangle cut by the plane y = y0 - tiny (in front of the plies).
    for (const Tool& t : tools_) {
      render::GlyphSet g;
      g.kind = render::GlyphSet::Kind::kSegment;
      g.colour = kToolLine;
      g.width = (margin > 0.0 ? 0.0025 * std::hypot(frame[2] - frame[0], frame[3] - frame[1])
                                      : 0.004 * box_.size().norm());
      std::vector<std::size_t> all(t.mesh.n_cells());
      for (std::size_t c = 0; c < all.size(); ++c) all[c] = c;
      for (const auto& [p, q] : plane_cuts(t.mesh, all, Vec3(0.0, y0, 0.0), Vec3::UnitY())) {
        Vec2 a(p[0], p[2]), e(q[0], q[2]);
        if (margin > 0.0 && !render::clip_segment(a, e, frame)) continue;
        g.tails.push_back(Vec3(a.x(), p[1], a.y()));
        g.heads.push_back(Vec3(e.x(), q[1], e.y()));
      }
      if (g.tails.empty()) continue;
      scene.glyphs.push_back(std::move(g));
      scene.legend.push_back({render::LegendEntry::Kind::kLine, kToolLine, "tool '" + t.name + "'"});
    }
    write(report, scene, "section.png",
          "Section of the 2-D (plane strain) part: every ply in its own colour, the tools' surfaces as lines "
          "(drawn within a third of the plies' extent around them).");
  }

  // The part's centre in plan (reference): the centre of the plies' plan box, moved onto
  // the x0 / y0 symmetry planes of the case (a quarter model's symmetry corner), as the
  // line profiles of profiles.csv (forming/output/forming_results.cpp).
  Vec3 part_centre() const {
    Box plan;
    for (const auto& p : summary_["parameters"]["plies"]) {
      const auto& o = p["origin"];
      const auto& sz = p["size"];
      if (!o.is_array() || !sz.is_array()) continue;
      const Vec3 lo(o[0].get<double>(), o[1].get<double>(), o[2].get<double>());
      plan.add(lo);
      plan.add(lo + Vec3(sz[0].get<double>(), sz[1].get<double>(), 0.0));
    }
    if (plan.lo[0] > plan.hi[0]) return 0.5 * (box_.lo + box_.hi);
    Vec3 c = 0.5 * (plan.lo + plan.hi);
    for (const auto& bc : summary_["parameters"]["boundary_conditions"]) {
      if (bc.value("kind", std::string()) != "symmetry") continue;
      const std::string side = bc.value("side", std::string());
      if (side == "x0") c[0] = plan.lo[0];
      if (side == "y0") c[1] = plan.lo[1];
    }
    return c;
  }

  // A vertical section of a 3-D part: the plane through the part's centre along the plan
  // angle options_.section_angle_deg, every ply's cut (its cells cut by the plane) in its
  // own colour and the tools' cut lines, drawn in the plane: along the section (mm from the
  // centre) against z.
  void section_3d(PlotReport& report) {
    const double a = options_.section_angle_deg * 3.14159265358979323846 / 180.0;
    const Vec3 d(std::cos(a), std::sin(a), 0.0), nrm(-std::sin(a), std::cos(a), 0.0);
    Vec3 c = part_centre();
    c[2] = 0.0;
    // A plane along a symmetry edge would cut the cells on their faces: move it a hair into
    // the part.
    const double size = std::max(box_.size().head<2>().norm(), 1e-12);
    c += (0.5 * (box_.lo + box_.hi) - c).dot(nrm) >= 0.0 ? 1e-6 * size * nrm : -1e-6 * size * nrm;
    const auto in_plane = [&](const Vec3& p) { return Vec3((p - c).dot(d), 0.0, p[2]); };
    static const std::array<std::array<int, 2>, 12> kEdges = {
        {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};
    render::Scene scene;
    scene.title = "Section through the part: every ply and the tools";
    scene.subtitle = "vertical plane through the centre at " + fmt(options_.section_angle_deg, "%g") +
                     "\u00b0 from x (plan); horizontal: distance along it [mm], vertical: z [mm], true scale";
    scene.footnote = footnote();
    scene.view.kind = render::ViewKind::kFront;
    static const std::array<render::Colour, 6> palette = {
        render::Colour::from_rgb8(0xd9, 0x5f, 0x02), render::Colour::from_rgb8(0x1b, 0x9e, 0x77),
        render::Colour::from_rgb8(0x75, 0x70, 0xb3), render::Colour::from_rgb8(0xe7, 0x29, 0x8a),
        render::Colour::from_rgb8(0x66, 0xa6, 0x1e), render::Colour::from_rgb8(0xe6, 0xab, 0x02)};
    Box cut_box;
    for (int b = 0; b < n_bodies(); ++b) {
      render::Surface s;
      std::vector<Vec3> pts;
      for (const std::size_t cell : last_.cells[static_cast<std::size_t>(b)]) {
        const Index* v = &last_.mesh.connectivity[static_cast<std::size_t>(last_.mesh.offsets[cell])];
        std::array<double, 8> dist;
        double lo = 1e300, hi = -1e300;
        for (int k = 0; k < 8; ++k) {
          dist[static_cast<std::size_t>(k)] = (last_.at(v[k]) - c).dot(nrm);
          lo = std::min(lo, dist[static_cast<std::size_t>(k)]);
          hi = std::max(hi, dist[static_cast<std::size_t>(k)]);
        }
        if (!(lo < 0.0 && hi > 0.0)) continue;
        std::vector<Vec3> cut;
        for (const auto& e : kEdges) {
          const double da = dist[static_cast<std::size_t>(e[0])], db = dist[static_cast<std::size_t>(e[1])];
          if ((da < 0.0) == (db < 0.0)) continue;
          const Vec3 pa = last_.at(v[e[0]]), pb = last_.at(v[e[1]]);
          cut.push_back(in_plane(pa + (da / (da - db)) * (pb - pa)));
        }
        if (cut.size() < 3) continue;
        Vec3 m = Vec3::Zero();
        for (const Vec3& q : cut) m += q / static_cast<double>(cut.size());
        std::sort(cut.begin(), cut.end(), [&](const Vec3& p, const Vec3& q) {
          return std::atan2(p[2] - m[2], p[0] - m[0]) < std::atan2(q[2] - m[2], q[0] - m[0]);
        });
        std::vector<Index> poly;
        for (const Vec3& q : cut) {
          poly.push_back(static_cast<Index>(pts.size()));
          pts.push_back(q);
          cut_box.add(q);
        }
        s.polygons.push_back(poly);
      }
      if (s.polygons.empty()) continue;
      s.points.resize(static_cast<Index>(pts.size()), 3);
      for (std::size_t i = 0; i < pts.size(); ++i) s.points.row(static_cast<Index>(i)) = pts[i].transpose();
      s.colour = palette[static_cast<std::size_t>(b) % palette.size()];
      s.shading = false;
      s.outline = false;
      scene.surfaces.push_back(std::move(s));
      scene.legend.push_back(
          {render::LegendEntry::Kind::kSwatch, palette[static_cast<std::size_t>(b) % palette.size()], ply_label(b)});
    }
    if (scene.surfaces.empty()) {
      report.notes.push_back("no section: the plane at " + fmt(options_.section_angle_deg, "%g") +
                             " deg through the centre misses the plies");
      return;
    }
    // Tool profiles: each tool triangle near the plies cut by the plane, kept where it is
    // within the plies' cut (padded) so that a large tool does not shrink the picture.
    const double span = std::max(cut_box.size()[0], cut_box.size()[2]);
    const Vec3 pad = Vec3::Constant(0.15 * span);
    for (const Tool& t : tools_) {
      render::GlyphSet g;
      g.kind = render::GlyphSet::Kind::kSegment;
      g.colour = kToolLine;
      g.width = 0.003 * cut_box.size().norm();
      // Clipped to the plies' extent along the section (a quarter model's tool goes on
      // beyond its symmetry plane); kept within the pad above and below them.
      const double u0 = cut_box.lo[0], u1 = cut_box.hi[0];
      for (const auto& [p, q] : plane_cuts(t.mesh, tool_cells_near(t, box_.lo, box_.hi), c, nrm)) {
        Vec3 u = in_plane(p), v = in_plane(q);
        if (u[0] > v[0]) std::swap(u, v);
        if (v[0] < u0 || u[0] > u1) continue;
        const Vec3 w = v - u;
        if (u[0] < u0) u += ((u0 - u[0]) / w[0]) * w;
        if (v[0] > u1) v -= ((v[0] - u1) / w[0]) * w;
        if (std::min(u[2], v[2]) < cut_box.lo[2] - pad[2] || std::max(u[2], v[2]) > cut_box.hi[2] + pad[2]) continue;
        g.tails.push_back(u);
        g.heads.push_back(v);
      }
      if (g.tails.empty()) continue;
      scene.glyphs.push_back(std::move(g));
      scene.legend.push_back({render::LegendEntry::Kind::kLine, kToolLine, "tool '" + t.name + "'"});
    }
    // Scale: an arrow of a round length in the legend, drawn to the picture's scale.
    const double decade = std::pow(10.0, std::floor(std::log10(0.2 * span)));
    const double bar = 0.2 * span >= 5 * decade ? 5 * decade : 0.2 * span >= 2 * decade ? 2 * decade : decade;
    render::GlyphSet scale;
    scale.kind = render::GlyphSet::Kind::kArrow;
    scale.colour = {0.2, 0.2, 0.2};
    scale.width = 0.004 * span;
    scene.glyphs.push_back(scale);
    scene.legend.push_back({render::LegendEntry::Kind::kArrow, scale.colour, fmt(bar, "%g") + " mm (scale)", 0, 2, bar,
                            static_cast<int>(scene.glyphs.size()) - 1});
    write(report, scene, "section.png",
          "Vertical section through the part's centre at " + fmt(options_.section_angle_deg, "%g") +
              " deg from x: every ply in its own colour (true scale), the tools' profiles as lines (cut from the "
              "tools' output triangles: a sphere's chords can look as if they entered the top ply).");
  }

  void fibres(PlotReport& report) {
    int body = -1;
    if (!options_.ply.empty()) {
      for (std::size_t b = 0; b < names_.size(); ++b)
        if (names_[b] == options_.ply) body = static_cast<int>(b);
      if (body < 0) {
        std::string known;
        for (const std::string& n : names_) known += (known.empty() ? "" : ", ") + n;
        throw UsageError("--ply: no ply '" + options_.ply + "' in this run (plies: " + known + ")");
      }
    } else {
      body = n_bodies() - 1;
      const nlohmann::json& plies = summary_["forming"]["plies"];
      for (int b = n_bodies() - 1; b >= 0; --b)
        if (plies.is_array() && static_cast<std::size_t>(b) < plies.size() &&
            plies[static_cast<std::size_t>(b)].value("fibre_reinforced", false)) {
          body = b;
          break;
        }
    }
    render::Scene scene;
    scene.title = "Fibre directions: ply " + ply_label(body);
    scene.subtitle = "final fibre orientation, one line per " + fmt(box_.size().head<2>().maxCoeff() / 24.0, "%.2g") +
                     " mm of the part";
    scene.footnote = footnote();
    scene.view.kind = plane_strain_ ? render::ViewKind::kIso : render::ViewKind::kTop;
    render::Surface& s = scene.surfaces.emplace_back();
    std::vector<Vec3> pts;
    const auto faces = top_faces(last_, body);
    const io::FieldArray* u = last_.point("displacement");
    const auto& a = last_.cell("fibre_direction", frame_name()).values;
    const double g = box_.size().head<2>().maxCoeff() / 24.0;
    std::map<std::pair<long, long>, std::pair<double, std::size_t>> best;  // lattice bin -> (distance, face)
    for (std::size_t i = 0; i < faces.size(); ++i) {
      std::vector<Index> poly;
      Vec3 X = Vec3::Zero();
      for (Index q : faces[i].top) {
        poly.push_back(static_cast<Index>(pts.size()));
        pts.push_back(last_.at(q));
        const Vec3 d = u ? Vec3(u->values[3 * q], u->values[3 * q + 1], u->values[3 * q + 2]) : Vec3::Zero();
        X += 0.25 * (last_.at(q) - d);
      }
      s.polygons.push_back(poly);
      const long bx = static_cast<long>(std::floor(X[0] / g)), by = static_cast<long>(std::floor(X[1] / g));
      const double dist = Vec2(X[0] - (bx + 0.5) * g, X[1] - (by + 0.5) * g).norm();
      const auto it = best.find({bx, by});
      if (it == best.end() || dist < it->second.first) best[{bx, by}] = {dist, i};
    }
    s.points.resize(static_cast<Index>(pts.size()), 3);
    for (std::size_t i = 0; i < pts.size(); ++i) s.points.row(static_cast<Index>(i)) = pts[i].transpose();
    s.colour = {0.90, 0.88, 0.82};
    render::GlyphSet glyphs;
    glyphs.kind = render::GlyphSet::Kind::kSegment;
    glyphs.colour = {0.55, 0.08, 0.08};
    glyphs.width = 0.12 * g;
    for (const auto& [bin, v] : best) {
      const Face& f = faces[v.second];
      Vec3 c = Vec3::Zero();
      for (Index q : f.top) c += 0.25 * last_.at(q);
      const Vec3 d(a[3 * f.cell], a[3 * f.cell + 1], a[3 * f.cell + 2]);
      glyphs.tails.push_back(c - 0.36 * g * d);
      glyphs.heads.push_back(c + 0.36 * g * d);
    }
    scene.glyphs.push_back(std::move(glyphs));
    scene.legend.push_back({render::LegendEntry::Kind::kLine, {0.55, 0.08, 0.08}, "fibre direction", 0, 3});
    write(report, scene, "fibres.png",
          "Final fibre orientation of ply " + ply_label(body) + ": one short line along the fibres per lattice cell.");
  }

  void force_chart(PlotReport& report) {
    const fs::path path = dir_ / "tool_force.csv";
    if (!fs::exists(path)) return;
    const io::CsvTable t = io::read_csv(path.string());
    render::Chart chart;
    chart.title = "Press force against stroke";
    chart.x_label = "stroke [mm]";
    chart.y_label = "force [N]";
    chart.footnote = "tool_force.csv";
    static const std::array<render::Colour, 4> colours = {
        render::Colour::from_rgb8(0x1f, 0x77, 0xb4), render::Colour::from_rgb8(0xd6, 0x27, 0x28),
        render::Colour::from_rgb8(0x2c, 0xa0, 0x2c), render::Colour::from_rgb8(0x94, 0x67, 0xbd)};
    for (const std::string& name : t.names()) {
      if (name.size() < 10 || name.compare(name.size() - 10, 10, "_stroke_mm") != 0) continue;
      const std::string tool = name.substr(0, name.size() - 10);
      render::ChartSeries s;
      s.label = tool == "edge" ? "displaced edge" : "tool '" + tool + "'";
      s.style = render::ChartSeries::Style::kLine;
      s.colour = colours[chart.series.size() % colours.size()];
      const Eigen::VectorXd x = t.numbers(t.column_index(name)), y = t.numbers(t.column_index(tool + "_force_N"));
      s.x.assign(x.data(), x.data() + x.size());
      s.y.assign(y.data(), y.data() + y.size());
      render::ChartSeries dots = s;
      dots.label = "";
      dots.style = render::ChartSeries::Style::kDots;
      chart.series.push_back(s);
      chart.series.push_back(dots);
    }
    if (chart.series.empty()) return;
    render::write_chart_png(chart, options_.size, (dir_ / "plots" / "force_displacement.png").string());
    lap("render force_displacement.png");
    report.pictures.push_back("plots/force_displacement.png");
    captions_["plots/force_displacement.png"] =
        "Force the press needs against the tool's stroke (tool_force.csv; one dot per converged step).";
  }

  void sequence(PlotReport& report) {
    std::vector<std::size_t> pick;
    const std::size_t n = frames_.size(), want = static_cast<std::size_t>(options_.frames);
    if (n <= want) {
      for (std::size_t i = 0; i < n; ++i) pick.push_back(i);
    } else {
      for (std::size_t k = 0; k < want; ++k) pick.push_back((k * (n - 1)) / std::max<std::size_t>(1, want - 1));
      pick.erase(std::unique(pick.begin(), pick.end()), pick.end());
    }
    // One colour range and one framing for all frames: the largest |u|, the union box.
    std::vector<PlyFrame> frames;
    double hi = 0.0;
    Box all;
    for (std::size_t i : pick) {
      frames.push_back(read_frame(dir_ / frames_[i].file, ns_, nt_));
      if (const io::FieldArray* u = frames.back().point("displacement"))
        for (std::size_t p = 0; p + 2 < u->values.size(); p += 3)
          hi = std::max(hi, Vec3(u->values[p], u->values[p + 1], u->values[p + 2]).norm());
      for (Index p = 0; p < frames.back().mesh.points.rows(); ++p) all.add(frames.back().at(p));
    }
    lap("read " + std::to_string(pick.size()) + " frames");
    const render::Bands bands = render::nice_bands(0.0, hi, 10);
    fs::create_directories(dir_ / "plots" / "frames");
    std::vector<std::string> files;
    for (std::size_t k = 0; k < pick.size(); ++k) {
      const std::vector<Tool> tools = read_tools(dir_, sets_, frames_[pick[k]].file);
      render::Scene scene = shape_scene(frames[k], tools, &bands);
      scene.title = "Forming: frame " + std::to_string(k + 1) + " of " + std::to_string(pick.size());
      scene.subtitle = "load factor " + fmt(frames_[pick[k]].time, "%.3f") + "; displacement magnitude";
      scene.footnote = frames_[pick[k]].file;
      // Invisible corners of the union box: every frame framed alike.
      render::Surface& corners = scene.surfaces.emplace_back();
      corners.points.resize(8, 3);
      for (int c = 0; c < 8; ++c)
        corners.points.row(c) =
            Vec3(c & 1 ? all.hi[0] : all.lo[0], c & 2 ? all.hi[1] : all.lo[1], c & 4 ? all.hi[2] : all.lo[2])
                .transpose();
      for (Index c = 0; c < 8; ++c) corners.polygons.push_back({c, c, c});
      corners.colour = {1, 1, 1};
      corners.outline = false;
      corners.shading = false;
      char name[64];
      std::snprintf(name, sizeof name, "plots/frames/frame_%04zu.png", k);
      render::write_png(scene, options_.frame_size, (dir_ / name).string());
      lap("render frame " + std::to_string(k));
      files.push_back((dir_ / name).string());
    }
    report.notes.push_back(std::to_string(files.size()) + " frames in plots/frames/");
    if (!files.empty()) frames_first_ = "plots/frames/frame_0000.png";
    if (options_.animation) {
      std::string why;
      const std::string movie = (dir_ / "plots" / "forming.avi").string();
      const bool movie_ok = write_animation(files, movie, 4.0, &why);
      lap("animation");
      if (movie_ok)
        report.animation = "plots/forming.avi";
      else
        report.notes.push_back("no animation: " + why);
    }
  }

  void write(PlotReport& report, const render::Scene& scene, const std::string& file, const std::string& caption) {
    render::write_png(scene, options_.size, (dir_ / "plots" / file).string());
    lap("render " + file);
    report.pictures.push_back("plots/" + file);
    captions_["plots/" + file] = caption;
  }

  void write_report(const PlotReport& report) {
    std::ostringstream h;
    const auto esc = [](const std::string& s) { return io::xml_escape(s); };
    h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>simform: " << esc(dir_.filename().string())
      << "</title>\n<style>body{font-family:sans-serif;max-width:1250px;margin:auto}"
      << "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 8px;text-align:left}"
      << "img{max-width:100%;border:1px solid #ddd}figure{margin:1.5em 0}</style></head><body>\n";
    h << "<h1>Forming run " << esc(dir_.filename().string()) << "</h1>\n<table>\n";
    const auto row = [&](const std::string& k, const std::string& v) {
      h << "<tr><th>" << esc(k) << "</th><td>" << esc(v) << "</td></tr>\n";
    };
    row("case", summary_["inputs"].value("case", std::string("?")));
    row("status", summary_.value("status", std::string("?")) + ": " + summary_.value("message", std::string()));
    row("units", summary_["parameters"].value("units", std::string("mm, N, MPa")));
    if (summary_.contains("max_displacement") && summary_["max_displacement"].is_array()) {
      Vec3 m = Vec3::Zero();
      for (int c = 0; c < 3; ++c) m[c] = summary_["max_displacement"][static_cast<std::size_t>(c)].get<double>();
      row("largest displacement", fmt(m.norm(), "%.4g") + " mm");
    }
    h << "</table>\n";
    const nlohmann::json& plies = summary_["forming"]["plies"];
    if (plies.is_array() && !plies.empty()) {
      h << "<h2>Forming results per ply (summary.json \"forming\")</h2>\n<table><tr><th>ply</th><th>fibre "
           "stretch</th><th>fibre angle change [deg]</th><th>trellis shear [deg]</th><th>thickness "
           "[mm]</th><th>waviness amplitude / wavelength [mm]</th></tr>\n";
      const auto num = [](const nlohmann::json& j) {
        return j.is_number() ? fmt(j.get<double>(), "%.4g") : std::string("&ndash;");
      };
      for (const auto& p : plies) {
        h << "<tr><td>" << esc(p.value("ply", std::string())) << "</td><td>" << num(p["fibre_stretch"]["min"])
          << " &ndash; " << num(p["fibre_stretch"]["max"]) << "</td><td>" << num(p["fibre_angle_change_deg"]["min"])
          << " &ndash; " << num(p["fibre_angle_change_deg"]["max"]) << "</td><td>";
        if (p.contains("trellis_shear_angle_deg") && p["trellis_shear_angle_deg"].is_object())
          h << num(p["trellis_shear_angle_deg"]["min"]) << " &ndash; " << num(p["trellis_shear_angle_deg"]["max"])
            << " (with " << esc(p.value("trellis_partner", std::string())) << ")";
        else
          h << "&ndash;";
        h << "</td><td>" << num(p["thickness_mm"]["min"]) << " &ndash; " << num(p["thickness_mm"]["max"]) << " (ref. "
          << num(p["thickness_mm"]["reference"]) << ")</td><td>" << num(p["wrinkling"]["amplitude_mm"]) << " / "
          << num(p["wrinkling"]["wavelength_mm"]) << "</td></tr>\n";
      }
      h << "</table>\n";
    }
    h << "<p>Data: <a href=\"tool_force.csv\">tool_force.csv</a>, <a href=\"profiles.csv\">profiles.csv</a> (0, 45 "
         "and 90 degree line profiles), <a href=\"history.csv\">history.csv</a>, <a "
         "href=\"summary.json\">summary.json</a>, <a href=\"result.pvd\">result.pvd</a> (ParaView).</p>\n";
    for (const std::string& pic : report.pictures) {
      h << "<figure><img src=\"" << esc(pic) << "\" alt=\"" << esc(pic) << "\"><figcaption>" << esc(captions_[pic])
        << "</figcaption></figure>\n";
    }
    if (!frames_first_.empty())
      h << "<p>Frame sequence: <a href=\"plots/frames/\">plots/frames/</a>"
        << (report.animation.empty() ? std::string()
                                     : ", animation <a href=\"" + report.animation + "\">" + report.animation + "</a>")
        << ".</p>\n";
    h << "</body></html>\n";
    io::write_file_atomic((dir_ / "report.html").string(), h.str());
  }

  fs::path dir_;
  PlotOptions options_;
  nlohmann::json summary_;
  int ns_ = 4, nt_ = 2;
  bool plane_strain_ = false;
  std::vector<std::string> names_;
  std::vector<double> angles_;
  std::vector<DataSet> sets_, frames_;
  PlyFrame last_;
  std::vector<Tool> tools_;
  Box box_;
  std::map<std::string, std::string> captions_;
  std::string frames_first_;
  // SF_PLOT_TIMING: wall and CPU time of each piece.
  using Clock = std::chrono::steady_clock;
  struct Lap {
    std::string what;
    double wall, cpu;
  };
  std::vector<Lap> laps_;
  Clock::time_point wall_mark_ = Clock::now();
  std::clock_t cpu_mark_ = std::clock();
  // The time since the previous lap (or since reading the results) goes to `what`.
  void lap(const std::string& what) {
    const std::clock_t now = std::clock();
    const Clock::time_point wall = Clock::now();
    laps_.push_back({what, std::chrono::duration<double>(wall - wall_mark_).count(),
                     static_cast<double>(now - cpu_mark_) / CLOCKS_PER_SEC});
    cpu_mark_ = now;
    wall_mark_ = wall;
  }
};

}  // namespace

PlotReport plot_results(const std::string& results_dir, const PlotOptions& options) {
  Plotter p(results_dir, options);
  return p.run();
}

}  // namespace sf::forming

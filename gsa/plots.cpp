#include "gsa/plots.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "common/io/vtk_xml.hpp"
#include "common/render/chart.hpp"
#include "common/render/display.hpp"
#include "gsa/report.hpp"
#include "gsa/view3d.hpp"

namespace sf::gsa {

namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const render::Colour kTension{0.80, 0.11, 0.09};
const render::Colour kCompression{0.09, 0.31, 0.78};
const render::Colour kScaleArrow{0.2, 0.2, 0.2};
const render::Colour kFibre1{0.90, 0.42, 0.0};
const render::Colour kFibre2{0.16, 0.16, 0.62};
const render::Colour kElementEdges{0.78, 0.78, 0.78};

int reference_decimals(double v) {
  return v > 0 ? std::max(0, static_cast<int>(-std::floor(std::log10(v) + 1e-9))) : 0;
}

// Marks per sample spacing across the part: about this many sample points along the
// longer side of a square mesh.
constexpr double kSamplesAcross = 10.0;

const io::FieldArray* find_field(const io::PolyMesh& m, const std::string& name, int n_components) {
  for (const auto& f : m.point_data)
    if (f.name == name && f.n_components == n_components && static_cast<Index>(f.n_tuples()) == m.n_points()) return &f;
  return nullptr;
}

const io::FieldArray& require_field(const io::PolyMesh& m, const std::string& name, int n_components,
                                    const std::string& file) {
  const io::FieldArray* f = find_field(m, name, n_components);
  if (!f)
    throw InputError(file + ": missing point data array '" + name + "' (" + std::to_string(n_components) +
                     " component" + (n_components > 1 ? "s" : "") + "); was it written by gsa analyse?");
  return *f;
}

Vec3 vec_of(const io::FieldArray& f, Index i) {
  const auto k = static_cast<std::size_t>(i) * 3;
  return {f.values[k], f.values[k + 1], f.values[k + 2]};
}

double polygon_area(const io::PolyMesh& m, const std::vector<Index>& poly) {
  Vec3 n = Vec3::Zero();
  for (std::size_t k = 0; k < poly.size(); ++k)
    n += m.points.row(poly[k]).transpose().cross(m.points.row(poly[(k + 1) % poly.size()]).transpose());
  return 0.5 * n.norm();
}

double surface_area(const io::PolyMesh& m) {
  double a = 0;
  for (const auto& p : m.polygons) a += polygon_area(m, p);
  return a;
}

using Results = PlotData;

// ---------------------------------------------------------------------------------------
// Sampling points for arrows and fibre lines

struct Sampling {
  std::vector<Index> points;                      // point indices (same on both surfaces)
  double spacing = 1;                             // model units on the undeformed surface
  std::vector<std::vector<Index>> element_edges;  // element boundaries as polylines
};

Sampling sample_surface(const io::PolyMesh& m) {
  Sampling s;
  const double area = surface_area(m);
  // gsa writes each element as (subdiv + 1)^2 points, subdiv^2 quads, cell data "element".
  const io::FieldArray* element = nullptr;
  for (const auto& f : m.cell_data)
    if (f.name == "element" && f.n_components == 1 && f.values.size() == m.n_cells()) element = &f;
  Index n_el = 0;
  if (element)
    for (double e : element->values) n_el = std::max<Index>(n_el, static_cast<Index>(e) + 1);
  // Every element keeps its (subdiv + 1)^2 points; cells outside the measured region are
  // left out (gsa/measured_region.hpp), so the element count comes from the points.
  int subdiv = 0;
  for (int sd = 32; sd >= 1 && n_el > 0; --sd) {  // the finest that fits: 8 as gsa writes it
    const Index per = static_cast<Index>(sd + 1) * (sd + 1);
    if (m.n_points() % per == 0 && m.n_points() / per >= n_el &&
        m.polygons.size() <= static_cast<std::size_t>(m.n_points() / per * sd * sd)) {
      subdiv = sd;
      n_el = m.n_points() / per;
      break;
    }
  }
  // Points on a drawn cell: sampling points and element edges elsewhere are not drawn.
  std::vector<char> drawn(static_cast<std::size_t>(m.n_points()), 0);
  for (const auto& poly : m.polygons)
    for (Index p : poly)
      if (p >= 0 && p < m.n_points()) drawn[static_cast<std::size_t>(p)] = 1;
  if (subdiv > 0) {
    const int np = subdiv + 1;
    const int k =
        std::clamp(static_cast<int>(std::lround(kSamplesAcross / std::sqrt(double(n_el)))), 1, std::max(1, subdiv / 2));
    std::vector<int> at;
    for (int q = 0; q < k; ++q) at.push_back(static_cast<int>(std::lround((q + 0.5) * subdiv / k)));
    // An element edge is drawn in runs of drawn points.
    auto add_edge = [&](const std::vector<Index>& line) {
      std::vector<Index> run;
      for (Index p : line) {
        if (drawn[static_cast<std::size_t>(p)]) {
          run.push_back(p);
          continue;
        }
        if (run.size() > 1) s.element_edges.push_back(run);
        run.clear();
      }
      if (run.size() > 1) s.element_edges.push_back(run);
    };
    for (Index e = 0; e < n_el; ++e) {
      const Index base = e * np * np;
      for (int j : at)
        for (int i : at)
          if (drawn[static_cast<std::size_t>(base + j * np + i)]) s.points.push_back(base + j * np + i);
      std::vector<Index> b0, b1, b2, b3;
      for (int t = 0; t < np; ++t) {
        b0.push_back(base + t);
        b1.push_back(base + subdiv * np + t);
        b2.push_back(base + t * np);
        b3.push_back(base + t * np + subdiv);
      }
      for (const auto* b : {&b0, &b1, &b2, &b3}) add_edge(*b);
    }
  } else {
    // Any tessellation: the point nearest to the centre of each cell of a square grid over
    // the surface's bounding box in its two widest coordinates.
    const Eigen::RowVector3d lo = m.points.colwise().minCoeff(), hi = m.points.colwise().maxCoeff();
    Eigen::RowVector3d ext = hi - lo;
    int a = 0, b = 1;
    if (ext[2] > std::min(ext[0], ext[1])) (ext[0] < ext[1] ? a : b) = 2;
    const double h = std::max(ext[a], ext[b]) / kSamplesAcross;
    const int na = std::max(1, static_cast<int>(std::ceil(ext[a] / h))),
              nb = std::max(1, static_cast<int>(std::ceil(ext[b] / h)));
    std::vector<Index> best(static_cast<std::size_t>(na * nb), -1);
    std::vector<double> dist(best.size(), HUGE_VAL);
    for (Index p = 0; p < m.n_points(); ++p) {
      if (!drawn[static_cast<std::size_t>(p)]) continue;
      const double u = (m.points(p, a) - lo[a]) / h, v = (m.points(p, b) - lo[b]) / h;
      const int iu = std::min(na - 1, static_cast<int>(u)), iv = std::min(nb - 1, static_cast<int>(v));
      const double d = std::hypot(u - iu - 0.5, v - iv - 0.5);
      const auto c = static_cast<std::size_t>(iv * na + iu);
      if (d < dist[c] && d < 0.35) dist[c] = d, best[c] = p;
    }
    for (Index p : best)
      if (p >= 0) s.points.push_back(p);
  }
  s.spacing = s.points.empty() ? 1.0 : std::sqrt(area / static_cast<double>(s.points.size()));
  if (!(s.spacing > 0)) s.spacing = 1.0;
  return s;
}

// ---------------------------------------------------------------------------------------
// Scene pieces

render::Surface plain_surface(const io::PolyMesh& m) {
  render::Surface s;
  s.points = m.points;
  s.polygons = m.polygons;
  return s;
}

// Colour range for a field: round bands over its finite values, at least `min_span` wide
// (a nearly uniform field shows as one or two bands, not as amplified noise); diverging
// and centred on 0 when the values take both signs (viridis otherwise).
render::ScalarColouring colouring_for(const std::vector<double>& values, const std::string& title,
                                      const std::string& units, double min_span) {
  render::ScalarColouring c;
  c.title = title;
  c.units = units;
  c.values = values;
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (double v : values)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!(hi >= lo)) lo = 0, hi = 1;
  // Round-off on the other side of zero (a shear angle of -1e-6 deg) does not start a band.
  if (lo < 0 && hi > 0 && -lo < 1e-3 * (hi - lo)) lo = 0;
  if (lo < 0 && hi > 0 && hi < 1e-3 * (hi - lo)) hi = 0;
  if (hi - lo < min_span) {
    const double mid = 0.5 * (lo + hi);
    lo = mid - min_span / 2;
    hi = mid + min_span / 2;
  }
  // Diverging (centred on 0) only when both signs matter: a side below 10 % of the other
  // (e.g. round-off around a zero shear angle) would waste half the bands.
  const bool signed_field = lo < 0 && hi > 0 && std::min(-lo, hi) >= 0.1 * std::max(-lo, hi);
  c.map = signed_field ? render::ColourMap::kDiverging : render::ColourMap::kViridis;
  c.bands = render::nice_bands(lo, hi, 10, signed_field);
  return c;
}

std::vector<double> scalar_values(const io::PolyMesh& m, const std::string& name, const std::string& file) {
  return require_field(m, name, 1, file).values;
}

// "from A to B" (or "uniform, A" / "nearly uniform, A to B" when the range is below
// `min_span`, the smallest range the colour bands resolve).
std::string range_text(const std::vector<double>& v, int decimals, const std::string& unit, double min_span) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (double x : v)
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  if (!(hi >= lo)) return "no values";
  const std::string a = render::format_fixed(lo, decimals), b = render::format_fixed(hi, decimals);
  if (hi - lo < min_span) return a == b ? "uniform: " + a + unit : "nearly uniform: " + a + unit + " to " + b + unit;
  return "from " + a + unit + " to " + b + unit;
}

// Decimals that show a strain range sensibly (3 significant digits of its largest value).
int decimals_for(const std::vector<double>& v) {
  double m = 0;
  for (double x : v)
    if (std::isfinite(x)) m = std::max(m, std::abs(x));
  if (m <= 0) return 3;
  return std::clamp(2 - static_cast<int>(std::floor(std::log10(m))), 0, 6);
}

// The round number (1, 2, 5 x 10^k) nearest to `x` on a log scale.
double round_125(double x) {
  if (!(x > 0)) return 0;
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  double best = p;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (std::abs(std::log(m * p / x)) < std::abs(std::log(best / x))) best = m * p;
  return best;
}

struct ArrowScale {
  double model_per_strain = 0;  // arrow length per unit strain (model units)
  double reference = 0;         // strain of the legend's scale arrow
  double spacing = 1;
};

ArrowScale arrow_scale(const Results& r, const Sampling& s, StrainMeasure m) {
  const auto names = measure_fields(m);
  const std::string file = r.source + "/undeformed.vtp";
  const auto& e1 = require_field(r.undeformed, names[0], 1, file);
  const auto& e2 = require_field(r.undeformed, names[1], 1, file);
  double emax = 0;
  for (Index p : s.points)
    for (const auto* f : {&e1, &e2}) {
      const double v = f->values[static_cast<std::size_t>(p)];
      if (std::isfinite(v)) emax = std::max(emax, std::abs(v));
    }
  ArrowScale a;
  a.spacing = s.spacing;
  if (emax <= 0) emax = 1e-3;
  // The longest arrow reaches 40 % of the spacing from the centre: pairs on neighbouring
  // points stay a fifth of the spacing apart even when they point at each other.
  a.model_per_strain = 0.35 * s.spacing / emax;
  a.reference = round_125(emax);
  return a;
}

render::Scene arrow_scene(const Results& r, const Sampling& s, const ArrowScale& a, bool deformed,
                          const PlotOptions& o) {
  const io::PolyMesh& m = deformed ? r.deformed : r.undeformed;
  const std::string file = r.source + (deformed ? "/deformed.vtp" : "/undeformed.vtp");
  const auto names = measure_fields(r.measure);
  const auto& e1 = require_field(m, names[0], 1, file);
  const auto& e2 = require_field(m, names[1], 1, file);
  const auto& d1 = require_field(m, "dir1", 3, file);
  const auto& d2 = require_field(m, "dir2", 3, file);

  render::Scene scene;
  scene.title = deformed ? "Principal strains on the formed part" : "Principal strains on the blank";
  scene.subtitle = r.case_name + "  \xC2\xB7  " + measure_name(r.measure) + " strain  \xC2\xB7  " +
                   (deformed ? "deformed surface" : "undeformed surface (material directions before forming)");
  scene.view = deformed ? o.view : render::View{};
  const double gap = 0.05 * a.spacing;
  const double min_length = 0.03 * a.spacing;
  const double min_strain = min_length / a.model_per_strain;
  scene.footnote = "Arrows along the major and minor directions at " + std::to_string(s.points.size()) +
                   " points, one length scale for both arrow pictures, true to scale where the surface faces "
                   "the viewer; none drawn where the strain is below " +
                   render::format_fixed(min_strain, reference_decimals(min_strain) + 1) +
                   " in magnitude. View: " + render::view_name(scene.view) + ". Lengths in " + r.units + ".";
  render::Surface surf = plain_surface(m);
  surf.colour = {0.93, 0.93, 0.93};
  surf.lines = s.element_edges;
  surf.line_colour = kElementEdges;
  scene.surfaces.push_back(std::move(surf));

  render::GlyphSet tension, compression;
  tension.colour = kTension;
  compression.colour = kCompression;
  for (auto* g : {&tension, &compression}) {
    g->width = 0.05 * a.spacing;
    g->head_length = 0.16 * a.spacing;
    g->head_width = 0.15 * a.spacing;
  }
  for (Index p : s.points) {
    const Vec3 x = m.points.row(p).transpose();
    for (int k = 0; k < 2; ++k) {
      const double e = (k == 0 ? e1 : e2).values[static_cast<std::size_t>(p)];
      Vec3 d = vec_of(k == 0 ? d1 : d2, p);
      if (!std::isfinite(e) || !d.allFinite() || d.norm() < 1e-12) continue;
      d.normalize();
      const double len = a.model_per_strain * std::abs(e);
      if (len < min_length) continue;
      for (const double sgn : {-1.0, 1.0}) {
        const Vec3 inner = x + sgn * gap * d, outer = x + sgn * (gap + len) * d;
        if (e > 0) {
          tension.tails.push_back(inner);
          tension.heads.push_back(outer);
        } else {
          compression.tails.push_back(outer);
          compression.heads.push_back(inner);
        }
      }
    }
  }
  scene.glyphs = {tension, compression};
  scene.legend_title = "Arrows";
  render::LegendEntry t, c, ref;
  t.kind = c.kind = ref.kind = render::LegendEntry::Kind::kArrow;
  t.colour = kTension;
  t.label = "tension (heads out)";
  t.glyph_set = 0;
  c.colour = kCompression;
  c.label = "compression (heads in)";
  c.glyph_set = 1;
  ref.colour = kScaleArrow;
  ref.glyph_set = 0;
  ref.model_length = a.model_per_strain * a.reference;
  ref.label = "length of " + render::format_fixed(a.reference, reference_decimals(a.reference)) + " " +
              measure_word(r.measure) + " strain";
  render::LegendEntry edges;
  edges.kind = render::LegendEntry::Kind::kLine;
  edges.colour = kElementEdges;
  edges.width_px = 2;
  edges.label = "element edges";
  scene.legend = {t, c, ref, edges};
  return scene;
}

render::Scene contour_scene(const Results& r, const std::vector<double>& values, const std::string& title,
                            const std::string& bar_title, const std::string& units, double min_span,
                            const std::string& what, const PlotOptions& o) {
  render::Scene scene;
  scene.title = title;
  scene.subtitle = r.case_name + "  \xC2\xB7  " + what;
  scene.view = o.view;
  scene.footnote = "Formed part (deformed surface). View: " + render::view_name(o.view) +
                   ". Bands of equal width; dark lines at the band edges.";
  render::Surface surf = plain_surface(r.deformed);
  surf.colouring = colouring_for(values, bar_title, units, min_span);
  scene.surfaces.push_back(std::move(surf));
  return scene;
}

// The marks flagged as outliers (summary.json "outliers") as black asterisks on the
// formed part, where they were measured; the footnote says how many.
void draw_flagged_marks(const Results& r, render::Scene& scene) {
  const auto out = r.summary.find("outliers");
  if (out == r.summary.end() || !out->contains("flagged")) return;
  double size = 0.0;
  if (const auto p = r.summary.find("parameters");
      p != r.summary.end() && p->contains("mark_spacing") && (*p)["mark_spacing"].is_number())
    size = 0.45 * (*p)["mark_spacing"].get<double>();
  if (!(size > 0.0) && r.deformed.n_points() > 0)
    size = 0.005 * (r.deformed.points.colwise().maxCoeff() - r.deformed.points.colwise().minCoeff()).norm();
  render::GlyphSet g;
  g.kind = render::GlyphSet::Kind::kSegment;
  g.colour = {0.0, 0.0, 0.0};
  g.width = 0.18 * size;
  Index n = 0;
  for (const auto& f : (*out)["flagged"]) {
    if (!f.contains("position") || !f["position"].is_array() || f["position"].size() != 3) continue;
    const Vec3 x(f["position"][0].get<double>(), f["position"][1].get<double>(), f["position"][2].get<double>());
    for (const Vec3& d : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}) {
      g.tails.push_back(x - size * d);
      g.heads.push_back(x + size * d);
    }
    ++n;
  }
  if (n == 0) return;
  scene.glyphs.push_back(std::move(g));
  scene.footnote += " Black asterisks: " + std::to_string(n) + " flagged mark" + (n == 1 ? "" : "s") +
                    " (summary.json, strains.csv flag_*).";
}

render::Scene fibre_scene(const Results& r, const Sampling& s, const PlotOptions& o) {
  const std::string file = r.source + "/deformed.vtp";
  const auto& f1 = require_field(r.deformed, "fibre1", 3, file);
  const auto& f2 = require_field(r.deformed, "fibre2", 3, file);
  render::Scene scene;
  scene.title = "Fibre directions on the formed part";
  scene.subtitle = r.case_name + "  \xC2\xB7  both fibre families, current directions";
  scene.view = o.view;
  scene.footnote = "Short lines along each fibre family at " + std::to_string(s.points.size()) +
                   " points of the deformed surface. View: " + render::view_name(o.view) + ".";
  render::Surface surf = plain_surface(r.deformed);
  surf.colour = {0.93, 0.93, 0.93};
  surf.lines = s.element_edges;
  surf.line_colour = kElementEdges;
  scene.surfaces.push_back(std::move(surf));
  const double half = 0.36 * s.spacing;
  render::GlyphSet g1, g2;
  g1.kind = g2.kind = render::GlyphSet::Kind::kSegment;
  g1.colour = kFibre1;
  g2.colour = kFibre2;
  g1.width = g2.width = 0.06 * s.spacing;
  for (Index p : s.points) {
    const Vec3 x = r.deformed.points.row(p).transpose();
    for (int k = 0; k < 2; ++k) {
      Vec3 d = vec_of(k == 0 ? f1 : f2, p);
      if (!d.allFinite() || d.norm() < 1e-12) continue;
      d.normalize();
      auto& g = k == 0 ? g1 : g2;
      g.tails.push_back(x - half * d);
      g.heads.push_back(x + half * d);
    }
  }
  scene.glyphs = {g1, g2};
  scene.legend_title = "Fibre families";
  for (int k = 0; k < 2; ++k) {
    render::LegendEntry e;
    e.kind = render::LegendEntry::Kind::kLine;
    e.colour = k == 0 ? kFibre1 : kFibre2;
    e.width_px = 4;
    std::string angle = k < static_cast<int>(r.fibre_angles.size())
                            ? render::format_fixed(r.fibre_angles[static_cast<std::size_t>(k)], 0) + "\xC2\xB0"
                            : "";
    e.label = "family " + std::to_string(k + 1) + (angle.empty() ? "" : " (" + angle + " on the blank)");
    scene.legend.push_back(e);
  }
  render::LegendEntry edges;
  edges.kind = render::LegendEntry::Kind::kLine;
  edges.colour = kElementEdges;
  edges.width_px = 2;
  edges.label = "element edges";
  scene.legend.push_back(edges);
  return scene;
}

// ---------------------------------------------------------------------------------------
// Principal strain plot

// Reference path lambda2 = lambda1^k for lambda1 >= 1 (both directions for k = 1).
render::ChartSeries reference_line(double k, StrainMeasure m, const std::string& label, const render::Colour& colour,
                                   double dash) {
  render::ChartSeries s;
  s.style = render::ChartSeries::Style::kLine;
  s.label = label;
  s.colour = colour;
  s.size_px = 2;
  s.dash_px = dash;
  s.sets_range = false;
  const double lmin = k == 1.0 ? 0.2 : 1.0;
  for (int i = 0; i <= 400; ++i) {
    const double l1 = lmin * std::pow(5.0 / lmin, i / 400.0);
    const double l2 = std::pow(l1, k);
    s.x.push_back(strain_of_stretch(l2, m));
    s.y.push_back(strain_of_stretch(l1, m));
  }
  return s;
}

// Stage series: each path as a line through its stages with a dot at its last stage.
void add_strain_paths(const std::vector<StrainPath>& paths, render::Chart& chart) {
  static const render::Colour kPathColours[] = {{0.90, 0.50, 0.00}, {0.00, 0.60, 0.50}, {0.80, 0.10, 0.10},
                                                {0.35, 0.20, 0.70}, {0.55, 0.35, 0.10}, {0.10, 0.45, 0.80}};
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const StrainPath& p = paths[i];
    render::ChartSeries line, end;
    line.style = render::ChartSeries::Style::kLine;
    line.colour = end.colour = kPathColours[i % std::size(kPathColours)];
    line.size_px = 2.5;
    end.size_px = 6;
    line.x = p.minor;
    line.y = p.major;
    for (std::size_t k = p.major.size(); k-- > 0;)
      if (std::isfinite(p.major[k]) && std::isfinite(p.minor[k])) {
        end.x = {p.minor[k]};
        end.y = {p.major[k]};
        break;
      }
    line.label = i < 8 ? "path of " + p.id : "";
    chart.series.push_back(std::move(line));
    chart.series.push_back(std::move(end));
  }
  if (!paths.empty())
    chart.footnote += " Lines: strain paths through the " + std::to_string(paths.front().major.size()) +
                      " stages (strain_paths.csv), a dot at the last.";
}

render::Colour zone_colour(Zone z) {
  switch (z) {
    case Zone::kFailure:
      return {0.84, 0.09, 0.09};
    case Zone::kNeckingRisk:
      return {1.00, 0.62, 0.00};
    case Zone::kExcessThinning:
      return {0.58, 0.20, 0.72};
    case Zone::kCompression:
      return {0.15, 0.42, 0.90};
    case Zone::kInsufficientStretch:
      return {0.62, 0.62, 0.62};
    case Zone::kSafe:
      return {0.18, 0.66, 0.28};
    case Zone::kOutside:
      return {0.90, 0.90, 0.80};
    case Zone::kNone:
      break;
  }
  return {0.97, 0.97, 0.97};
}

// The zones on the formed part: every quad of the tessellated surface classified from its
// corners' mean stretches (the mid-surface's when the surfaces carry them), drawn as one
// plain surface per zone with its outline.
render::Scene zone_scene(const Results& r, const PlotOptions& o) {
  const FlcAssessment& a = *r.assessment;
  const bool mid = find_field(r.deformed, "mid_lambda1", 1) && find_field(r.deformed, "mid_lambda2", 1);
  const std::string file = r.source + "/deformed.vtp";
  const io::FieldArray& l1 = require_field(r.deformed, mid ? "mid_lambda1" : "lambda1", 1, file);
  const io::FieldArray& l2 = require_field(r.deformed, mid ? "mid_lambda2" : "lambda2", 1, file);
  std::map<Zone, std::vector<std::vector<Index>>> by_zone;
  for (const auto& poly : r.deformed.polygons) {
    double s1 = 0, s2 = 0;
    int n = 0;
    for (Index v : poly) {
      const double a1 = l1.values[static_cast<std::size_t>(v)], a2 = l2.values[static_cast<std::size_t>(v)];
      if (!std::isfinite(a1) || !std::isfinite(a2)) continue;
      s1 += a1, s2 += a2, ++n;
    }
    Zone z = Zone::kNone;
    if (n > 0) {
      const double lam1 = s1 / n, lam2 = s2 / n;
      const double major = strain_of_stretch(lam1, r.measure), minor = strain_of_stretch(lam2, r.measure);
      z = classify_zone(major, minor, 100.0 * (1.0 / (lam1 * lam2) - 1.0), r.flc->major_at(minor), r.measure,
                        a.options);
    }
    by_zone[z].push_back(poly);
  }
  render::Scene scene;
  scene.title = "Forming-limit zones";
  scene.view = o.view;
  scene.subtitle =
      r.case_name + "  \xC2\xB7  " + a.strains + " strains  \xC2\xB7  " + measure_name(r.measure) + " strain";
  scene.footnote =
      "Formed part. Zones of the fitted surface (corners' mean strains); marks counted in "
      "summary.json, per mark in strains.csv (zone). Curve: " +
      a.curve + ".";
  scene.legend_title = "Zone (marks)";
  for (const auto& [z, polys] : by_zone) {
    render::Surface surf;
    surf.points = r.deformed.points;
    surf.polygons = polys;
    surf.colour = zone_colour(z);
    scene.surfaces.push_back(std::move(surf));
  }
  for (Zone z : kZones) {
    if (!by_zone.count(z) && a.counts.at(zone_code(z)) == 0) continue;
    render::LegendEntry e;
    e.kind = render::LegendEntry::Kind::kSwatch;
    e.colour = zone_colour(z);
    e.label = zone_label(z) + " (" + std::to_string(a.counts.at(zone_code(z))) + ")";
    scene.legend.push_back(e);
  }
  return scene;
}

// Major, minor and thickness strain along a section (branch 0) against the arc length on
// the formed part; the mid-surface strains solid and the face's dashed when both exist.
render::Chart section_chart(const Results& r, const Section& sec) {
  const bool mid = r.section_options.mid.enabled();
  const std::string w = measure_word(r.measure);
  render::Chart c;
  c.title = "Section " + sec.name.substr(sec.name.find('_') + 1) + ": " + sec.spec.text;
  c.subtitle = r.case_name + "  \xC2\xB7  " + measure_name(r.measure) + " strain along the cut";
  c.x_label = "arc length on the formed part (" + r.units + ")";
  c.y_label = w + " strain";
  c.legend_title = "Key";
  render::ChartSeries e1, e2, m1, m2, th;
  for (auto* x : {&e1, &e2, &m1, &m2, &th}) x->style = render::ChartSeries::Style::kLine;
  e1.colour = m1.colour = {0.80, 0.10, 0.10};
  e2.colour = m2.colour = {0.10, 0.30, 0.75};
  th.colour = {0.15, 0.55, 0.20};
  e1.size_px = e2.size_px = mid ? 1.6 : 2.6;
  m1.size_px = m2.size_px = th.size_px = 2.6;
  if (mid) e1.dash_px = e2.dash_px = 6;
  std::vector<double> su, sd;
  for (const SectionPoint& p : sec.points) {
    if (p.branch != 0) continue;
    for (auto* x : {&e1, &e2, &m1, &m2, &th}) x->x.push_back(p.s_deformed);
    e1.y.push_back(p.major);
    e2.y.push_back(p.minor);
    m1.y.push_back(p.mid_major);
    m2.y.push_back(p.mid_minor);
    th.y.push_back(p.thickness_strain);
    su.push_back(p.s_undeformed);
    sd.push_back(p.s_deformed);
  }
  e1.label = mid ? "major, marked face" : "major";
  e2.label = mid ? "minor, marked face" : "minor";
  m1.label = "major, mid-surface";
  m2.label = "minor, mid-surface";
  th.label = "thickness strain (h/h0)";
  c.series = {e1, e2};
  if (mid) c.series.insert(c.series.end(), {m1, m2});
  c.series.push_back(th);
  c.footnote = "section_" + sec.name.substr(sec.name.find('_') + 1) +
               ".csv holds every point (both arc lengths, "
               "positions, all branches).";
  if (sec.n_branches > 1) c.footnote += " Branch 0 of " + std::to_string(sec.n_branches) + " shown.";
  if (sec.neck && sec.neck->ok && su.size() >= 2) {
    const NeckResult& n = *sec.neck;
    // The apex position (blank arc length) on the formed part's arc length.
    const auto it = std::lower_bound(su.begin(), su.end(), n.apex_position);
    const std::size_t k = std::clamp<std::size_t>(static_cast<std::size_t>(it - su.begin()), 1, su.size() - 1);
    const double t = (n.apex_position - su[k - 1]) / std::max(su[k] - su[k - 1], 1e-300);
    const double x = sd[k - 1] + t * (sd[k] - sd[k - 1]);
    render::ChartSeries apex;
    apex.x = {x, x};
    apex.y = {n.limit_major, n.limit_minor};
    apex.colour = {0, 0, 0};
    apex.size_px = 6;
    apex.label = "neck limit strains (ISO 12004-2 style): " + render::format_fixed(n.limit_major, 3) + ", " +
                 render::format_fixed(n.limit_minor, 3);
    c.series.push_back(apex);
  } else if (sec.neck && !sec.neck->ok) {
    c.footnote += " Neck not evaluated: " + sec.neck->message + ".";
  }
  c.include_origin = false;
  return c;
}

render::Chart principal_chart(const Results& r, PlotSummary& summary) {
  const MarkStrains& ms = r.marks;
  const FormingLimitCurve* flc = r.flc ? &*r.flc : nullptr;
  static const std::vector<double> kNoMargins;
  const std::vector<double>& margin = r.margins ? r.margins->margin : kNoMargins;
  const std::string w = measure_word(r.measure);
  render::Chart chart;
  chart.title = "Principal strains";
  chart.x_label = "minor strain (" + w + ")";
  chart.y_label = "major strain (" + w + ")";
  chart.equal_axes = true;
  chart.legend_title = "Key";
  const std::string uni =
      r.measure == StrainMeasure::kTrue ? "uniaxial tension (major = -2 minor)" : "uniaxial tension";
  const std::string shear = r.measure == StrainMeasure::kTrue ? "pure shear (major = -minor)" : "pure shear";
  chart.series.push_back(reference_line(1.0, r.measure, "equibiaxial (major = minor)", {0.85, 0.45, 0.0}, 9));
  chart.series.push_back(reference_line(0.0, r.measure, "plane strain (minor = 0)", {0.10, 0.55, 0.20}, 0));
  chart.series.push_back(reference_line(-0.5, r.measure, uni, {0.50, 0.22, 0.68}, 5));
  chart.series.push_back(reference_line(-1.0, r.measure, shear, {0.45, 0.33, 0.18}, 2.5));
  render::ChartSeries safe, beyond;
  safe.colour = {0.10, 0.27, 0.60};
  beyond.colour = {0.80, 0.0, 0.45};
  safe.size_px = beyond.size_px = 3.2;
  safe.opacity = 0.75;
  Index n = 0;
  for (std::size_t i = 0; i < ms.major.size(); ++i) {
    if (!std::isfinite(ms.major[i]) || !std::isfinite(ms.minor[i])) continue;
    ++n;
    const bool out = flc && i < margin.size() && std::isfinite(margin[i]) && margin[i] < 0;
    auto& s = out ? beyond : safe;
    s.x.push_back(ms.minor[i]);
    s.y.push_back(ms.major[i]);
  }
  summary.n_marks = n;
  safe.label = (flc ? "marks within the limit (" : "marks (") + std::to_string(safe.x.size()) + ")";
  const bool zones = flc && r.assessment && r.assessment->zone.size() == ms.major.size();
  if (!zones) chart.series.push_back(safe);
  if (flc) {
    render::ChartSeries curve;
    curve.style = render::ChartSeries::Style::kLine;
    curve.label = "forming limit curve";
    curve.colour = {0.85, 0.08, 0.08};
    curve.size_px = 3;
    curve.sets_range = false;
    curve.x = flc->minor;
    curve.y = flc->major;
    chart.series.push_back(curve);
    // Show the curve where the marks are (not its whole extent, which may dwarf them).
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto* s : {&safe, &beyond})
      for (double x : s->x) lo = std::min(lo, x), hi = std::max(hi, x);
    if (hi >= lo) {
      for (double x : {lo, hi}) chart.range_points.emplace_back(x, flc->major_at(x));
      for (std::size_t i = 0; i < flc->minor.size(); ++i)
        if (flc->minor[i] >= lo && flc->minor[i] <= hi) chart.range_points.emplace_back(flc->minor[i], flc->major[i]);
    }
    beyond.label = "marks beyond the limit (" + std::to_string(beyond.x.size()) + ")";
    if (!zones) chart.series.push_back(beyond);
  }
  if (zones) {
    // One colour per zone (the marks' zones of strains.csv) and the necking-risk line.
    const FlcAssessment& a = *r.assessment;
    render::ChartSeries risk;
    risk.style = render::ChartSeries::Style::kLine;
    risk.colour = zone_colour(Zone::kFailure);
    risk.opacity = 0.7;
    risk.size_px = 1.6;
    risk.dash_px = 8;
    risk.sets_range = false;
    risk.x = flc->minor;
    for (double y : flc->major) risk.y.push_back(y - a.options.necking_margin);
    risk.label = "curve - " + render::format_fixed(a.options.necking_margin, 2) + " (necking risk)";
    chart.series.push_back(risk);
    for (Zone z : kZones) {
      render::ChartSeries d;
      d.colour = zone_colour(z);
      d.size_px = 3.2;
      for (std::size_t i = 0; i < ms.major.size(); ++i)
        if (a.zone[i] == z) {
          d.x.push_back(ms.minor[i]);
          d.y.push_back(ms.major[i]);
        }
      if (d.x.empty()) continue;
      d.label = zone_label(z) + " (" + std::to_string(d.x.size()) + ")";
      chart.series.push_back(d);
    }
  }
  chart.subtitle =
      r.case_name + "  \xC2\xB7  " + measure_name(r.measure) + " strain  \xC2\xB7  " + std::to_string(n) + " marks";
  if (zones) chart.subtitle += "  \xC2\xB7  " + r.assessment->strains + " strains";
  chart.footnote = "One dot per analysed mark (strains.csv). Equal axes." +
                   std::string(flc ? " Forming limit curve from " + fs::path(flc->source).filename().string() +
                                         ", in " + w + " strain."
                                   : "");
  add_strain_paths(r.strain_paths, chart);
  return chart;
}

}  // namespace

// ---------------------------------------------------------------------------------------

PlotData plot_data(ResultsFolder folder, StrainMeasure measure) {
  PlotData d;
  d.source = folder.dir;
  d.case_name = case_name_of(folder.summary, folder.dir);
  d.units = units_of(folder.summary);
  d.fibre_angles = fibre_angles_of(folder.summary);
  d.measure = measure;
  d.marks = assessed_mark_strains(folder, measure);
  d.summary = std::move(folder.summary);
  d.has_surfaces = folder.has_surfaces;
  d.undeformed = std::move(folder.undeformed);
  d.deformed = std::move(folder.deformed);
  return d;
}

PlotData plot_data(const AnalysisResult& result, nlohmann::json summary, io::PolyMesh undeformed, io::PolyMesh deformed,
                   const std::string& dir, StrainMeasure measure) {
  PlotData d;
  d.source = dir;
  d.case_name = case_name_of(summary, dir);
  d.units = units_of(summary);
  d.fibre_angles = fibre_angles_of(summary);
  d.measure = measure;
  d.marks = mark_strains(result, measure);
  d.summary = std::move(summary);
  d.has_surfaces =
      undeformed.n_points() > 0 && !undeformed.polygons.empty() && deformed.n_points() == undeformed.n_points();
  d.undeformed = std::move(undeformed);
  d.deformed = std::move(deformed);
  return d;
}

render::Scene arrow_diagram(const PlotData& r, bool deformed, const PlotOptions& o) {
  if (!r.has_surfaces)
    throw InputError(r.source + ": no undeformed.vtp / deformed.vtp (triangle method?): no arrow diagram");
  const Sampling s = sample_surface(r.undeformed);
  return arrow_scene(r, s, arrow_scale(r, s, r.measure), deformed, o);
}

namespace {

// With fit_height, the height that frames the undeformed part seen from above (X to the
// right, Y up) at the picture's width: the frame takes about 72 % of the width (the
// legend panel the rest) and the title and footnote about 200 px at 1200 px. Not below
// 45 % of the width, which the colour bar and legend need.
PlotOptions fitted_to_part(const Results& r, PlotOptions o) {
  if (!o.fit_height || r.undeformed.n_points() == 0) return o;
  const Eigen::RowVector3d lo = r.undeformed.points.colwise().minCoeff(), hi = r.undeformed.points.colwise().maxCoeff();
  const Eigen::RowVector3d ext = hi - lo;
  if (!(ext[0] > 0) || !(ext[2] < 0.5 * std::max(ext[0], ext[1]))) return o;  // not a blank seen from above
  const double w = o.size.width;
  const double wanted = 0.72 * w * ext[1] / ext[0] + 200.0 * w / 1200.0;
  o.size.height = static_cast<int>(std::lround(std::clamp(wanted, 0.45 * w, static_cast<double>(o.size.height))));
  return o;
}

// The pictures of the fitted surfaces (surface method), in report order.
void draw_surface_pictures(const Results& r, const std::function<void(const std::string&, const render::Scene&)>& draw,
                           const PlotOptions& o, bool fibres) {
  const Sampling s = sample_surface(r.undeformed);
  const ArrowScale a = arrow_scale(r, s, r.measure);
  draw("arrows_undeformed.png", arrow_scene(r, s, a, false, o));
  draw("arrows_deformed.png", arrow_scene(r, s, a, true, o));
  const std::string file = r.source + "/deformed.vtp";
  const auto th = scalar_values(r.deformed, "thickness_change_pct", file);
  draw("thickness.png", contour_scene(r, th, "Thickness change", "Thickness change", "%", 1.0,
                                      "formed part, incompressible sheet, " + range_text(th, 1, " %", 1.0), o));
  const auto names = measure_fields(r.measure);
  const std::string w = measure_word(r.measure);
  const auto e1 = scalar_values(r.deformed, names[0], file);
  const auto e2 = scalar_values(r.deformed, names[1], file);
  render::Scene major =
      contour_scene(r, e1, "Major strain", "Major " + w + " strain", "-", 0.01,
                    measure_name(r.measure) + " strain, " + range_text(e1, decimals_for(e1), "", 0.01), o);
  draw_flagged_marks(r, major);
  draw("major_strain.png", major);
  draw("minor_strain.png",
       contour_scene(r, e2, "Minor strain", "Minor " + w + " strain", "-", 0.01,
                     measure_name(r.measure) + " strain, " + range_text(e2, decimals_for(e2), "", 0.01), o));
  if (!fibres) return;
  const auto sh = scalar_values(r.deformed, "shear_angle_deg", file);
  draw("shear_angle.png",
       contour_scene(
           r, sh, "Trellis shear angle", "Shear angle", "\xC2\xB0", 1.0,
           "initial angle between the fibre families minus the current one, " + range_text(sh, 1, "\xC2\xB0", 1.0), o));
  draw("fibres.png", fibre_scene(r, s, o));
}

// The interactive 3-D view of report.html (gsa/view3d.hpp), with the marks of the
// strains.csv just written (out_path) or else the folder's. A view that cannot be made
// leaves a note in the page, never a failed run.
void add_view3d(const PlotData& r, const std::function<std::string(const std::string&)>& out_path, ReportPage& page) {
  if (!r.has_surfaces) return;
  if (!view3d_available()) {
    page.view3d_note = view3d_library();
    return;
  }
  std::string csv = out_path("strains.csv");
  if (!std::filesystem::exists(csv)) csv = (std::filesystem::path(r.source) / "strains.csv").string();
  try {
    std::optional<io::CsvTable> strains;
    if (std::filesystem::exists(csv)) strains = io::read_csv(csv);
    page.view3d_html = make_view3d(r, strains ? &*strains : nullptr).html;
  } catch (const Error& e) {
    page.view3d_note = e.what();
  }
}

}  // namespace

PlotSummary write_pictures(const PlotData& r, const PlotOptions& o,
                           const std::function<std::string(const std::string&)>& out_path,
                           const PictureProgress& progress) {
  PlotSummary summary;
  const bool fibres = r.has_surfaces && find_field(r.deformed, "shear_angle_deg", 1) != nullptr;
  const bool zones = r.has_surfaces && r.assessment && r.flc;
  const int n_pictures =
      (r.has_surfaces ? (fibres ? 8 : 6) : 1) + (zones ? 1 : 0) + static_cast<int>(r.sections.size());
  const auto display = render::acquire_display();  // one display for all pictures
  int done = 0;
  if (progress) progress(done, n_pictures);
  const PlotOptions part = fitted_to_part(r, o);  // the pictures of the part; the strain plot keeps o.size
  auto draw = [&](const std::string& name, const render::Scene& scene) {
    render::write_png(scene, part.size, out_path(name));
    summary.pictures.push_back(name);
    if (progress) progress(++done, n_pictures);
  };
  if (r.has_surfaces) draw_surface_pictures(r, draw, o, fibres);
  {
    const render::Chart chart = principal_chart(r, summary);
    render::write_chart_png(chart, o.size, out_path("principal_strains.png"));
    // The strain plot reads best first after the arrows; keep report order stable.
    summary.pictures.push_back("principal_strains.png");
    if (progress) progress(++done, n_pictures);
  }
  if (zones) draw("zones.png", zone_scene(r, o));
  for (const Section& sec : r.sections) {
    render::write_chart_png(section_chart(r, sec), o.size, out_path(sec.name + ".png"));
    summary.pictures.push_back(sec.name + ".png");
    if (progress) progress(++done, n_pictures);
  }
  ReportPage page;
  page.case_name = r.case_name;
  page.measure = r.measure;
  page.pictures = summary.pictures;
  page.flc = r.margins ? &*r.margins : nullptr;
  add_view3d(r, out_path, page);
  write_report(out_path("report.html"), r.summary, page);
  return summary;
}

bool zones_belong_to(const nlohmann::json& summary, const FormingLimitCurve& flc, StrainMeasure measure) {
  if (!summary.is_object() || !summary.contains("forming_limit")) return false;
  const nlohmann::json& f = summary["forming_limit"];
  if (!f.is_object() || f.value("measure", std::string()) != measure_word(measure)) return false;
  const auto points = f.find("curve_points");
  if (points == f.end() || !points->is_object()) return false;
  try {
    return points->at("minor").get<std::vector<double>>() == flc.minor &&
           points->at("major").get<std::vector<double>>() == flc.major;
  } catch (const nlohmann::json::exception&) {
    return false;  // a summary edited by hand: treat as another curve
  }
}

Redrawn redraw_results_folder(const std::string& dir, StrainMeasure measure,
                              const std::optional<FormingLimitCurve>& flc, const PlotOptions& options,
                              const std::function<std::string(const std::string&)>& out_path,
                              const PictureProgress& progress) {
  ResultsFolder folder = read_results_folder(dir);
  Redrawn out;
  if (flc) {
    out.margins = flc_margins(*flc, assessed_mark_strains(folder, measure), measure);
    // The zones of gsa analyse belong to its curve: kept with the same curve, not shown
    // beside another one (the caller drops zones.png; summary.json keeps them, naming
    // their curve).
    const bool same = zones_belong_to(folder.summary, *flc, measure);
    write_strains_with_margin(folder, out_path("strains.csv"), *out.margins, same);
    if (!same && folder.summary.is_object()) folder.summary.erase("forming_limit");
  }
  PlotData data = plot_data(std::move(folder), measure);
  data.flc = flc;
  data.margins = out.margins;
  out.pictures = write_pictures(data, options, out_path, progress);
  return out;
}

}  // namespace sf::gsa

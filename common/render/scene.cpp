#include "common/render/scene.hpp"

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCleanPolyData.h>
#include <vtkContourFilter.h>
#include <vtkDoubleArray.h>
#include <vtkFeatureEdges.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "common/core/error.hpp"
#include "common/render/display.hpp"

namespace sf::render {

namespace {

constexpr int kSupersample = 2;       // render at twice the size and average
constexpr int kMaxRenderSide = 4096;  // ... unless that exceeds this many pixels
const Colour kDark{0.15, 0.15, 0.15};
const Colour kNanColour{0.72, 0.72, 0.72};

// ---------------------------------------------------------------------------------------
// Sizes relative to a 1200 x 900 picture.

// Text scales with the width, and with the height below 540 px per 1200 px of width, so a
// long part's pictures, cut to its proportions (gsa/plots.cpp), keep their text size.
double font_scale(const ImageSize& s) { return std::max(0.25, std::min(s.width / 1200.0, s.height / 540.0)); }
double font_px(double base, double f) { return std::max(8.0, std::round(base * f)); }

struct Fonts {
  double f, pad, title, subtitle, footnote, panel, panel_title, bar_width;
  explicit Fonts(const ImageSize& s)
      : f(font_scale(s)),
        pad(std::round(16 * f)),
        title(font_px(26, f)),
        subtitle(font_px(17, f)),
        footnote(font_px(14, f)),
        panel(font_px(16, f)),
        panel_title(font_px(17, f)),
        bar_width(std::round(26 * f)) {}
};

const ScalarColouring* colour_bar_field(const Scene& scene) {
  for (const Surface& s : scene.surfaces)
    if (s.colouring && s.colouring->colour_bar) return &*s.colouring;
  return nullptr;
}

bool any_nan(const std::vector<double>& v) {
  return std::any_of(v.begin(), v.end(), [](double x) { return std::isnan(x); });
}

std::string bar_title_line(const ScalarColouring& c) {
  return c.units.empty() ? c.title : c.title + " [" + c.units + "]";
}

// Colour bar title: one line when it fits the panel, else title and units on two lines.
std::vector<std::string> bar_title_lines(const ScalarColouring& c, double max_width, double size) {
  const std::string one = bar_title_line(c);
  if (c.units.empty() || text_extent(one, size, true)[0] <= max_width) return {one};
  return {c.title, "[" + c.units + "]"};
}

std::vector<std::string> edge_labels(const Bands& b) {
  std::vector<std::string> out;
  for (int k = 0; k <= b.n_bands; ++k) out.push_back(format_fixed(b.min + k * b.step, b.decimals));
  return out;
}

// Splits `text` into lines no wider than `width` pixels (at word boundaries; '\n' forces).
std::vector<std::string> wrap(const std::string& text, double width, double size) {
  std::vector<std::string> lines;
  std::stringstream paragraphs(text);
  std::string para;
  while (std::getline(paragraphs, para, '\n')) {
    std::stringstream words(para);
    std::string word, line;
    while (words >> word) {
      const std::string candidate = line.empty() ? word : line + " " + word;
      if (!line.empty() && text_extent(candidate, size)[0] > width) {
        lines.push_back(line);
        line = word;
      } else {
        line = candidate;
      }
    }
    lines.push_back(line);
  }
  return lines;
}

std::vector<std::string> footnote_lines(const Scene& scene, const ImageSize& size, const Fonts& ft) {
  if (scene.footnote.empty()) return {};
  return wrap(scene.footnote, size.width - 2 * ft.pad, ft.footnote);
}

// Width the right panel needs (0: no panel).
double panel_width(const Scene& scene, const ImageSize& size, const Fonts& ft) {
  double need = 0;
  if (const ScalarColouring* c = colour_bar_field(scene)) {
    double labels = 0;
    for (const auto& l : edge_labels(c->bands)) labels = std::max(labels, text_extent(l, ft.panel)[0]);
    need = std::max(need, ft.bar_width + 14 * ft.f + labels);
    need = std::max(need, std::min(text_extent(c->title, ft.panel_title, true)[0], 0.3 * size.width));
    if (any_nan(c->values)) need = std::max(need, 30 * ft.f + text_extent("no value", ft.panel)[0]);
  }
  if (!scene.legend.empty()) {
    need = std::max(need, text_extent(scene.legend_title, ft.panel_title, true)[0]);
    for (const LegendEntry& e : scene.legend) {
      const double symbol = e.kind == LegendEntry::Kind::kNone ? 0 : 44 * ft.f;
      const double text = text_extent(e.label, ft.panel)[0];
      need = std::max(need, symbol + 8 * ft.f + text);
    }
  }
  if (need <= 0) return 0;
  return std::clamp(need + 2.5 * ft.pad, 0.16 * size.width, 0.42 * size.width);
}

// ---------------------------------------------------------------------------------------
// Camera

struct ViewFrame {
  Vec3 toward_eye, up, right;
};

Vec3 mean_normal(const Scene& scene) {
  Vec3 n = Vec3::Zero();
  for (const Surface& s : scene.surfaces)
    for (const auto& poly : s.polygons) {
      if (poly.size() < 3) continue;
      for (std::size_t k = 0; k < poly.size(); ++k) {
        const Index a = poly[k], b = poly[(k + 1) % poly.size()];
        if (a < 0 || b < 0 || a >= s.points.rows() || b >= s.points.rows()) continue;
        n += s.points.row(a).transpose().cross(s.points.row(b).transpose());
      }
    }
  return n;
}

ViewFrame view_frame(const Scene& scene) {
  Vec3 d = Vec3::UnitZ();
  switch (scene.view.kind) {
    case ViewKind::kAuto: {
      const Vec3 n = mean_normal(scene);
      if (n.norm() > 0) d = n.normalized();
      if (d.z() < 0 || (d.z() == 0 && (d.y() < 0 || (d.y() == 0 && d.x() < 0)))) d = -d;
      break;
    }
    case ViewKind::kTop:
      d = Vec3::UnitZ();
      break;
    case ViewKind::kFront:
      d = -Vec3::UnitY();
      break;
    case ViewKind::kSide:
      d = Vec3::UnitX();
      break;
    case ViewKind::kIso:
      d = Vec3(1, -1, 1).normalized();
      break;
    case ViewKind::kDirection:
      d = scene.view.direction.norm() > 0 ? scene.view.direction.normalized() : Vec3::UnitZ();
      break;
  }
  // Up: +Y seen from above or below, else +Z; projected onto the view plane.
  Vec3 up = std::abs(d.z()) > 0.7 ? Vec3::UnitY() : Vec3::UnitZ();
  up -= up.dot(d) * d;
  if (up.norm() < 1e-6) {
    up = Vec3::UnitX() - d.x() * d;
  }
  up.normalize();
  return {d, up, up.cross(d).normalized()};
}

// ---------------------------------------------------------------------------------------
// Geometry helpers

struct PolyBuilder {
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> polys;
  vtkNew<vtkCellArray> lines;
  vtkNew<vtkUnsignedCharArray> colours;
  PolyBuilder() {
    points->SetDataTypeToDouble();
    colours->SetNumberOfComponents(4);
    colours->SetName("colours");
  }
  vtkIdType add(const Vec3& p) { return points->InsertNextPoint(p.x(), p.y(), p.z()); }
  vtkIdType add(const Vec2& p) { return points->InsertNextPoint(p.x(), p.y(), 0.0); }
  template <class P>
  void polygon(const std::vector<P>& pts, const Colour& c, double opacity) {
    std::vector<vtkIdType> ids;
    for (const auto& p : pts) ids.push_back(add(p));
    polys->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
    const unsigned char rgba[4] = {to8(c.r), to8(c.g), to8(c.b), to8(opacity)};
    colours->InsertNextTypedTuple(rgba);
  }
  static unsigned char to8(double v) { return static_cast<unsigned char>(std::lround(std::clamp(v, 0.0, 1.0) * 255)); }
  vtkSmartPointer<vtkPolyData> data(bool with_colours) {
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    pd->SetPoints(points);
    pd->SetPolys(polys);
    if (lines->GetNumberOfCells() > 0) pd->SetLines(lines);
    if (with_colours) pd->GetCellData()->SetScalars(colours);
    return pd;
  }
};

// A 2-D polyline as filled quads (dashed if asked), round-ish joints for thick lines.
void stroke(PolyBuilder& b, const Shape2D& s) {
  const double w = std::max(0.5, s.width_px);
  auto quad = [&](const Vec2& p, const Vec2& q) {
    const Vec2 t = q - p;
    const double len = t.norm();
    if (len <= 1e-9) return;
    const Vec2 n = Vec2(-t.y(), t.x()) / len * (w / 2);
    b.polygon(std::vector<Vec2>{p - n, q - n, q + n, p + n}, s.colour, s.opacity);
  };
  auto dot = [&](const Vec2& c) {
    std::vector<Vec2> pts;
    for (int k = 0; k < 8; ++k) pts.emplace_back(c + w / 2 * Vec2(std::cos(k * kPi / 4), std::sin(k * kPi / 4)));
    b.polygon(pts, s.colour, s.opacity);
  };
  const double period = 2 * s.dash_px;
  double start = 0;  // distance along the polyline where the segment starts
  for (std::size_t k = 0; k + 1 < s.points.size(); ++k) {
    const Vec2 p = s.points[k], q = s.points[k + 1];
    const double len = (q - p).norm();
    if (!(len > 1e-9) || !std::isfinite(len)) continue;
    if (s.dash_px < 0.5) {  // solid (dashes under half a pixel would not show)
      quad(p, q);
      if (w >= 2.5 && k + 2 < s.points.size()) dot(q);
    } else {
      // Dashes are the intervals [m period, m period + dash] of the distance along the line.
      const Vec2 t = (q - p) / len;
      const double end = start + len;
      for (double m = std::floor(start / period); m * period < end; m += 1) {
        const double lo = std::max(start, m * period), hi = std::min(end, m * period + s.dash_px);
        if (hi > lo) quad(p + (lo - start) * t, p + (hi - start) * t);
      }
    }
    start += len;
  }
}

void fill_overlay(PolyBuilder& b, const Shape2D& s) {
  if (s.filled) {
    if (s.points.size() >= 3) b.polygon(s.points, s.colour, s.opacity);
  } else {
    stroke(b, s);
  }
}

// A flat arrow (or segment) in the plane facing the eye.
void glyph_polygons(PolyBuilder& b, const Vec3& tail, const Vec3& head, bool arrow, double width, double head_length,
                    double head_width, const Vec3& toward_eye, const Vec3& lift, const Colour& c) {
  const Vec3 d = head - tail;
  const double len = d.norm();
  if (len <= 1e-12 || !d.allFinite()) return;
  const Vec3 u = d / len;
  Vec3 side = toward_eye.cross(u);
  if (side.norm() < 1e-6) side = u.unitOrthogonal();
  side.normalize();
  const Vec3 t = tail + lift, h = head + lift;
  if (!arrow) {
    b.polygon(std::vector<Vec3>{t - side * width / 2, h - side * width / 2, h + side * width / 2, t + side * width / 2},
              c, 1.0);
    return;
  }
  const double hl = std::min(head_length, 0.6 * len);
  const double hw = head_width * hl / head_length;
  const Vec3 base = h - u * hl;
  if (len - hl > 1e-12)
    b.polygon(
        std::vector<Vec3>{t - side * width / 2, base - side * width / 2, base + side * width / 2, t + side * width / 2},
        c, 1.0);
  b.polygon(std::vector<Vec3>{base - side * hw / 2, h, base + side * hw / 2}, c, 1.0);
}

// The same arrow in pixels (legend).
void arrow_2d(PolyBuilder& b, const Vec2& tail, const Vec2& head, double width, double head_length, double head_width,
              const Colour& c) {
  const Vec2 d = head - tail;
  const double len = d.norm();
  if (len <= 1e-9) return;
  const Vec2 u = d / len, n(-u.y(), u.x());
  const double hl = std::min(head_length, 0.6 * len);
  const double hw = head_width * hl / head_length;
  const Vec2 base = head - u * hl;
  b.polygon(std::vector<Vec2>{tail - n * width / 2, base - n * width / 2, base + n * width / 2, tail + n * width / 2},
            c, 1.0);
  b.polygon(std::vector<Vec2>{base - n * hw / 2, head, base + n * hw / 2}, c, 1.0);
}

// ---------------------------------------------------------------------------------------
// VTK actors

void check_surface(const Surface& s, std::size_t which) {
  const Index n = s.points.rows();
  for (const auto& poly : s.polygons) {
    if (poly.size() < 3)
      throw std::invalid_argument("render: surface " + std::to_string(which) +
                                  " has a polygon with fewer than 3 points");
    for (Index i : poly)
      if (i < 0 || i >= n)
        throw std::invalid_argument("render: surface " + std::to_string(which) + ": point index " + std::to_string(i) +
                                    " out of range");
  }
  for (const auto& line : s.lines)
    for (Index i : line)
      if (i < 0 || i >= n)
        throw std::invalid_argument("render: surface " + std::to_string(which) + ": line point index out of range");
  if (s.colouring && static_cast<Index>(s.colouring->values.size()) != n)
    throw std::invalid_argument("render: surface " + std::to_string(which) + ": " +
                                std::to_string(s.colouring->values.size()) + " values for " + std::to_string(n) +
                                " points");
}

vtkSmartPointer<vtkPoints> to_vtk_points(const Points3& p) {
  auto pts = vtkSmartPointer<vtkPoints>::New();
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(p.rows());
  for (Index i = 0; i < p.rows(); ++i) pts->SetPoint(i, p(i, 0), p(i, 1), p(i, 2));
  return pts;
}

vtkSmartPointer<vtkCellArray> to_vtk_cells(const std::vector<std::vector<Index>>& cells) {
  auto ca = vtkSmartPointer<vtkCellArray>::New();
  std::vector<vtkIdType> ids;
  for (const auto& c : cells) {
    ids.assign(c.begin(), c.end());
    ca->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  return ca;
}

vtkSmartPointer<vtkActor> line_actor(vtkAlgorithmOutput* port, vtkPolyData* data, const Colour& c, double width) {
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  if (port)
    mapper->SetInputConnection(port);
  else
    mapper->SetInputData(data);
  mapper->ScalarVisibilityOff();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(c.r, c.g, c.b);
  actor->GetProperty()->LightingOff();
  actor->GetProperty()->SetLineWidth(static_cast<float>(width));
  mapper->SetRelativeCoincidentTopologyLineOffsetParameters(-1.0, -2.0);
  return actor;
}

void add_surface(vtkRenderer* ren, const Surface& s, double f, std::vector<vtkSmartPointer<vtkObject>>& keep) {
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(to_vtk_points(s.points));
  pd->SetPolys(to_vtk_cells(s.polygons));
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  if (s.colouring) {
    const ScalarColouring& c = *s.colouring;
    auto values = vtkSmartPointer<vtkDoubleArray>::New();
    values->SetName("values");
    values->SetNumberOfValues(static_cast<vtkIdType>(c.values.size()));
    for (std::size_t i = 0; i < c.values.size(); ++i) values->SetValue(static_cast<vtkIdType>(i), c.values[i]);
    pd->GetPointData()->SetScalars(values);
    auto lut = vtkSmartPointer<vtkLookupTable>::New();
    const int n = c.banded ? std::max(1, c.bands.n_bands) : 256;
    lut->SetNumberOfTableValues(n);
    lut->SetTableRange(c.bands.min, c.bands.max);
    lut->Build();
    for (int i = 0; i < n; ++i) {
      const Colour col = colour_at(c.map, (i + 0.5) / n);
      lut->SetTableValue(i, col.r, col.g, col.b, 1.0);
    }
    lut->SetNanColor(kNanColour.r, kNanColour.g, kNanColour.b, 1.0);
    mapper->SetLookupTable(lut);
    mapper->UseLookupTableScalarRangeOff();
    mapper->SetScalarRange(c.bands.min, c.bands.max);
    mapper->SetScalarModeToUsePointData();
    mapper->ScalarVisibilityOn();
    mapper->InterpolateScalarsBeforeMappingOn();  // crisp band edges inside each polygon
    keep.push_back(lut);
  } else {
    mapper->ScalarVisibilityOff();
  }
  // Merge points that coincide (gsa writes each element with its own points), so that
  // normals are smooth across element edges and the outline is the true boundary.
  double bounds[6];
  pd->GetBounds(bounds);
  const double diag =
      std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) + (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) +
                (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
  auto clean = vtkSmartPointer<vtkCleanPolyData>::New();
  clean->SetInputData(pd);
  clean->PointMergingOn();
  clean->ToleranceIsAbsoluteOn();
  clean->SetAbsoluteTolerance(1e-9 * std::max(diag, 1e-30));
  clean->ConvertPolysToLinesOff();
  clean->ConvertLinesToPointsOff();
  clean->ConvertStripsToPolysOff();
  keep.push_back(clean);
  if (s.shading) {
    auto normals = vtkSmartPointer<vtkPolyDataNormals>::New();
    normals->SetInputConnection(clean->GetOutputPort());
    normals->SplittingOff();
    normals->ConsistencyOn();
    normals->ComputePointNormalsOn();
    normals->ComputeCellNormalsOff();
    mapper->SetInputConnection(normals->GetOutputPort());
    keep.push_back(normals);
  } else {
    mapper->SetInputConnection(clean->GetOutputPort());
  }
  mapper->SetRelativeCoincidentTopologyPolygonOffsetParameters(2.0, 2.0);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  vtkProperty* prop = actor->GetProperty();
  prop->SetColor(s.colour.r, s.colour.g, s.colour.b);
  if (s.shading) {
    prop->SetAmbient(0.7);
    prop->SetDiffuse(0.3);
  } else {
    prop->SetAmbient(1.0);
    prop->SetDiffuse(0.0);
  }
  prop->SetSpecular(0.0);
  ren->AddActor(actor);

  if (!s.lines.empty()) {
    auto lp = vtkSmartPointer<vtkPolyData>::New();
    lp->SetPoints(pd->GetPoints());
    lp->SetLines(to_vtk_cells(s.lines));
    ren->AddActor(line_actor(nullptr, lp, s.line_colour, std::max(1.0, 1.0 * f)));
  }
  if (s.colouring && s.colouring->iso_lines && s.colouring->bands.n_bands > 1) {
    // Contour only polygons whose points all have values.
    const auto& v = s.colouring->values;
    std::vector<std::vector<Index>> valid;
    for (const auto& poly : s.polygons)
      if (std::all_of(poly.begin(), poly.end(), [&](Index i) { return std::isfinite(v[i]); })) valid.push_back(poly);
    auto cp = vtkSmartPointer<vtkPolyData>::New();
    cp->SetPoints(pd->GetPoints());
    cp->SetPolys(to_vtk_cells(valid));
    cp->GetPointData()->SetScalars(pd->GetPointData()->GetScalars());
    auto contour = vtkSmartPointer<vtkContourFilter>::New();
    contour->SetInputData(cp);
    const Bands& b = s.colouring->bands;
    for (int k = 1; k < b.n_bands; ++k) contour->SetValue(k - 1, b.min + k * b.step);
    contour->ComputeScalarsOff();
    contour->ComputeNormalsOff();
    keep.push_back(contour);
    ren->AddActor(line_actor(contour->GetOutputPort(), nullptr, Colour{0.2, 0.2, 0.2}, std::max(1.0, 1.2 * f)));
  }
  if (s.outline && !s.polygons.empty()) {
    auto edges = vtkSmartPointer<vtkFeatureEdges>::New();
    edges->SetInputConnection(clean->GetOutputPort());
    edges->BoundaryEdgesOn();
    edges->FeatureEdgesOff();
    edges->NonManifoldEdgesOff();
    edges->ManifoldEdgesOff();
    edges->ColoringOff();
    keep.push_back(edges);
    ren->AddActor(line_actor(edges->GetOutputPort(), nullptr, Colour{0.25, 0.25, 0.25}, std::max(1.0, 1.5 * f)));
  }
}

void configure_text(vtkTextProperty* p, const Text2D& t) {
  p->SetFontFamilyToArial();
  p->SetFontSize(static_cast<int>(std::lround(t.size_px)));
  p->SetColor(t.colour.r, t.colour.g, t.colour.b);
  p->SetBold(t.bold ? 1 : 0);
  p->SetItalic(0);
  p->SetShadow(0);
  p->SetOrientation(t.angle_deg);
  p->SetJustification(t.halign < 0 ? VTK_TEXT_LEFT : t.halign == 0 ? VTK_TEXT_CENTERED : VTK_TEXT_RIGHT);
  p->SetVerticalJustification(t.valign < 0 ? VTK_TEXT_BOTTOM : t.valign == 0 ? VTK_TEXT_CENTERED : VTK_TEXT_TOP);
}

// Everything the renderer adds in 2-D: title band, colour bar, legend.
struct Overlay {
  PolyBuilder shapes;
  std::vector<Text2D> texts;
};

struct ResolvedGlyph {
  double width, head_length, head_width, lift;
};

ResolvedGlyph resolve_glyph(const GlyphSet& g, double part_size) {
  ResolvedGlyph r{};
  r.width = g.width > 0 ? g.width : part_size / 250.0;
  r.head_length = g.head_length > 0 ? g.head_length : 4 * r.width;
  r.head_width = g.head_width > 0 ? g.head_width : 3.2 * r.width;
  r.lift = g.lift > 0 ? g.lift : part_size * 2e-3;
  return r;
}

void draw_colour_bar(Overlay& o, const ScalarColouring& c, const Fonts& ft, double x0, double top, double bottom,
                     double panel_w) {
  const auto lines = bar_title_lines(c, panel_w - ft.pad, ft.panel_title);
  double y = top;
  for (const auto& l : lines) {
    o.texts.push_back({l, Vec2(x0, y), ft.panel_title, kDark, -1, 1, true, 0});
    y -= ft.panel_title * 1.35;
  }
  const double bar_top = y - 8 * ft.f;
  double bar_bottom = std::max(bottom, bar_top - 0.62 * (top - bottom));
  const bool nan = any_nan(c.values);
  if (nan) bar_bottom = std::max(bar_bottom, bottom + 40 * ft.f);
  const double h = bar_top - bar_bottom;
  if (h <= 10) return;
  const Bands& b = c.bands;
  const int n_slices = c.banded ? std::max(1, b.n_bands) : 128;
  const double x1 = x0 + ft.bar_width;
  for (int i = 0; i < n_slices; ++i) {
    const double ya = bar_bottom + h * i / n_slices, yb = bar_bottom + h * (i + 1) / n_slices;
    const Colour col = colour_at(c.map, (i + 0.5) / n_slices);
    o.shapes.polygon(std::vector<Vec2>{{x0, ya}, {x1, ya}, {x1, yb}, {x0, yb}}, col, 1.0);
  }
  Shape2D frame;
  frame.filled = false;
  frame.colour = kDark;
  frame.width_px = std::max(1.0, ft.f);
  frame.points = {{x0, bar_bottom}, {x1, bar_bottom}, {x1, bar_top}, {x0, bar_top}, {x0, bar_bottom}};
  stroke(o.shapes, frame);
  // Labels at band edges; every k-th when crowded, always through 0 on a symmetric bar.
  const int n = std::max(1, b.n_bands);
  int stride = 1;
  while (h / n * stride < 1.35 * ft.panel && stride < n) ++stride;
  int origin = 0;
  for (int k = 0; k <= n; ++k)
    if (std::abs(b.min + k * b.step) < 1e-9 * b.step) origin = k;
  const auto labels = edge_labels(b);
  for (int k = 0; k <= n; ++k) {
    if ((k - origin) % stride != 0) continue;
    const double yk = bar_bottom + h * k / n;
    Shape2D tick;
    tick.filled = false;
    tick.colour = kDark;
    tick.width_px = std::max(1.0, ft.f);
    tick.points = {{x1, yk}, {x1 + 5 * ft.f, yk}};
    stroke(o.shapes, tick);
    o.texts.push_back({labels[k], Vec2(x1 + 8 * ft.f, yk), ft.panel, kDark, -1, 0, false, 0});
  }
  if (nan) {
    const double s = 16 * ft.f, yb = bar_bottom - 24 * ft.f - s;
    o.shapes.polygon(std::vector<Vec2>{{x0, yb}, {x0 + s, yb}, {x0 + s, yb + s}, {x0, yb + s}}, kNanColour, 1.0);
    o.texts.push_back({"no value", Vec2(x0 + s + 8 * ft.f, yb + s / 2), ft.panel, kDark, -1, 0, false, 0});
  }
}

double draw_legend(Overlay& o, const Scene& scene, const Fonts& ft, double x0, double top, double panel_w,
                   double pixels_per_unit, const std::vector<ResolvedGlyph>& glyphs) {
  double y = top;
  if (!scene.legend_title.empty()) {
    o.texts.push_back({scene.legend_title, Vec2(x0, y), ft.panel_title, kDark, -1, 1, true, 0});
    y -= ft.panel_title * 1.6;
  }
  const double row = std::max(26 * ft.f, ft.panel * 1.6);
  const double sym = 36 * ft.f;
  for (const LegendEntry& e : scene.legend) {
    const double yc = y - row / 2;
    double text_x = x0 + sym + 8 * ft.f;
    switch (e.kind) {
      case LegendEntry::Kind::kSwatch: {
        const double s = 16 * ft.f;
        o.shapes.polygon(
            std::vector<Vec2>{{x0, yc - s / 2}, {x0 + s, yc - s / 2}, {x0 + s, yc + s / 2}, {x0, yc + s / 2}}, e.colour,
            1.0);
        break;
      }
      case LegendEntry::Kind::kLine: {
        Shape2D l;
        l.filled = false;
        l.colour = e.colour;
        l.width_px = e.width_px;
        l.dash_px = e.dash_px;
        l.points = {{x0, yc}, {x0 + sym, yc}};
        stroke(o.shapes, l);
        break;
      }
      case LegendEntry::Kind::kDot: {
        std::vector<Vec2> pts;
        for (int k = 0; k < 16; ++k)
          pts.emplace_back(Vec2(x0 + sym / 2, yc) + e.width_px * Vec2(std::cos(k * kPi / 8), std::sin(k * kPi / 8)));
        o.shapes.polygon(pts, e.colour, 1.0);
        break;
      }
      case LegendEntry::Kind::kArrow: {
        double w = 2.5 * ft.f, hl = 10 * ft.f, hw = 8 * ft.f;
        double len = sym;
        if (e.glyph_set >= 0 && e.glyph_set < static_cast<int>(glyphs.size()) && pixels_per_unit > 0) {
          const ResolvedGlyph& g = glyphs[static_cast<std::size_t>(e.glyph_set)];
          w = std::max(1.0, g.width * pixels_per_unit);
          hl = g.head_length * pixels_per_unit;
          hw = g.head_width * pixels_per_unit;
        }
        if (e.model_length > 0 && pixels_per_unit > 0) len = e.model_length * pixels_per_unit;
        if (len > sym) {
          // A long scale arrow gets its own line; its label goes below it.
          arrow_2d(o.shapes, Vec2(x0, yc), Vec2(x0 + len, yc), w, hl, hw, e.colour);
          y -= row * 0.8;
          text_x = x0;
        } else {
          arrow_2d(o.shapes, Vec2(x0 + (sym - len) / 2, yc), Vec2(x0 + (sym + len) / 2, yc), w, hl, hw, e.colour);
        }
        break;
      }
      case LegendEntry::Kind::kNone:
        text_x = x0;
        break;
    }
    o.texts.push_back({e.label, Vec2(text_x, y - row / 2), ft.panel, kDark, -1, 0, false, 0});
    y -= row;
  }
  (void)panel_w;
  return y;
}

std::string temp_path_for(const std::string& path) { return path + ".tmp-" + std::to_string(::getpid()) + ".png"; }

}  // namespace

// ---------------------------------------------------------------------------------------

Layout layout_of(const Scene& scene, const ImageSize& size) {
  const Fonts ft(size);
  Layout l;
  l.scale = ft.f;
  l.title_band = ft.pad;
  if (!scene.title.empty()) l.title_band += ft.title * 1.3;
  if (!scene.subtitle.empty()) l.title_band += ft.subtitle * 1.45;
  l.title_band += ft.pad / 2;
  const auto foot = footnote_lines(scene, size, ft);
  l.footnote_band = foot.empty() ? 0 : ft.footnote * (1.0 + 1.3 * static_cast<double>(foot.size()));
  l.panel_left = size.width - panel_width(scene, size, ft);
  l.frame = {ft.pad, l.footnote_band + ft.pad, l.panel_left - ft.pad, size.height - l.title_band - ft.pad / 2};
  if (scene.frame_px) l.frame = *scene.frame_px;
  return l;
}

Vec2 text_extent(const std::string& text, double size_px, bool bold) {
  if (text.empty()) return Vec2::Zero();
  vtkTextRenderer* tr = vtkTextRenderer::GetInstance();
  vtkNew<vtkTextProperty> p;
  Text2D t;
  t.size_px = size_px;
  t.bold = bold;
  configure_text(p, t);
  int bbox[4] = {0, 0, 0, 0};
  if (tr == nullptr || !tr->GetBoundingBox(p, text, bbox, 72))
    return Vec2(0.6 * size_px * static_cast<double>(text.size()), size_px);
  return Vec2(bbox[1] - bbox[0] + 1, bbox[3] - bbox[2] + 1);
}

namespace {

// One off-screen window for every picture drawn while a display guard lives. A new window
// per picture creates a GL context and allocates and clears its framebuffers afresh: that
// was a fifth of `simform plot`'s processor time (memset of new framebuffer textures) plus
// the page faults behind it. The guard holds the window and destroys it before its display.
struct ReusedWindow {
  vtkSmartPointer<vtkRenderWindow> win = vtkSmartPointer<vtkRenderWindow>::New();
  ReusedWindow() {
    win->SetOffScreenRendering(1);
    win->SetMultiSamples(0);
  }
  ~ReusedWindow() { win->Finalize(); }
  ReusedWindow(const ReusedWindow&) = delete;
  ReusedWindow& operator=(const ReusedWindow&) = delete;
};

vtkRenderWindow* window_for(DisplayGuard& guard) {
  static std::weak_ptr<ReusedWindow> cached;
  static const DisplayGuard* owner = nullptr;
  std::shared_ptr<ReusedWindow> w = cached.lock();
  if (!w || owner != &guard) {
    w = std::make_shared<ReusedWindow>();
    guard.hold(w);
    cached = w;
    owner = &guard;
  }
  return w->win;
}

// Renders the scene at `size` into `image` (RGB, VTK's bottom-up rows) in `win`.
Framing render_image(const Scene& scene, const ImageSize& size, vtkRenderWindow* win, vtkImageData* image) {
  const Fonts ft(size);
  const Layout layout = layout_of(scene, size);
  const ViewFrame vf = view_frame(scene);

  Framing framing;
  framing.width = size.width;
  framing.height = size.height;
  framing.right = vf.right;
  framing.up = vf.up;
  framing.toward_eye = vf.toward_eye;

  // Extent of the 3-D content in the view plane.
  double r0 = HUGE_VAL, r1 = -HUGE_VAL, u0 = HUGE_VAL, u1 = -HUGE_VAL, d0 = HUGE_VAL, d1 = -HUGE_VAL;
  auto extend = [&](const Vec3& p) {
    if (!p.allFinite()) return;
    r0 = std::min(r0, p.dot(vf.right));
    r1 = std::max(r1, p.dot(vf.right));
    u0 = std::min(u0, p.dot(vf.up));
    u1 = std::max(u1, p.dot(vf.up));
    d0 = std::min(d0, p.dot(vf.toward_eye));
    d1 = std::max(d1, p.dot(vf.toward_eye));
  };
  for (const Surface& s : scene.surfaces)
    for (Index i = 0; i < s.points.rows(); ++i) extend(s.points.row(i).transpose());
  for (const GlyphSet& g : scene.glyphs)
    for (std::size_t i = 0; i < g.tails.size(); ++i) {
      extend(g.tails[i]);
      extend(g.heads[i]);
    }
  const bool has_3d = r1 >= r0;
  double part_size = 1;
  // Lines drawn on a surface (iso-lines, outline, element edges) stay in front of it.
  vtkMapper::SetResolveCoincidentTopologyToPolygonOffset();
  vtkNew<vtkRenderer> ren;
  ren->SetBackground(1, 1, 1);
  std::vector<vtkSmartPointer<vtkObject>> keep;
  std::vector<ResolvedGlyph> resolved;
  if (has_3d) {
    const auto& fr = layout.frame;
    const double fw = std::max(1.0, fr[2] - fr[0]), fh = std::max(1.0, fr[3] - fr[1]);
    part_size = std::max({r1 - r0, u1 - u0, 1e-9});
    const double wr = std::max(r1 - r0, 1e-6 * part_size), wu = std::max(u1 - u0, 1e-6 * part_size);
    const double s = std::min(fw / wr, fh / wu);
    const Vec3 centre = vf.right * (r0 + r1) / 2 + vf.up * (u0 + u1) / 2 + vf.toward_eye * (d0 + d1) / 2;
    const double tx = (fr[0] + fr[2]) / 2, ty = (fr[1] + fr[3]) / 2;
    const Vec3 focal = centre - vf.right * (tx - size.width / 2.0) / s - vf.up * (ty - size.height / 2.0) / s;
    framing.pixels_per_unit = s;
    framing.focal = focal;
    vtkCamera* cam = ren->GetActiveCamera();
    cam->ParallelProjectionOn();
    cam->SetFocalPoint(focal.x(), focal.y(), focal.z());
    const double dist = (d1 - d0) + 2 * part_size + 1;
    const Vec3 eye = focal + vf.toward_eye * dist;
    cam->SetPosition(eye.x(), eye.y(), eye.z());
    cam->SetViewUp(vf.up.x(), vf.up.y(), vf.up.z());
    cam->SetParallelScale(size.height / (2 * s));
    cam->SetClippingRange(0.01 * part_size, dist + (d1 - d0) + 2 * part_size);

    for (const Surface& surf : scene.surfaces) add_surface(ren, surf, ft.f, keep);
    for (const GlyphSet& g : scene.glyphs) {
      const ResolvedGlyph rg = resolve_glyph(g, part_size);
      resolved.push_back(rg);
      PolyBuilder b;
      for (std::size_t i = 0; i < g.tails.size(); ++i)
        glyph_polygons(b, g.tails[i], g.heads[i], g.kind == GlyphSet::Kind::kArrow, rg.width, rg.head_length,
                       rg.head_width, vf.toward_eye, vf.toward_eye * rg.lift, g.colour);
      auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
      mapper->SetInputData(b.data(false));
      mapper->ScalarVisibilityOff();
      auto actor = vtkSmartPointer<vtkActor>::New();
      actor->SetMapper(mapper);
      actor->GetProperty()->SetColor(g.colour.r, g.colour.g, g.colour.b);
      actor->GetProperty()->LightingOff();
      ren->AddActor(actor);
    }
  }

  // Overlay: title band, colour bar and legend in the right panel, the scene's own shapes.
  Overlay o;
  double y_title = size.height - ft.pad;
  if (!scene.title.empty()) {
    o.texts.push_back({scene.title, Vec2(size.width / 2.0, y_title), ft.title, kDark, 0, 1, true, 0});
    y_title -= ft.title * 1.3;
  }
  if (!scene.subtitle.empty())
    o.texts.push_back(
        {scene.subtitle, Vec2(size.width / 2.0, y_title), ft.subtitle, Colour{0.3, 0.3, 0.3}, 0, 1, false, 0});
  {
    const auto foot = footnote_lines(scene, size, ft);
    for (std::size_t i = 0; i < foot.size(); ++i)
      o.texts.push_back({foot[i], Vec2(ft.pad, ft.footnote * (0.7 + 1.3 * static_cast<double>(foot.size() - 1 - i))),
                         ft.footnote, Colour{0.35, 0.35, 0.35}, -1, -1, false, 0});
  }
  if (layout.panel_left < size.width) {
    const double x0 = layout.panel_left + ft.pad * 0.5;
    const double panel_w = size.width - layout.panel_left - ft.pad;
    double top = size.height - layout.title_band - ft.pad / 2;
    const double bottom = layout.footnote_band + 3 * ft.pad;
    if (!scene.legend.empty()) {
      top = draw_legend(o, scene, ft, x0, top, panel_w, framing.pixels_per_unit, resolved) - ft.pad;
    }
    if (const ScalarColouring* c = colour_bar_field(scene)) draw_colour_bar(o, *c, ft, x0, top, bottom, panel_w);
  }
  for (const Shape2D& s : scene.shapes) fill_overlay(o.shapes, s);
  for (const Text2D& t : scene.texts) o.texts.push_back(t);

  if (o.shapes.polys->GetNumberOfCells() > 0) {
    auto mapper = vtkSmartPointer<vtkPolyDataMapper2D>::New();
    mapper->SetInputData(o.shapes.data(true));
    mapper->SetScalarModeToUseCellData();
    mapper->SetColorModeToDirectScalars();
    mapper->ScalarVisibilityOn();
    auto actor = vtkSmartPointer<vtkActor2D>::New();
    actor->SetMapper(mapper);
    ren->AddActor2D(actor);
  }
  for (const Text2D& t : o.texts) {
    if (t.text.empty()) continue;
    auto actor = vtkSmartPointer<vtkTextActor>::New();
    actor->SetInput(t.text.c_str());
    configure_text(actor->GetTextProperty(), t);
    actor->SetPosition(t.at.x(), t.at.y());
    ren->AddActor2D(actor);
  }

  win->SetSize(size.width, size.height);
  win->AddRenderer(ren);
  win->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(win);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();

  image->DeepCopy(grab->GetOutput());
  win->RemoveRenderer(ren);  // releases the scene's graphics resources; the window stays
  return framing;
}

// The scene with its pixel-sized content scaled by `k` (for supersampling).
Scene scaled_overlay(const Scene& scene, double k) {
  Scene s = scene;
  for (Shape2D& sh : s.shapes) {
    for (Vec2& p : sh.points) p *= k;
    sh.width_px *= k;
    sh.dash_px *= k;
  }
  for (Text2D& t : s.texts) {
    t.at *= k;
    t.size_px *= k;
  }
  for (LegendEntry& e : s.legend) {
    e.width_px *= k;
    e.dash_px *= k;
  }
  if (s.frame_px)
    for (double& v : *s.frame_px) v *= k;
  return s;
}

}  // namespace

Framing write_png(const Scene& scene, const ImageSize& size, const std::string& path) {
  if (size.width < 16 || size.height < 16) throw std::invalid_argument("render: image size too small");
  for (std::size_t i = 0; i < scene.surfaces.size(); ++i) check_surface(scene.surfaces[i], i);
  for (const GlyphSet& g : scene.glyphs)
    if (g.tails.size() != g.heads.size())
      throw std::invalid_argument("render: glyph set with different numbers of tails and heads");

  static std::mutex rendering;  // one window, one picture at a time
  const std::lock_guard<std::mutex> lock(rendering);
  const auto display = acquire_display();  // before any window exists
  // Supersampling: render at k times the size (with 4x multisampling) and average k x k
  // pixel blocks, for smooth lines, arrow heads and text.
  const int k = std::max(size.width, size.height) * kSupersample <= kMaxRenderSide ? kSupersample : 1;
  const ImageSize big{size.width * k, size.height * k};
  vtkNew<vtkImageData> rendered;
  Framing framing = render_image(k == 1 ? scene : scaled_overlay(scene, k), big, window_for(*display), rendered);
  framing.width = size.width;
  framing.height = size.height;
  framing.pixels_per_unit /= k;

  int dims[3];
  rendered->GetDimensions(dims);
  const int nc = rendered->GetNumberOfScalarComponents();
  if (dims[0] != big.width || dims[1] != big.height || nc < 3 || rendered->GetScalarType() != VTK_UNSIGNED_CHAR)
    throw Error(path + ": rendering failed (unexpected image from the render window)");
  vtkNew<vtkImageData> out;
  out->SetDimensions(size.width, size.height, 1);
  out->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  const auto* src = static_cast<const unsigned char*>(rendered->GetScalarPointer());
  auto* dst = static_cast<unsigned char*>(out->GetScalarPointer());
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      for (int c = 0; c < 3; ++c) {
        int sum = 0;
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i)
            sum += src[(static_cast<std::size_t>(y * k + j) * big.width + (x * k + i)) * nc + c];
        dst[(static_cast<std::size_t>(y) * size.width + x) * 3 + c] =
            static_cast<unsigned char>((sum + k * k / 2) / (k * k));
      }

  const std::string tmp = temp_path_for(path);
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputData(out);
  writer->Write();
  const bool failed = writer->GetErrorCode() != 0;
  std::error_code ec;
  if (failed || !std::filesystem::exists(tmp, ec)) {
    std::filesystem::remove(tmp, ec);
    throw Error(path + ": cannot write PNG file");
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error(path + ": cannot write PNG file (" + ec.message() + ")");
  }
  return framing;
}

}  // namespace sf::render

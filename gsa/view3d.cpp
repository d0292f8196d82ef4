#include "gsa/view3d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/xml_escape.hpp"
#include "gsa/option_error.hpp"
#include "gsa/results_folder.hpp"

#ifdef SF_HAVE_THREE_JS
namespace sf::gsa::embedded {
extern const char three_js[];
extern const std::size_t three_js_size;
extern const char orbit_controls_js[];
extern const std::size_t orbit_controls_js_size;
extern const char view3d_js[];
extern const std::size_t view3d_js_size;
}  // namespace sf::gsa::embedded
#endif

namespace sf::gsa {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string base64(const void* data, std::size_t n) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = static_cast<const unsigned char*>(data);
  std::string s;
  s.reserve((n + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < n; i += 3) {
    const unsigned v = (b[i] << 16) | (b[i + 1] << 8) | b[i + 2];
    s += k[(v >> 18) & 63];
    s += k[(v >> 12) & 63];
    s += k[(v >> 6) & 63];
    s += k[v & 63];
  }
  if (i < n) {
    const unsigned v = (b[i] << 16) | (i + 1 < n ? b[i + 1] << 8 : 0);
    s += k[(v >> 18) & 63];
    s += k[(v >> 12) & 63];
    s += i + 1 < n ? k[(v >> 6) & 63] : '=';
    s += '=';
  }
  return s;
}

// Float32 little-endian in base64 (x86 and ARM are little-endian, as typed arrays are there).
std::string f32(const std::vector<double>& v) {
  std::vector<float> f(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) f[i] = static_cast<float>(v[i]);
  return base64(f.data(), f.size() * sizeof(float));
}
std::string u32(const std::vector<std::uint32_t>& v) { return base64(v.data(), v.size() * sizeof(std::uint32_t)); }

// Smallest colour range of a field with this unit, as the PNG contour plots use (gsa/plots.cpp):
// 0.01 of strain or stretch, 1 % or 1 degree. A nearly uniform field then shows as one or two
// colours, not as its noise stretched over the whole bar. Other units (lengths): none.
double min_span_of(const std::string& unit) {
  if (unit == "-") return 0.01;
  if (unit == "%" || unit == "\xC2\xB0") return 1.0;
  return 0.0;
}

// {lo, hi} of the finite values; {null, null} when there are none.
nlohmann::json data_range_of(const std::vector<double>& v) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double x : v)
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  if (!(lo <= hi)) return {nullptr, nullptr};
  return {lo, hi};
}

// The colour range: the data's, widened about its middle to at least `min_span`.
nlohmann::json colour_range_of(const nlohmann::json& data_range, double min_span) {
  if (data_range[0].is_null()) return data_range;
  const double lo = data_range[0].get<double>(), hi = data_range[1].get<double>();
  if (hi - lo >= min_span) return data_range;
  const double mid = 0.5 * (lo + hi);
  return {mid - 0.5 * min_span, mid + 0.5 * min_span};
}

// The "range" (colour) and "data_range" (values) keys of a field.
void put_ranges(nlohmann::json& f, const std::vector<double>& v, const std::string& unit) {
  const nlohmann::json data = data_range_of(v);
  f["range"] = colour_range_of(data, min_span_of(unit));
  f["data_range"] = data;
}

const io::FieldArray* field(const io::PolyMesh& m, const std::string& name, int components) {
  for (const auto& f : m.point_data)
    if (f.name == name && f.n_components == components) return &f;
  return nullptr;
}

// Label and unit of a surface field or a strains.csv column, by its name.
std::pair<std::string, std::string> label_of(const std::string& name, const std::string& length_unit) {
  static const std::map<std::string, std::pair<std::string, std::string>> known = {
      {"true1", {"Major true strain", "-"}},
      {"true2", {"Minor true strain", "-"}},
      {"eng1", {"Major engineering strain", "-"}},
      {"eng2", {"Minor engineering strain", "-"}},
      {"E1", {"Major Green strain", "-"}},
      {"E2", {"Minor Green strain", "-"}},
      {"lambda1", {"Major stretch", "-"}},
      {"lambda2", {"Minor stretch", "-"}},
      {"thickness_change_pct", {"Thickness change", "%"}},
      {"shear_angle_deg", {"Trellis shear angle", "\xC2\xB0"}},
      {"fibre1_stretch", {"Fibre 1 stretch", "-"}},
      {"fibre2_stretch", {"Fibre 2 stretch", "-"}},
      {"flc_margin", {"Forming limit margin", "-"}},
  };
  if (const auto it = known.find(name); it != known.end()) return it->second;
  auto ends = [&](const std::string& s) {
    return name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
  };
  if (ends("_mm")) return {name, "mm"};
  if (ends("_pct")) return {name, "%"};
  if (ends("_deg")) return {name, "\xC2\xB0"};
  static const std::set<std::string> lengths = {"residual", "residual_undeformed", "X_fit",          "Y_fit",
                                                "Z_fit",    "flag_deviation",      "flag_threshold", "flag_noise"};
  if (lengths.count(name)) return {name, length_unit};
  return {name, ""};
}

// The structure of a tessellated surface as surface_polymesh() writes it: element e's
// (subdiv + 1)^2 points from e (subdiv + 1)^2 on, row by row; quad (e, j, i) is
// {a, a + 1, a + np + 1, a + np} with a = e np^2 + j np + i. Empty when the mesh is not so.
struct Tessellation {
  int subdiv = 0;
  Index n_elements = 0;
  std::vector<bool> measured;  // (e * subdiv + j) * subdiv + i
  bool cell(Index e, int j, int i) const {
    return j >= 0 && i >= 0 && j < subdiv && i < subdiv &&
           measured[static_cast<std::size_t>((e * subdiv + j) * subdiv + i)];
  }
};

Tessellation structure_of(const io::PolyMesh& m) {
  Tessellation t;
  if (m.polygons.empty()) return t;
  const auto& p0 = m.polygons.front();
  if (p0.size() != 4) return t;
  const Index np = p0[3] - p0[0];
  if (np < 2 || m.n_points() % (np * np) != 0) return {};
  const int subdiv = static_cast<int>(np - 1);
  const Index ne = m.n_points() / (np * np);
  std::vector<bool> measured(static_cast<std::size_t>(ne * subdiv * subdiv), false);
  for (const auto& p : m.polygons) {
    if (p.size() != 4) return {};
    const Index a = p[0], e = a / (np * np), j = (a % (np * np)) / np, i = a % np;
    if (i >= subdiv || j >= subdiv || p[1] != a + 1 || p[2] != a + np + 1 || p[3] != a + np) return {};
    measured[static_cast<std::size_t>((e * subdiv + j) * subdiv + i)] = true;
  }
  t.subdiv = subdiv;
  t.n_elements = ne;
  t.measured = std::move(measured);
  return t;
}

struct Surface {
  std::vector<Index> used;  // tessellation point of each embedded vertex
  std::vector<std::uint32_t> triangles;
  int step = 1;
};

// The embedded vertices and triangles: every step-th tessellation line, with the coarsest
// step of 1, 2, 4 ... that keeps the vertex count under the budget.
Surface decimated(const io::PolyMesh& m, const Tessellation& t, Index max_vertices) {
  Surface s;
  if (t.subdiv == 0) {  // not a gsa tessellation: every polygon as a fan, no decimation
    std::vector<Index> map(static_cast<std::size_t>(m.n_points()), -1);
    auto id = [&](Index p) {
      Index& k = map[static_cast<std::size_t>(p)];
      if (k < 0) k = static_cast<Index>(s.used.size()), s.used.push_back(p);
      return static_cast<std::uint32_t>(k);
    };
    for (const auto& p : m.polygons)
      for (std::size_t k = 1; k + 1 < p.size(); ++k)
        for (Index v : {p[0], p[k], p[k + 1]}) s.triangles.push_back(id(v));
    return s;
  }
  const Index np = t.subdiv + 1;
  for (int step = 1; step <= t.subdiv; step *= 2) {
    if (t.subdiv % step != 0) break;
    Surface c;
    c.step = step;
    std::vector<Index> map(static_cast<std::size_t>(m.n_points()), -1);
    auto id = [&](Index p) {
      Index& k = map[static_cast<std::size_t>(p)];
      if (k < 0) k = static_cast<Index>(c.used.size()), c.used.push_back(p);
      return static_cast<std::uint32_t>(k);
    };
    const int n = t.subdiv / step;
    for (Index e = 0; e < t.n_elements; ++e)
      for (int J = 0; J < n; ++J)
        for (int I = 0; I < n; ++I) {
          bool all = true;
          for (int j = J * step; all && j < (J + 1) * step; ++j)
            for (int i = I * step; all && i < (I + 1) * step; ++i) all = t.cell(e, j, i);
          if (!all) continue;
          const Index a = e * np * np + J * step * np + I * step, b = a + step, cc = a + step * np + step,
                      d = a + step * np;
          const std::uint32_t ia = id(a), ib = id(b), ic = id(cc), idd = id(d);
          for (std::uint32_t v : {ia, ib, ic, ia, ic, idd}) c.triangles.push_back(v);
        }
    s = std::move(c);
    if (static_cast<Index>(s.used.size()) <= max_vertices || step * 2 > t.subdiv) break;
  }
  return s;
}

std::vector<double> positions(const io::PolyMesh& m, const std::vector<Index>& used) {
  std::vector<double> v;
  v.reserve(used.size() * 3);
  for (Index p : used)
    for (int c = 0; c < 3; ++c) v.push_back(m.points(p, c));
  return v;
}

std::vector<double> gather(const io::FieldArray& f, const std::vector<Index>& used) {
  std::vector<double> v;
  v.reserve(used.size() * static_cast<std::size_t>(f.n_components));
  for (Index p : used)
    for (int c = 0; c < f.n_components; ++c) v.push_back(f.values[static_cast<std::size_t>(p * f.n_components + c)]);
  return v;
}

// A number for a strains.csv cell, NaN for an empty or "nan" cell; nothing for text.
std::optional<double> number_of(std::string_view s) {
  if (s.empty()) return kNaN;
  std::string t(s);
  for (char& ch : t) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (t == "nan" || t == "-nan") return kNaN;
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end == t.c_str() || *end != '\0') return std::nullopt;
  return v;
}

// Point (e, xi1, xi2) of a tessellated surface, bilinear inside its tessellation cell.
Vec3 point_at(const io::PolyMesh& m, const Tessellation& t, Index e, double xi1, double xi2) {
  const Index np = t.subdiv + 1;
  const double u = std::clamp(xi1, 0.0, 1.0) * t.subdiv, v = std::clamp(xi2, 0.0, 1.0) * t.subdiv;
  const int i = std::min(static_cast<int>(u), t.subdiv - 1), j = std::min(static_cast<int>(v), t.subdiv - 1);
  const double a = u - i, b = v - j;
  const Index p = e * np * np + j * np + i;
  auto x = [&](Index q) { return Vec3(m.points.row(q).transpose()); };
  return (1 - a) * (1 - b) * x(p) + a * (1 - b) * x(p + 1) + a * b * x(p + np + 1) + (1 - a) * b * x(p + np);
}

nlohmann::json surface_json(const PlotData& d, const Tessellation& t, const View3dOptions& o, View3dStats& st) {
  const Surface s = decimated(d.deformed, t, o.max_vertices);
  st.vertices = static_cast<Index>(s.used.size());
  st.triangles = static_cast<Index>(s.triangles.size() / 3);
  st.quads_per_element_side = t.subdiv > 0 ? t.subdiv / s.step : 0;
  nlohmann::json j;
  j["n_vertices"] = st.vertices;
  j["n_triangles"] = st.triangles;
  j["quads_per_element_side"] = st.quads_per_element_side;
  j["tessellation_per_element_side"] = t.subdiv;
  j["pos_u"] = f32(positions(d.undeformed, s.used));
  j["pos_d"] = f32(positions(d.deformed, s.used));
  j["index"] = u32(s.triangles);
  // The measure's major and minor first, then thickness and shear, then the rest.
  const auto m = measure_fields(d.measure);
  std::vector<std::string> order = {m[0], m[1], "thickness_change_pct", "shear_angle_deg"};
  for (const auto& f : d.deformed.point_data)
    if (f.n_components == 1 && std::find(order.begin(), order.end(), f.name) == order.end()) order.push_back(f.name);
  nlohmann::json fields = nlohmann::json::array();
  for (const std::string& name : order) {
    const io::FieldArray* f = field(d.deformed, name, 1);
    if (!f || f->values.size() != static_cast<std::size_t>(d.deformed.n_points())) continue;
    const std::vector<double> v = gather(*f, s.used);
    const auto [label, unit] = label_of(name, d.units);
    nlohmann::json x = {{"key", name}, {"label", label}, {"unit", unit}, {"data", f32(v)}};
    put_ranges(x, v, unit);
    fields.push_back(std::move(x));
    st.surface_fields.push_back(name);
  }
  j["fields"] = std::move(fields);
  return j;
}

nlohmann::json glyphs_json(const PlotData& d, const Tessellation& t, View3dStats& st) {
  nlohmann::json g;
  const auto m = measure_fields(d.measure);
  const io::FieldArray* e1 = field(d.deformed, m[0], 1);
  const io::FieldArray* e2 = field(d.deformed, m[1], 1);
  const io::FieldArray* du[2] = {field(d.undeformed, "dir1", 3), field(d.undeformed, "dir2", 3)};
  const io::FieldArray* dd[2] = {field(d.deformed, "dir1", 3), field(d.deformed, "dir2", 3)};
  if (!e1 || !e2 || !du[0] || !du[1] || !dd[0] || !dd[1])
    throw InputError(d.source + ": the surfaces lack " + m[0] + ", " + m[1] +
                     ", dir1 or dir2 (point data of undeformed.vtp / deformed.vtp), which the arrows need");
  if (t.subdiv == 0) return nullptr;
  Index n_measured = 0;
  for (Index e = 0; e < t.n_elements; ++e)
    for (int k = 0; k < t.subdiv * t.subdiv; ++k)
      if (t.measured[static_cast<std::size_t>(e * t.subdiv * t.subdiv + k)]) {
        ++n_measured;
        break;
      }
  std::vector<int> at = {t.subdiv / 2};
  if (n_measured <= 400 && t.subdiv % 4 == 0) at = {t.subdiv / 4, 3 * t.subdiv / 4};
  const Index np = t.subdiv + 1;
  std::vector<Index> sites;
  for (Index e = 0; e < t.n_elements; ++e)
    for (int j : at)
      for (int i : at)
        if (t.cell(e, j, i) && t.cell(e, j - 1, i - 1) && t.cell(e, j - 1, i) && t.cell(e, j, i - 1))
          sites.push_back(e * np * np + j * np + i);
  st.glyph_sites = static_cast<Index>(sites.size());
  g["n"] = sites.size();
  g["pos_u"] = f32(positions(d.undeformed, sites));
  g["pos_d"] = f32(positions(d.deformed, sites));
  g["dir1_u"] = f32(gather(*du[0], sites));
  g["dir2_u"] = f32(gather(*du[1], sites));
  g["dir1_d"] = f32(gather(*dd[0], sites));
  g["dir2_d"] = f32(gather(*dd[1], sites));
  g["major"] = f32(gather(*e1, sites));
  g["minor"] = f32(gather(*e2, sites));
  return g;
}

// Columns read least; dropped first (in this order) when the marks exceed the budget.
const std::vector<std::string>& drop_order() {
  static const std::vector<std::string> k = {"dir1u_x",
                                             "dir1u_y",
                                             "dir1u_z",
                                             "dir2_x",
                                             "dir2_y",
                                             "dir2_z",
                                             "dir1_x",
                                             "dir1_y",
                                             "dir1_z",
                                             "flag_noise",
                                             "X_fit",
                                             "Y_fit",
                                             "Z_fit",
                                             "flag_threshold",
                                             "flag_deviation",
                                             "E1",
                                             "E2",
                                             "eng1",
                                             "eng2",
                                             "lambda1",
                                             "lambda2",
                                             "residual_undeformed"};
  return k;
}

nlohmann::json marks_json(const PlotData& d, const Tessellation& t, const io::CsvTable& csv, const View3dOptions& o,
                          View3dStats& st) {
  if (t.subdiv == 0) return nullptr;
  const std::string& file = csv.file_name();
  const std::size_t ce = csv.column_index("element"), cx1 = csv.column_index("xi1"), cx2 = csv.column_index("xi2");
  const auto cid = csv.find_column("id");
  std::vector<std::size_t> rows;
  std::vector<double> pu, pd;
  for (std::size_t r = 0; r < csv.n_rows(); ++r) {
    const auto e = number_of(csv.cell(r, ce)), x1 = number_of(csv.cell(r, cx1)), x2 = number_of(csv.cell(r, cx2));
    if (!e || !x1 || !x2 || !std::isfinite(*e) || !std::isfinite(*x1) || !std::isfinite(*x2) || *e < 0 ||
        *e >= static_cast<double>(t.n_elements)) {
      ++st.marks_unplaced;
      continue;
    }
    const Index el = static_cast<Index>(*e);
    const Vec3 a = point_at(d.undeformed, t, el, *x1, *x2), b = point_at(d.deformed, t, el, *x1, *x2);
    for (int c = 0; c < 3; ++c) pu.push_back(a[c]), pd.push_back(b[c]);
    rows.push_back(r);
  }
  st.marks = static_cast<Index>(rows.size());
  nlohmann::json j;
  j["n"] = rows.size();
  j["unplaced"] = st.marks_unplaced;
  j["source"] = std::filesystem::path(file).filename().string();
  j["pos_u"] = f32(pu);
  j["pos_d"] = f32(pd);
  nlohmann::json ids = nlohmann::json::array();
  for (std::size_t r : rows) ids.push_back(cid ? std::string(csv.cell(r, *cid)) : std::to_string(r + 1));
  j["ids"] = std::move(ids);
  // Classify every other column: numbers, few distinct texts (categories), or neither.
  struct Column {
    std::size_t col;
    std::string name;
    std::vector<double> values;
    std::vector<std::string> categories;
  };
  std::vector<Column> cols;
  for (std::size_t c = 0; c < csv.n_columns(); ++c) {
    const std::string name = csv.names()[c];
    if (c == ce || c == cx1 || c == cx2 || (cid && c == *cid)) continue;
    Column col{c, name, {}, {}};
    bool numeric = true, any = false;
    for (std::size_t r : rows) {
      const auto v = number_of(csv.cell(r, c));
      if (!v) {
        numeric = false;
        break;
      }
      any = any || std::isfinite(*v);
      col.values.push_back(*v);
    }
    if (numeric) {
      if (any) cols.push_back(std::move(col));
      continue;
    }
    col.values.clear();
    std::map<std::string, int> codes;
    for (std::size_t r : rows) {
      const std::string s(csv.cell(r, c));
      if (s.empty()) {
        col.values.push_back(kNaN);
        continue;
      }
      auto it = codes.find(s);
      if (it == codes.end()) {
        if (codes.size() >= 24) break;
        it = codes.emplace(s, static_cast<int>(col.categories.size())).first;
        col.categories.push_back(s);
      }
      col.values.push_back(it->second);
    }
    if (col.values.size() == rows.size() && !col.categories.empty()) cols.push_back(std::move(col));
  }
  // Keep within the budget of numbers: drop the columns least read first (never the
  // page's own measure).
  const auto own = measure_fields(d.measure);
  for (const std::string& name : drop_order()) {
    if (name == own[0] || name == own[1]) continue;
    if (cols.size() * rows.size() <= o.max_mark_values) break;
    const auto it = std::find_if(cols.begin(), cols.end(), [&](const Column& c) { return c.name == name; });
    if (it == cols.end()) continue;
    st.mark_columns_left_out.push_back(name);
    cols.erase(it);
  }
  while (!cols.empty() && cols.size() * rows.size() > o.max_mark_values) {
    st.mark_columns_left_out.push_back(cols.back().name);
    cols.pop_back();
  }
  nlohmann::json jc = nlohmann::json::array();
  for (const Column& c : cols) {
    const auto [label, unit] = label_of(c.name, d.units);
    nlohmann::json x = {{"key", c.name}, {"label", label}, {"unit", unit}, {"data", f32(c.values)}};
    if (c.categories.empty())
      put_ranges(x, c.values, unit);
    else
      x["categories"] = c.categories;
    jc.push_back(std::move(x));
    st.mark_columns.push_back(c.name);
  }
  j["columns"] = std::move(jc);
  j["left_out"] = st.mark_columns_left_out;
  return j;
}

// Text inside a <script> element: "</script" would end it early.
std::string script_safe(std::string s) {
  for (std::size_t p = 0; (p = s.find("</", p)) != std::string::npos; p += 3) s.replace(p, 2, "<\\/");
  return s;
}

const char* kStyle = R"(<style>
.gsa-view{flex:1 1 100%;max-width:none;background:#fff;border:1px solid #ddd;padding:8px;box-sizing:border-box}
.gsa-view .gv-bar{display:flex;flex-wrap:wrap;gap:6px 16px;align-items:center;font-size:0.88em;margin-bottom:6px}
.gsa-view .gv-bar select{max-width:22em}
.gsa-view .gv-stage{position:relative;height:640px;background:#fff;border:1px solid #eee}
.gsa-view.gv-full{border:0;padding:6px 8px;height:100vh;display:flex;flex-direction:column}
.gsa-view.gv-full .gv-stage{flex:1 1 auto;height:auto;min-height:200px}
.gsa-view canvas.gv-gl{display:block;width:100%;height:100%;cursor:crosshair;outline:none}
.gsa-view .gv-legend{position:absolute;right:10px;top:10px;background:rgba(255,255,255,0.88);padding:6px 8px;
border:1px solid #ddd;font-size:0.8em;max-width:190px}
.gsa-view .gv-legend .gv-ticks{display:flex;flex-direction:column;justify-content:space-between;height:200px}
.gsa-view .gv-info{position:absolute;left:10px;top:10px;background:rgba(255,255,255,0.92);padding:6px 8px;
border:1px solid #ddd;font-size:0.8em;max-height:60%;overflow:auto;display:none;max-width:330px}
.gsa-view .gv-info table{width:auto}.gsa-view .gv-info th{width:auto;font-weight:600}
.gsa-view .gv-msg{color:#a40}
.gsa-view .gv-foot{font-size:0.85em;color:#444;margin:6px 0 0}
</style>
)";

}  // namespace

void View3dOptions::validate() const {
  if (max_vertices < 100)
    throw OptionError("max_vertices", "must be at least 100, found " + std::to_string(max_vertices));
  if (max_mark_values < 1000)
    throw OptionError("max_mark_values", "must be at least 1000, found " + std::to_string(max_mark_values));
}

bool view3d_available() {
#ifdef SF_HAVE_THREE_JS
  return true;
#else
  return false;
#endif
}

std::string view3d_library() {
  return view3d_available() ? "three.js r111 (Debian libjs-three, MIT licence)"
                            : "none: gsa was built without three.js (install the Debian package libjs-three, "
                              "scripts/install_deps.sh, and build again)";
}

View3d make_view3d(const PlotData& d, const io::CsvTable* strains, const View3dOptions& o) {
  o.validate();
  if (!view3d_available()) throw Error("3-D view: " + view3d_library());
  if (!d.has_surfaces)
    throw InputError(d.source + ": no fitted surfaces (triangle method): the 3-D view needs the surface method");
  if (d.undeformed.n_points() != d.deformed.n_points() || d.undeformed.polygons.size() != d.deformed.polygons.size())
    throw InputError(d.source + ": undeformed.vtp and deformed.vtp do not belong together (different point counts)");
  View3d v;
  const Tessellation t = structure_of(d.deformed);
  nlohmann::json j;
  j["title"] = d.case_name;
  j["units"] = d.units;
  j["measure"] = measure_name(d.measure);
  j["library"] = view3d_library();
  j["surface"] = surface_json(d, t, o, v.stats);
  j["glyphs"] = glyphs_json(d, t, v.stats);
  if (strains) j["marks"] = marks_json(d, t, *strains, o, v.stats);
  // Ids and names from the user's files may hold bytes that are not UTF-8: replaced, not fatal.
  const std::string data = script_safe(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  v.stats.data_bytes = data.size();
  std::ostringstream h;
  if (o.full_window)
    h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>gsa 3-D view: "
      << io::xml_escape(d.case_name)
      << "</title>\n<style>body{margin:0;font-family:system-ui,-apple-system,'Segoe UI',Roboto,Arial,sans-serif;"
         "color:#222}</style>\n</head>\n<body>\n";
  h << kStyle;
  h << "<section class=\"gsa-view" << (o.full_window ? " gv-full" : "")
    << "\" id=\"gsa-view\" data-state=\"loading\">\n"
    << "<h2 style=\"margin:2px 0 6px\">3-D view" << (o.full_window ? ": " + io::xml_escape(d.case_name) : "")
    << "</h2>\n<noscript><p class=\"gv-msg\">The 3-D view needs JavaScript.</p></noscript>\n"
    << "<div class=\"gv-bar\"></div>\n<div class=\"gv-stage\"></div>\n<p class=\"gv-foot\"></p>\n";
  h << "<script type=\"application/json\" id=\"gsa-view-data\">" << data << "</script>\n";
#ifdef SF_HAVE_THREE_JS
  h << "<script>/* three.js r111, https://threejs.org, MIT licence, Copyright 2010-2019 three.js authors; "
       "from Debian's libjs-three */\n"
    << script_safe(std::string(embedded::three_js, embedded::three_js_size)) << "\n</script>\n";
  h << "<script>/* three.js r111 examples/js/controls/OrbitControls.js, MIT licence */\n"
    << script_safe(std::string(embedded::orbit_controls_js, embedded::orbit_controls_js_size)) << "\n</script>\n";
  h << "<script>\n" << script_safe(std::string(embedded::view3d_js, embedded::view3d_js_size)) << "\n</script>\n";
#endif
  h << "</section>\n";
  if (o.full_window) h << "</body>\n</html>\n";
  v.html = h.str();
  return v;
}

View3dStats write_view_page(const std::string& dir, StrainMeasure measure, const View3dOptions& options,
                            const std::string& out) {
  options.validate();
  if (!view3d_available()) throw Error("gsa view: " + view3d_library());
  if (!std::filesystem::is_directory(dir))
    throw InputError(dir + ": no such folder; give a results folder written by `gsa analyse`");
  ResultsFolder folder = read_results_folder(dir);
  const io::CsvTable strains = folder.strains;
  const PlotData data = plot_data(std::move(folder), measure);
  View3dOptions o = options;
  o.full_window = true;
  View3d v = make_view3d(data, &strains, o);
  io::write_file_atomic(out.empty() ? (std::filesystem::path(dir) / "view.html").string() : out, v.html);
  return v.stats;
}

}  // namespace sf::gsa

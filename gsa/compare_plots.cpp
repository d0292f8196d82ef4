#include "gsa/compare_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/vtk_xml.hpp"
#include "common/io/xml_escape.hpp"
#include "common/render/chart.hpp"
#include "common/render/scene.hpp"

namespace sf::gsa {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const render::Colour kMeasured{0.12, 0.38, 0.70}, kSimulated{0.90, 0.45, 0.05}, kJoin{0.55, 0.55, 0.55};

std::string short_name(const std::string& source) {
  const std::filesystem::path p(source);
  const std::string parent = p.parent_path().filename().string();
  return parent.empty() ? p.filename().string() : parent + "/" + p.filename().string();
}

std::string fmt_number(double v, int significant = 3) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", significant, v);
  return buf;
}

// Largest |value| of the finite values (0 when none).
double max_abs(const std::vector<double>& v) {
  double a = 0;
  for (double x : v)
    if (std::isfinite(x)) a = std::max(a, std::abs(x));
  return a;
}

// A diverging colouring centred on zero, symmetric about it; `floor` is the smallest half
// range shown (so round-off differences do not fill the bands with noise).
render::ScalarColouring diverging(const std::vector<double>& values, const std::string& title, const std::string& units,
                                  double floor) {
  render::ScalarColouring c;
  c.title = title;
  c.units = units;
  c.values = values;
  c.map = render::ColourMap::kDiverging;
  const double a = std::max(max_abs(values), floor);
  c.bands = render::nice_bands(-a, a, 10, true);
  return c;
}

render::Scene contour(const CompareResult& r, const std::vector<double>& values, const std::string& title,
                      const std::string& bar, const std::string& units, double floor, const std::string& subtitle,
                      const PlotOptions& o, bool signed_field = true) {
  render::Scene scene;
  scene.title = title;
  scene.subtitle = subtitle;
  scene.view = o.view;
  const Statistics st = statistics_of(values);
  scene.footnote = "Measured formed part. Mean " + fmt_number(st.mean) + ", RMS " + fmt_number(st.rms) + ", max |.| " +
                   fmt_number(st.max_abs) + " " + units + " over the surface. Grey: outside the simulated part.";
  render::Surface s;
  s.points = r.surface.points;
  s.polygons = r.surface.polygons;
  if (signed_field) {
    s.colouring = diverging(values, bar, units, floor);
  } else {
    render::ScalarColouring c;
    c.title = bar;
    c.units = units;
    c.values = values;
    c.bands = render::nice_bands(0.0, std::max(max_abs(values), floor), 10, false);
    s.colouring = c;
  }
  scene.surfaces.push_back(std::move(s));
  return scene;
}

// Step outline of a histogram of `values` over [-a, a] in `bins` bins.
render::ChartSeries histogram_series(const std::vector<double>& values, double a, int bins, const std::string& label,
                                     const render::Colour& colour) {
  std::vector<double> count(static_cast<std::size_t>(bins), 0.0);
  Index n = 0;
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    int b = static_cast<int>(std::floor((v + a) / (2 * a) * bins));
    b = std::clamp(b, 0, bins - 1);
    count[static_cast<std::size_t>(b)] += 1;
    ++n;
  }
  render::ChartSeries s;
  s.label = label + " (" + std::to_string(n) + " marks)";
  s.style = render::ChartSeries::Style::kLine;
  s.colour = colour;
  s.size_px = 2.5;
  const double w = 2 * a / bins;
  s.x.push_back(-a);
  s.y.push_back(0);
  for (int b = 0; b < bins; ++b) {
    const double x0 = -a + b * w;
    s.x.push_back(x0);
    s.y.push_back(count[static_cast<std::size_t>(b)]);
    s.x.push_back(x0 + w);
    s.y.push_back(count[static_cast<std::size_t>(b)]);
  }
  s.x.push_back(a);
  s.y.push_back(0);
  return s;
}

std::vector<double> mark_values(const CompareResult& r, Field f) {
  std::vector<double> v;
  for (const auto& c : r.marks) v.push_back(c.difference[static_cast<std::size_t>(f)]);
  return v;
}

}  // namespace

std::vector<std::string> write_compare_pictures(const CompareSide& m, const CompareSide& s, const CompareResult& r,
                                                const PlotOptions& o,
                                                const std::function<std::string(const std::string&)>& out_path,
                                                const PictureProgress& progress) {
  std::vector<std::string> names;
  const std::string sub =
      short_name(m.source) + "  vs  " + short_name(s.source) + "  \xC2\xB7  measured \xE2\x88\x92 simulated";
  struct Job {
    std::string name;
    std::function<void(const std::string&)> draw;
  };
  std::vector<Job> jobs;
  const std::string w = measure_word(r.measure);
  auto add_contour = [&](const std::string& name, Field f, double floor) {
    const std::string title = field_title(f, r.measure) + " difference";
    jobs.push_back({name, [&, f, floor, title](const std::string& path) {
                      render::write_png(contour(r, r.surface.difference[static_cast<std::size_t>(f)], title,
                                                "\xCE\x94 " + field_title(f, r.measure), field_units(f), floor, sub, o),
                                        o.size, path);
                    }});
  };
  add_contour("diff_major.png", Field::kMajor, 1e-3);
  add_contour("diff_minor.png", Field::kMinor, 1e-3);
  add_contour("diff_thickness.png", Field::kThickness, 0.1);
  if (r.fibre_mode) add_contour("diff_shear_angle.png", Field::kShear, 0.1);
  const double spacing_floor = 1e-3;
  jobs.push_back(
      {"shape_deviation.png", [&](const std::string& path) {
         render::write_png(
             contour(r, r.surface.shape_deviation, "Shape deviation", "Normal distance", m.units, spacing_floor,
                     short_name(m.source) + "  from  " + short_name(s.source) + "  \xC2\xB7  after registration", o),
             o.size, path);
       }});
  jobs.push_back({"position_difference.png", [&](const std::string& path) {
                    render::write_png(contour(r, r.surface.position_difference, "Position of the same material point",
                                              "Distance", m.units, spacing_floor,
                                              short_name(m.source) + "  vs  " + short_name(s.source) +
                                                  "  \xC2\xB7  after registration (draw-in, sliding)",
                                              o, false),
                                      o.size, path);
                  }});
  jobs.push_back({"principal_strains.png", [&](const std::string& path) {
                    render::Chart chart;
                    chart.title = "Principal strains, measured and simulated";
                    chart.subtitle = short_name(m.source) + "  vs  " + short_name(s.source);
                    chart.x_label = "minor strain (" + w + ")";
                    chart.y_label = "major strain (" + w + ")";
                    chart.equal_axes = true;
                    chart.legend_title = "Key";
                    render::ChartSeries join, dm, ds;
                    join.label = "same mark";
                    join.style = render::ChartSeries::Style::kLine;
                    join.colour = kJoin;
                    join.size_px = 1;
                    join.opacity = 0.7;
                    dm.label = "measured";
                    dm.colour = kMeasured;
                    ds.label = "simulated";
                    ds.colour = kSimulated;
                    Index n = 0;
                    for (const auto& c : r.marks) {
                      if (!c.matched) continue;
                      const double x0 = c.measured[1], y0 = c.measured[0], x1 = c.simulated[1], y1 = c.simulated[0];
                      join.x.insert(join.x.end(), {x0, x1, kNaN});
                      join.y.insert(join.y.end(), {y0, y1, kNaN});
                      dm.x.push_back(x0);
                      dm.y.push_back(y0);
                      ds.x.push_back(x1);
                      ds.y.push_back(y1);
                      ++n;
                    }
                    const double size = n > 5000 ? 1.5 : n > 1000 ? 2.0 : 3.0;
                    dm.size_px = ds.size_px = size;
                    chart.series = {join, ds, dm};
                    chart.footnote =
                        std::to_string(n) + " matched marks; strain measure: " + measure_name(r.measure) + ".";
                    render::write_chart_png(chart, o.size, path);
                  }});
  jobs.push_back({"histogram.png", [&](const std::string& path) {
                    const std::vector<double> a = mark_values(r, Field::kMajor), b = mark_values(r, Field::kMinor);
                    const double range = std::max({max_abs(a), max_abs(b), 1e-4});
                    const render::Bands bands = render::nice_bands(-range, range, 10, true);
                    render::Chart chart;
                    chart.title = "Strain differences (measured \xE2\x88\x92 simulated)";
                    chart.subtitle = short_name(m.source) + "  vs  " + short_name(s.source);
                    chart.x_label = w + " strain difference";
                    chart.y_label = "marks per bin";
                    chart.legend_title = "Key";
                    chart.series = {histogram_series(a, bands.max, 40, "major", kMeasured),
                                    histogram_series(b, bands.max, 40, "minor", kSimulated)};
                    const Statistics sa = statistics_of(a), sb = statistics_of(b);
                    chart.footnote = "major: mean " + fmt_number(sa.mean) + ", RMS " + fmt_number(sa.rms) +
                                     "; minor: mean " + fmt_number(sb.mean) + ", RMS " + fmt_number(sb.rms) + ".";
                    render::write_chart_png(chart, o.size, path);
                  }});
  jobs.push_back({"histogram_shape.png", [&](const std::string& path) {
                    std::vector<double> v;
                    for (const auto& c : r.marks) v.push_back(c.shape_deviation);
                    const double range = std::max(max_abs(v), 1e-4);
                    const render::Bands bands = render::nice_bands(-range, range, 10, true);
                    render::Chart chart;
                    chart.title = "Shape deviation (measured from simulated)";
                    chart.subtitle = short_name(m.source) + "  vs  " + short_name(s.source);
                    chart.x_label = "normal distance [" + m.units + "]";
                    chart.y_label = "marks per bin";
                    chart.legend_title = "Key";
                    chart.series = {histogram_series(v, bands.max, 40, "shape deviation", kMeasured)};
                    const Statistics st = statistics_of(v);
                    chart.footnote =
                        "mean " + fmt_number(st.mean) + ", RMS " + fmt_number(st.rms) + " " + m.units + ".";
                    render::write_chart_png(chart, o.size, path);
                  }});
  const int total = static_cast<int>(jobs.size());
  if (progress) progress(0, total);
  for (int k = 0; k < total; ++k) {
    jobs[static_cast<std::size_t>(k)].draw(out_path(jobs[static_cast<std::size_t>(k)].name));
    names.push_back(jobs[static_cast<std::size_t>(k)].name);
    if (progress) progress(k + 1, total);
  }
  return names;
}

namespace {
std::string cell(const nlohmann::json& j) {
  if (j.is_null()) return "&ndash;";
  if (j.is_number_integer()) return std::to_string(j.get<long long>());
  if (j.is_number()) {
    const double v = j.get<double>();
    char buf[64];
    if (v != 0 && (std::abs(v) < 1e-3 || std::abs(v) >= 1e6))
      std::snprintf(buf, sizeof buf, "%.3e", v);
    else
      std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
  }
  if (j.is_string()) return io::xml_escape(j.get<std::string>());
  if (j.is_array()) {
    std::string s;
    for (std::size_t i = 0; i < j.size(); ++i) s += (i ? ", " : "") + cell(j[i]);
    return s;
  }
  return io::xml_escape(j.dump());
}

const nlohmann::json& at(const nlohmann::json& j, const char* key) {
  static const nlohmann::json null;
  return j.is_object() && j.contains(key) ? j[key] : null;
}

std::string caption(const std::string& name) {
  if (name == "diff_major.png") return "Major strain difference, measured minus simulated, on the measured part.";
  if (name == "diff_minor.png") return "Minor strain difference, measured minus simulated.";
  if (name == "diff_thickness.png") return "Thickness change difference (percentage points), measured minus simulated.";
  if (name == "diff_shear_angle.png") return "Fibre shear angle difference (degrees), measured minus simulated.";
  if (name == "shape_deviation.png")
    return "Signed normal distance of the registered measured part from the simulated surface.";
  if (name == "position_difference.png")
    return "Distance between the same material point on both parts after registration (draw-in, sliding).";
  if (name == "principal_strains.png")
    return "Major against minor strain: measured (blue) and simulated (orange), a grey line joining each mark's pair.";
  if (name == "histogram.png") return "Distribution of the major and minor strain differences over the matched marks.";
  if (name == "histogram_shape.png") return "Distribution of the shape deviation over the matched marks.";
  return name;
}
}  // namespace

void write_compare_report(const std::string& path, const nlohmann::json& j, const std::vector<std::string>& pictures) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>gsa compare</title>\n"
    << "<style>body{font-family:sans-serif;margin:2em;max-width:1300px}table{border-collapse:collapse;margin:0.5em "
       "0 1.5em}th,td{border:1px solid #ccc;padding:3px 8px;text-align:left}th{background:#f2f2f2}td.n{text-align:"
       "right;font-variant-numeric:tabular-nums}figure{margin:1em 0}img{max-width:100%;border:1px solid #ddd}"
       "figcaption{color:#444}</style></head><body>\n";
  const nlohmann::json& ms = at(j, "measured");
  const nlohmann::json& ss = at(j, "simulated");
  h << "<h1>gsa compare</h1>\n<p>Measured: <b>" << cell(at(ms, "source")) << "</b> (" << cell(at(ms, "kind"))
    << "); simulated: <b>" << cell(at(ss, "source")) << "</b> (" << cell(at(ss, "kind")) << "). " << cell(at(j, "sign"))
    << ".</p>\n";
  auto table = [&](const std::string& title, const nlohmann::json& obj, std::initializer_list<const char*> keys) {
    h << "<h2>" << io::xml_escape(title) << "</h2>\n<table>\n";
    for (const char* k : keys)
      if (obj.is_object() && obj.contains(k)) h << "<tr><th>" << k << "</th><td>" << cell(obj[k]) << "</td></tr>\n";
    h << "</table>\n";
  };
  table("Registration", at(j, "registration"),
        {"method", "maps", "status", "message", "start", "rotation_deg", "rotation_axis", "translation", "rms_distance",
         "rms_distance_all", "points", "points_used", "iterations"});
  table("Blank map (material coordinates)", at(j, "blank_map"),
        {"method", "maps", "rotation_deg", "translation", "rms_distance"});
  table("Marks", at(j, "counts"),
        {"measured_marks", "simulated_marks", "shared_ids_analysed", "matched", "matched_by_id",
         "matched_by_material_point", "unmatched", "unmatched_by_reason", "simulated_only"});
  h << "<h2>Differences (measured &minus; simulated)</h2>\n<table>\n<tr><th>field</th><th>units</th><th>n</th>"
       "<th>mean</th><th>RMS</th><th>std</th><th>p05</th><th>p50</th><th>p95</th><th>min</th><th>max</th></tr>\n";
  const nlohmann::json& st = at(j, "statistics");
  if (st.is_object())
    for (const auto& [name, s] : st.items()) {
      h << "<tr><th>" << io::xml_escape(name) << "</th><td>" << cell(at(s, "units")) << "</td>";
      for (const char* k : {"n", "mean", "rms", "std", "p05", "p50", "p95", "min", "max"})
        h << "<td class=\"n\">" << cell(at(s, k)) << "</td>";
      h << "</tr>\n";
    }
  h << "</table>\n";
  const nlohmann::json& un = at(j, "unmatched");
  if (un.is_array() && !un.empty()) {
    h << "<h2>Unmatched measured marks (" << un.size() << ")</h2>\n<table>\n<tr><th>id</th><th>reason</th></tr>\n";
    std::size_t shown = 0;
    for (const auto& u : un) {
      if (++shown > 200) break;
      h << "<tr><td>" << cell(at(u, "id")) << "</td><td>" << cell(at(u, "reason")) << "</td></tr>\n";
    }
    h << "</table>\n";
    if (un.size() > 200) h << "<p>(first 200 shown; all in summary.json and differences.csv)</p>\n";
  }
  for (const std::string& p : pictures)
    h << "<figure><img src=\"" << io::xml_escape(p) << "\" alt=\"" << io::xml_escape(p) << "\"><figcaption>"
      << io::xml_escape(caption(p)) << "</figcaption></figure>\n";
  h << "</body></html>\n";
  io::write_file_atomic(path, [&](std::ostream& os) { os << h.str(); });
}

void write_compare_vtp(const std::string& path, const CompareResult& r) {
  io::PolyMesh pm;
  pm.points = r.surface.points;
  pm.polygons = r.surface.polygons;
  for (int q = 0; q < kFieldCount; ++q) {
    if (!r.fibre_mode && q >= static_cast<int>(Field::kShear)) continue;
    pm.point_data.push_back({std::string(field_key(static_cast<Field>(q))) + "_difference", 1,
                             r.surface.difference[static_cast<std::size_t>(q)]});
  }
  pm.point_data.push_back({"shape_deviation", 1, r.surface.shape_deviation});
  pm.point_data.push_back({"position_difference", 1, r.surface.position_difference});
  io::write_vtp(path, pm);
}

}  // namespace sf::gsa

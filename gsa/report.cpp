#include "gsa/report.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/xml_escape.hpp"

namespace sf::gsa {

namespace {

std::string number(double v) {
  if (!std::isfinite(v)) return "&ndash;";
  char buf[64];
  if (v != 0 && (std::abs(v) < 1e-3 || std::abs(v) >= 1e6))
    std::snprintf(buf, sizeof buf, "%.3e", v);
  else
    std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// A JSON value as table text.
std::string text_of(const nlohmann::json& j) {
  if (j.is_null()) return "&ndash;";
  if (j.is_number()) return number(j.get<double>());
  if (j.is_boolean()) return j.get<bool>() ? "yes" : "no";
  if (j.is_string()) return io::xml_escape(j.get<std::string>());
  if (j.is_array()) {
    std::string s;
    for (std::size_t i = 0; i < j.size(); ++i) s += (i ? ", " : "") + text_of(j[i]);
    return s;
  }
  return io::xml_escape(j.dump());
}

const nlohmann::json& at(const nlohmann::json& j, std::initializer_list<const char*> path) {
  static const nlohmann::json null;
  const nlohmann::json* p = &j;
  for (const char* k : path) {
    if (!p->is_object() || !p->contains(k)) return null;
    p = &(*p)[k];
  }
  return *p;
}

struct Table {
  std::ostringstream html;
  explicit Table(const std::string& title) { html << "<h2>" << io::xml_escape(title) << "</h2>\n<table>\n"; }
  void row(const std::string& key, const std::string& value_html) {
    if (value_html.empty() || value_html == "&ndash;") return;
    html << "<tr><th>" << io::xml_escape(key) << "</th><td>" << value_html << "</td></tr>\n";
  }
  std::string str() { return html.str() + "</table>\n"; }
};

std::string caption_of(const std::string& name, StrainMeasure measure) {
  const std::string m = measure_name(measure);
  static const std::map<std::string, std::string> captions = {
      {"arrows_undeformed.png",
       "Principal strain arrows on the undeformed blank: the material directions that become the "
       "major and minor directions."},
      {"arrows_deformed.png", "Principal strain arrows on the formed part."},
      {"thickness.png", "Thickness change in percent, assuming an incompressible sheet."},
      {"major_strain.png", "Major principal strain on the formed part."},
      {"minor_strain.png", "Minor principal strain on the formed part."},
      {"shear_angle.png", "Trellis shear angle between the fibre families on the formed part."},
      {"fibres.png", "Current directions of both fibre families on the formed part."},
      {"zones.png",
       "Forming-limit zones on the formed part: failure (above the forming limit curve), necking risk (within the "
       "margin below it), excess thinning, compression (wrinkling tendency), insufficient stretch, safe."},
      {"principal_strains.png",
       "Major against minor strain, one dot per analysed mark, with the reference lines of "
       "equibiaxial, plane-strain, uniaxial-tension and pure-shear deformation."},
  };
  const auto it = captions.find(name);
  std::string c = it == captions.end() ? name : it->second;
  if (name.rfind("section_", 0) == 0)
    c = "Major, minor and thickness strain along " + name.substr(0, name.size() - 4) +
        " against the arc length on the formed part (every point in " + name.substr(0, name.size() - 4) + ".csv).";
  if (name.find("strain") != std::string::npos || name.find("arrows") != std::string::npos)
    c += " Strain measure: " + m + ".";
  return c;
}

// The page's head, style and header line.
void page_head(std::ostream& h, const nlohmann::json& s, const ReportPage& page) {
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<title>gsa report: " << io::xml_escape(page.case_name) << "</title>\n<style>\n"
    << "body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,Arial,sans-serif;margin:0;color:#222;"
       "background:#fafafa}\n"
    << "header{padding:14px 24px;background:#fff;border-bottom:1px solid #ddd}\n"
    << "h1{font-size:1.4em;margin:0 0 4px}h2{font-size:1.05em;margin:18px 0 6px}\n"
    << ".page{display:flex;gap:24px;padding:16px 24px;align-items:flex-start}\n"
    << "aside{flex:0 0 360px;position:sticky;top:12px;background:#fff;border:1px solid #ddd;"
       "padding:4px 14px 14px;font-size:0.9em}\n"
    << "main{flex:1 1 auto;display:flex;flex-wrap:wrap;gap:18px}\n"
    << "figure{margin:0;background:#fff;border:1px solid #ddd;padding:8px;flex:1 1 560px;max-width:900px}\n"
    << "figure img{width:100%;height:auto;display:block}\n"
    << "figcaption{font-size:0.88em;color:#444;margin-top:6px}\n"
    << "table{border-collapse:collapse;width:100%}th,td{text-align:left;padding:2px 6px;"
       "border-bottom:1px solid #eee;vertical-align:top}th{font-weight:600;color:#444;width:45%}\n"
    << ".files a{margin-right:10px}.warn{color:#a40}\n"
    << "@media (max-width:1000px){.page{flex-direction:column}aside{position:static;flex:none;width:auto}}\n"
    << "</style>\n</head>\n<body>\n";
  h << "<header><h1>Grid strain analysis: " << io::xml_escape(page.case_name) << "</h1>\n<div>"
    << text_of(at(s, {"tool"})) << " " << text_of(at(s, {"version"})) << " &middot; pictures in "
    << io::xml_escape(measure_name(page.measure)) << " strain &middot; <span class=\"files\">files: "
    << "<a href=\"strains.csv\">strains.csv</a><a href=\"summary.json\">summary.json</a>";
  if (page.pictures.size() > 1)
    h << "<a href=\"undeformed.vtp\">undeformed.vtp</a><a href=\"deformed.vtp\">deformed.vtp</a>";
  h << "</span></div></header>\n<div class=\"page\">\n<aside>\n";
}

// The summary's inputs and parameters.
void parameter_tables(std::ostream& h, const nlohmann::json& s) {
  {
    Table t("Inputs");
    t.row("grid file(s)", text_of(at(s, {"inputs"})));
    t.row("command", text_of(at(s, {"command_line"})));
    t.row("length unit", text_of(at(s, {"units", "length"})));
    h << t.str();
  }
  {
    Table t("Parameters");
    const auto& p = at(s, {"parameters"});
    t.row("method", text_of(at(p, {"method"})));
    t.row(
        "mesh",
        text_of(at(p, {"mesh", "grid"})) +
            (at(p, {"mesh", "elements"}).is_null() ? "" : " (" + text_of(at(p, {"mesh", "elements"})) + " elements)"));
    t.row("element", text_of(at(p, {"mesh", "element_type"})));
    t.row("smoothing", text_of(at(p, {"penalty"})));
    t.row("automatic weights", text_of(at(p, {"smoothing_automatic"})));
    for (const char* which : {"undeformed", "deformed"}) {
      const auto& w = at(p, {which});
      if (w.is_object())
        t.row(std::string("weights, ") + which + " fit",
              "&alpha; " + text_of(at(w, {"alpha"})) + ", &beta; " + text_of(at(w, {"beta"})) + ", &gamma; " +
                  text_of(at(w, {"gamma"})) + ", &delta; " + text_of(at(w, {"delta"})));
    }
    const std::string unit = at(s, {"units", "length"}).is_string() ? " " + text_of(at(s, {"units", "length"})) : "";
    if (at(p, {"noise_estimate"}).is_number()) t.row("noise estimate", text_of(at(p, {"noise_estimate"})) + unit);
    if (at(p, {"mark_spacing"}).is_number()) t.row("mark spacing", text_of(at(p, {"mark_spacing"})) + unit);
    if (at(p, {"gauge_length"}).is_number()) t.row("gauge length", text_of(at(p, {"gauge_length"})) + unit);
    if (at(p, {"rigid_motion"}).is_object())
      t.row("rigid motion, undeformed to deformed (best fit)",
            "rotation " + text_of(at(p, {"rigid_motion", "rotation_deg"})) + "&deg;, translation " +
                text_of(at(p, {"rigid_motion", "translation"})) + unit);
    if (at(p, {"smoothing", "criterion"}).is_string())
      t.row("smoothing chosen by",
            text_of(at(p, {"smoothing", "criterion"})) + " = " + text_of(at(p, {"smoothing", "criterion_value"})) +
                " at log10(&delta;/d<sup>6</sup>) " + text_of(at(p, {"smoothing", "log10_delta_optimum"})));
    if (at(p, {"smoothing", "local_gauge_length"}).is_number())
      t.row("locally relaxed smoothing", text_of(at(p, {"smoothing", "relaxed_elements"})) +
                                             " elements, gauge length there " +
                                             text_of(at(p, {"smoothing", "local_gauge_length"})) + unit);
    for (const char* which : {"undeformed", "deformed"}) {
      const auto& n = at(p, {"noise_model", which});
      if (n.is_object())
        t.row(std::string("noise model, ") + which, "correlated " + text_of(at(n, {"sigma_correlated"})) + unit +
                                                        " over " + text_of(at(n, {"correlation_length"})) + unit +
                                                        ", independent " + text_of(at(n, {"sigma_white"})) + unit);
    }
    t.row("outlier threshold (sigmas)", text_of(at(p, {"outlier_sigma"})));
    t.row("fibre angles (deg)", text_of(at(p, {"fibre_angles_deg"})));
    t.row("triangles", text_of(at(p, {"triangles"})));
    h << t.str();
  }
}

// Fit residuals, mark counts, strain ranges, the forming limit and warnings.
void result_tables(std::ostream& h, const nlohmann::json& s, const ReportPage& page) {
  if (at(s, {"fit"}).is_object()) {
    Table t("Fit residuals");
    const std::string unit = at(s, {"units", "length"}).is_string() ? " " + text_of(at(s, {"units", "length"})) : "";
    for (const char* which : {"undeformed", "deformed"})
      t.row(std::string(which) + " (RMS / max)", text_of(at(s, {"fit", which, "rms_residual"})) + " / " +
                                                     text_of(at(s, {"fit", which, "max_residual"})) + unit);
    h << t.str();
  }
  {
    Table t("Marks");
    t.row("points", text_of(at(s, {"counts", "points"})));
    const auto& by = at(s, {"counts", "by_status"});
    if (by.is_object())
      for (auto it = by.begin(); it != by.end(); ++it) t.row(it.key(), text_of(it.value()));
    h << t.str();
  }
  {
    const auto& r = at(s, {"strain_ranges"});
    if (r.is_object()) {
      h << "<h2>Strain ranges at the marks</h2>\n<p>E: Green-Lagrange, eng: engineering, true: logarithmic "
           "strain; the pictures show "
        << io::xml_escape(measure_name(page.measure))
        << " strain.</p>\n<table>\n<tr><th>field</th><td><b>min</b></td><td><b>max</b></td></tr>\n";
      for (auto it = r.begin(); it != r.end(); ++it)
        h << "<tr><th>" << io::xml_escape(it.key()) << "</th><td>" << text_of(at(it.value(), {"min"})) << "</td><td>"
          << text_of(at(it.value(), {"max"})) << "</td></tr>\n";
      h << "</table>\n";
    }
  }
  if (page.flc) {
    Table t("Forming limit");
    t.row("curve", io::xml_escape(page.flc->source));
    t.row("marks beyond the curve", std::to_string(page.flc->n_beyond) + " of " + std::to_string(page.flc->n_marks));
    t.row("smallest margin (" + measure_name(page.measure) + " strain)", number(page.flc->min_margin));
    t.row("per mark", "column <code>flc_margin</code> of strains.csv");
    h << t.str();
  }
  {
    const auto& f = at(s, {"outliers", "flagged"});
    if (f.is_array() && !f.empty()) {
      const std::string unit = at(s, {"units", "length"}).is_string() ? " " + text_of(at(s, {"units", "length"})) : "";
      h << "<h2>Flagged marks (" << f.size()
        << ")</h2>\n<p>Isolated points their neighbours disagree with; "
           "each keeps the fitted surfaces' strain and took no part in the fit. Drawn as crosses on the "
           "major strain picture.</p>\n<table>\n<tr><th>id</th><td><b>reason</b></td><td><b>off by / threshold"
        << unit << "</b></td></tr>\n";
      std::size_t shown = 0;
      for (const auto& x : f) {
        if (++shown > 50) break;
        h << "<tr><th>" << text_of(at(x, {"id"})) << "</th><td>" << text_of(at(x, {"reason"})) << "</td><td>"
          << text_of(at(x, {"deviation"})) << " / " << text_of(at(x, {"threshold"})) << "</td></tr>\n";
      }
      h << "</table>\n";
      if (f.size() > 50) h << "<p>" << f.size() - 50 << " more in summary.json and strains.csv.</p>\n";
    }
  }
  {
    const auto& w = at(s, {"warnings"});
    if (w.is_array() && !w.empty()) {
      h << "<h2>Warnings</h2>\n<ul>\n";
      for (const auto& x : w) h << "<li class=\"warn\">" << text_of(x) << "</li>\n";
      h << "</ul>\n";
    }
  }
}

// Every picture with its caption.
void figures(std::ostream& h, const ReportPage& page) {
  h << "</aside>\n<main>\n";
  h << page.view3d_html;
  if (page.view3d_html.empty() && !page.view3d_note.empty())
    h << "<p class=\"warn\" style=\"flex:1 1 100%\">No 3-D view: " << io::xml_escape(page.view3d_note) << "</p>\n";
  for (const std::string& name : page.pictures)
    h << "<figure><a href=\"" << io::xml_escape(name) << "\"><img src=\"" << io::xml_escape(name) << "\" alt=\""
      << io::xml_escape(caption_of(name, page.measure)) << "\"></a>\n<figcaption>"
      << io::xml_escape(caption_of(name, page.measure)) << "</figcaption></figure>\n";
  if (page.pictures.size() == 1)
    h << "<p>The triangle method has no fitted surfaces: only the principal strain plot is drawn. "
         "Run with <code>--method surface</code> for arrow diagrams and contours.</p>\n";
  h << "</main>\n</div>\n</body>\n</html>\n";
}

}  // namespace

// Mid-surface strains, the forming-limit assessment and the sections (summary.json
// "mid_surface", "forming_limit", "sections"; issue 17).
void press_tables(std::ostream& h, const nlohmann::json& s) {
  const std::string unit = at(s, {"units", "length"}).is_string() ? " " + text_of(at(s, {"units", "length"})) : "";
  if (const auto& m = at(s, {"mid_surface"}); m.is_object()) {
    Table t("Mid-surface strains");
    t.row("initial thickness", text_of(at(m, {"initial_thickness"})) + unit);
    t.row("grid on the", text_of(at(m, {"grid_face"})) + " face");
    t.row("mid-surface major (" + text_of(at(m, {"measure"})) + ")",
          text_of(at(m, {"mid_major", "min"})) + " .. " + text_of(at(m, {"mid_major", "max"})));
    t.row("mid-surface minor", text_of(at(m, {"mid_minor", "min"})) + " .. " + text_of(at(m, {"mid_minor", "max"})));
    t.row("current thickness",
          text_of(at(m, {"thickness", "min"})) + " .. " + text_of(at(m, {"thickness", "max"})) + unit);
    h << t.str();
  }
  if (const auto& f = at(s, {"forming_limit"}); f.is_object()) {
    Table t("Forming-limit assessment");
    t.row("curve", text_of(at(f, {"curve"})));
    t.row("assessed on", text_of(at(f, {"strains"})) + " strains (" + text_of(at(f, {"measure"})) + ")");
    t.row("smallest major margin", text_of(at(f, {"min_margin"})));
    t.row("smallest radial margin", text_of(at(f, {"min_radial_margin"})));
    const auto& z = at(f, {"zones"});
    if (z.is_object())
      for (auto it = z.begin(); it != z.end(); ++it) t.row("zone " + it.key(), text_of(it.value()) + " marks");
    t.row("per mark",
          "columns <code>flc_margin</code>, <code>flc_radial_margin</code>, <code>zone</code> of "
          "strains.csv");
    h << t.str();
  }
  if (const auto& secs = at(s, {"sections"}); secs.is_array() && !secs.empty()) {
    Table t("Sections");
    for (const auto& x : secs) {
      std::string v = "<a href=\"" + text_of(at(x, {"file"})) + "\">" + text_of(at(x, {"file"})) +
                      "</a>: " + text_of(at(x, {"definition"})) + ", " + text_of(at(x, {"length_deformed"})) + unit +
                      " on the part";
      if (at(x, {"neck", "limit_major"}).is_number())
        v += "; neck limit strains " + text_of(at(x, {"neck", "limit_major"})) + " / " +
             text_of(at(x, {"neck", "limit_minor"}));
      else if (at(x, {"neck", "error"}).is_string())
        v += "; neck: " + text_of(at(x, {"neck", "error"}));
      t.row(text_of(at(x, {"name"})), v);
    }
    h << t.str();
  }
}

void write_report(const std::string& path, const nlohmann::json& summary, const ReportPage& page) {
  std::ostringstream h;
  page_head(h, summary, page);
  parameter_tables(h, summary);
  result_tables(h, summary, page);
  press_tables(h, summary);
  figures(h, page);
  io::write_file_atomic(path, h.str());
}

}  // namespace sf::gsa

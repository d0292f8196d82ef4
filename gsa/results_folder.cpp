#include "gsa/results_folder.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <optional>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/json.hpp"

namespace sf::gsa {

namespace fs = std::filesystem;

ResultsFolder read_results_folder(const std::string& dir) {
  ResultsFolder r;
  r.dir = dir;
  const fs::path d(dir);
  const std::string strains = (d / "strains.csv").string();
  if (!fs::exists(strains)) throw InputError(dir + ": no strains.csv here; give a folder written by `gsa analyse`");
  r.strains = io::read_csv(strains);
  const std::string summary = (d / "summary.json").string();
  if (fs::exists(summary)) r.summary = io::read_json(summary);
  const std::string u = (d / "undeformed.vtp").string(), v = (d / "deformed.vtp").string();
  // One surface without the other: the folder is incomplete (a file removed or lost).
  if (fs::exists(u) != fs::exists(v))
    throw InputError((fs::exists(u) ? v : u) + ": missing beside " + (fs::exists(u) ? u : v) +
                     "; the results folder is incomplete (rerun gsa analyse)");
  if (fs::exists(u) && fs::exists(v)) {
    r.undeformed = io::read_vtp(u);
    r.deformed = io::read_vtp(v);
    if (r.undeformed.n_points() != r.deformed.n_points() || r.undeformed.polygons.size() != r.deformed.polygons.size())
      throw InputError(v + ": does not match " + u + " point for point; rerun gsa analyse");
    r.has_surfaces = r.undeformed.n_points() > 0 && !r.undeformed.polygons.empty();
  }
  return r;
}

std::string units_of(const nlohmann::json& summary) {
  if (summary.contains("units") && summary["units"].contains("length") && summary["units"]["length"].is_string())
    return summary["units"]["length"].get<std::string>();
  return "mm";
}

std::vector<double> fibre_angles_of(const nlohmann::json& summary) {
  std::vector<double> out;
  const auto& params = summary.contains("parameters") ? summary["parameters"] : nlohmann::json();
  if (params.is_object() && params.contains("fibre_angles_deg") && params["fibre_angles_deg"].is_array())
    for (const auto& a : params["fibre_angles_deg"])
      if (a.is_number()) out.push_back(a.get<double>());
  return out;
}

std::string case_name_of(const nlohmann::json& summary, const std::string& dir) {
  if (summary.contains("inputs") && summary["inputs"].is_array() && !summary["inputs"].empty()) {
    // One grid file, or the undeformed and deformed files of a two-file run.
    std::string name;
    for (const auto& input : summary["inputs"]) {
      if (!input.is_string()) continue;
      const fs::path p = input.get<std::string>();
      const std::string parent = p.parent_path().filename().string();
      const std::string one = parent.empty() ? p.filename().string() : parent + "/" + p.filename().string();
      name += (name.empty() ? "" : " \xE2\x86\x92 ") + one;
    }
    if (!name.empty()) return name;
  }
  return fs::path(dir).filename().string();
}

MarkStrains mark_strains(const io::CsvTable& t, StrainMeasure m) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const auto names = measure_fields(m);
  const std::size_t c1 = t.column_index(names[0]), c2 = t.column_index(names[1]);
  const auto cs = t.find_column("status");
  MarkStrains out;
  for (std::size_t row = 0; row < t.n_rows(); ++row) {
    double e1 = kNaN, e2 = kNaN;
    if (!cs || t.cell(row, *cs) == "ok") {
      e1 = t.number(row, c1, true);
      e2 = t.number(row, c2, true);
    }
    out.major.push_back(e1);
    out.minor.push_back(e2);
  }
  return out;
}

MarkStrains assessed_mark_strains(const ResultsFolder& folder, StrainMeasure m) {
  MarkStrains out = mark_strains(folder.strains, m);
  const io::CsvTable& t = folder.strains;
  const auto c1 = t.find_column("mid_major"), c2 = t.find_column("mid_minor");
  const nlohmann::json& s = folder.summary;
  if (!c1 || !c2 || !s.is_object() || !s.contains("mid_surface") || !s["mid_surface"].is_object()) return out;
  const std::string written = s["mid_surface"].value("measure", std::string());
  std::optional<StrainMeasure> from;
  for (StrainMeasure k : {StrainMeasure::kTrue, StrainMeasure::kEngineering, StrainMeasure::kLagrangian})
    if (measure_word(k) == written) from = k;
  if (!from)
    throw InputError(folder.dir + "/summary.json: mid_surface.measure '" + written +
                     "' is not a strain measure (true, engineering, lagrangian)");
  // A principal strain in one measure to the other through its stretch.
  auto convert = [&](double e) {
    if (!std::isfinite(e)) return e;
    const double l = *from == StrainMeasure::kTrue          ? std::exp(e)
                     : *from == StrainMeasure::kEngineering ? 1.0 + e
                                                            : std::sqrt(1.0 + 2.0 * e);
    return strain_of_stretch(l, m);
  };
  for (std::size_t row = 0; row < t.n_rows() && row < out.major.size(); ++row) {
    if (!std::isfinite(out.major[row])) continue;  // not analysed
    out.major[row] = convert(t.number(row, *c1, true));
    out.minor[row] = convert(t.number(row, *c2, true));
  }
  return out;
}

void write_strains_with_margin(const ResultsFolder& folder, const std::string& out, const FlcMargins& margins,
                               bool keep_zones) {
  const io::CsvTable& t = folder.strains;
  // Keep the leading comment lines of the original file (but an earlier margin's).
  std::vector<std::string> comments;
  {
    std::ifstream in(fs::path(folder.dir) / "strains.csv");
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.rfind('#', 0) != 0) break;
      if (line.rfind("# flc_margin", 0) == 0 || (!keep_zones && line.rfind("# flc_radial_margin", 0) == 0)) continue;
      comments.push_back(line);
    }
  }
  // The margin goes where it was when the zones stay (same columns as gsa analyse wrote),
  // else last; the zones of an earlier curve go with it (gsa analyse writes them anew).
  constexpr std::size_t kMargin = static_cast<std::size_t>(-1);
  std::vector<std::string> header;
  std::vector<std::size_t> keep;
  bool placed = false;
  for (std::size_t c = 0; c < t.n_columns(); ++c) {
    const std::string& name = t.names()[c];
    if (name == "flc_margin") {
      if (!keep_zones) continue;
      placed = true;
      header.push_back(name);
      keep.push_back(kMargin);
    } else if (keep_zones || (name != "flc_radial_margin" && name != "zone")) {
      header.push_back(name);
      keep.push_back(c);
    }
  }
  if (!placed) {
    header.push_back("flc_margin");
    keep.push_back(kMargin);
  }
  io::write_file_atomic(out, [&](std::ostream& os) {
    for (const auto& c : comments) os << c << "\n";
    os << flc_margin_comment(margins) << "\n";
    io::CsvWriter w(os, header);
    for (std::size_t r = 0; r < t.n_rows(); ++r) {
      w.begin_row();
      for (std::size_t c : keep) {
        if (c == kMargin)
          w.add(r < margins.margin.size() ? margins.margin[r] : std::nan(""));
        else
          w.add(t.cell(r, c));
      }
      w.end_row();
    }
  });
}

}  // namespace sf::gsa

#include "gsa/command_options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/core/error.hpp"
#include "common/io/grid_file.hpp"
#include "common/io/measurement_formats.hpp"
#include "common/render/scene.hpp"
#include "gsa/flc.hpp"

namespace sf::gsa {

namespace {

std::vector<double> parse_angles(const std::string& text) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--fibres: expected angles in degrees separated by commas (e.g. 0,90), found '" + item + "'");
    }
  }
  return out;
}

// "--elements NxM" into the mesh options.
void parse_elements(const std::string& text, MeshOptions& mesh) {
  const auto x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument("x");
    mesh.elements1 = std::stoi(text.substr(0, x));
    mesh.elements2 = std::stoi(text.substr(x + 1));
  } catch (const std::exception&) {
    throw UsageError("--elements: expected NxM (e.g. 8x6), found '" + text + "'");
  }
  if (mesh.elements1 < 1 || mesh.elements2 < 1) throw UsageError("--elements: counts must be >= 1");
}

Method parse_method(const std::string& text) {
  if (text == "surface") return Method::kSurface;
  if (text == "triangles") return Method::kTriangles;
  throw UsageError("--method: expected 'surface' or 'triangles', found '" + text + "'");
}

PenaltyKind parse_penalty(const std::string& text) {
  if (text == "third") return PenaltyKind::kThirdOrder;
  if (text == "sobolev") return PenaltyKind::kSobolev;
  if (text == "jumps") return PenaltyKind::kJumps;
  throw UsageError("--penalty: expected 'third', 'jumps' or 'sobolev', found '" + text + "'");
}

SmoothingRule parse_smoothing_rule(const std::string& text) {
  if (text == "noise-model") return SmoothingRule::kNoiseModel;
  if (text == "gcv") return SmoothingRule::kGcv;
  throw UsageError("--smoothing-rule: expected 'noise-model' or 'gcv', found '" + text + "'");
}

// Runs a library validate() and turns its field into the user's flag.
template <class Options>
void validate_for_the_command_line(const Options& options) {
  try {
    options.validate();
  } catch (const OptionError& e) {
    throw UsageError(flag_of_field(e.field()) + ": " + e.problem());
  }
}

std::string number_text(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

}  // namespace

void check_units_text(const std::string& units) {
  if (units.size() > 40)
    throw UsageError("--units: expected a short length unit such as mm, found " + std::to_string(units.size()) +
                     " characters");
  for (const char c : units)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == ',' || c == '"')
      throw UsageError(
          "--units: expected a length unit such as mm (no line breaks, control characters, commas or quotes)");
}

std::string flag_of_field(const std::string& field) {
  static const std::map<std::string, std::string> flags = {
      {"mesh.elements1", "--elements"},
      {"mesh.elements2", "--elements"},
      {"mesh.file", "--mesh"},
      {"smoothing.alpha", "--alpha"},
      {"smoothing.beta", "--beta"},
      {"smoothing.gamma", "--gamma"},
      {"smoothing.delta", "--delta"},
      {"smoothing.scale", "--smoothing-scale"},
      {"outliers.sigma", "--outlier-sigma"},
      {"fibre_angles", "--fibres"},
      {"sample", "--sample"},
      {"units", "--units"},
      {"necking_margin", "--necking-margin"},
      {"thinning_limit_pct", "--thinning-limit"},
      {"min_stretch", "--min-stretch"},
  };
  const auto it = flags.find(field);
  return it == flags.end() ? field : it->second;
}

AnalyseOptions analyse_options(const AnalyseFlags& a) {
  AnalyseOptions o;
  o.method = parse_method(a.method);
  o.smoothing.penalty = parse_penalty(a.penalty);
  o.smoothing.rule = parse_smoothing_rule(a.smoothing_rule);
  o.smoothing.local = !a.no_local_smoothing;
  if (!a.mesh.empty() && !a.elements.empty()) throw UsageError("give either --mesh or --elements, not both");
  o.mesh.file = a.mesh;
  if (!a.elements.empty()) parse_elements(a.elements, o.mesh);
  o.smoothing.alpha = a.alpha;
  o.smoothing.beta = a.beta;
  o.smoothing.gamma = a.gamma;
  o.smoothing.delta = a.delta;
  o.smoothing.scale = a.smoothing_scale;
  o.outliers.sigma = a.outlier_sigma;
  o.sigma_weights = !a.no_sigma_weights;
  if (!a.fibres.empty()) o.fibre_angles = parse_angles(a.fibres);
  validate_for_the_command_line(o);
  return o;
}

OutputOptions output_options(const AnalyseFlags& a) {
  check_units_text(a.units);
  OutputOptions o;
  o.units = a.units;
  o.sample = a.sample;
  o.measure = parse_measure(a.measure, "--measure");
  if (a.thickness) {
    if (!std::isfinite(*a.thickness) || !(*a.thickness > 0))
      throw UsageError("--thickness: expected the initial sheet thickness in " + a.units + " (> 0), found " +
                       number_text(*a.thickness));
    o.mid.thickness = *a.thickness;
  }
  o.mid.face = parse_grid_face(a.grid_face, "--grid-face");
  const int curves = (a.flc.empty() ? 0 : 1) + (a.flc_n ? 1 : 0) + (a.flc0 ? 1 : 0);
  if (curves > 1) throw UsageError("--flc, --flc-n and --flc0 each give a forming limit curve: give one of them");
  if (!a.flc.empty()) o.flc = read_flc(a.flc);
  if (a.flc_n) {
    if (!a.thickness)
      throw UsageError("--flc-n: the Keeler-Brazier curve needs the sheet thickness: add --thickness T (mm)");
    const double flc0 = keeler_brazier_flc0(*a.thickness, *a.flc_n, "--flc-n", "--thickness");
    o.flc_description = "Keeler-Brazier, t = " + number_text(*a.thickness) + " mm, n = " + number_text(*a.flc_n) +
                        ": FLC0 = " + number_text(flc0) + " (engineering), standard shape";
    o.flc = standard_shape_flc(flc0, o.measure, o.flc_description);
  }
  if (a.flc0) {
    if (!std::isfinite(*a.flc0) || !(*a.flc0 > 0))
      throw UsageError(
          "--flc0: expected the plane-strain forming limit, a major strain > 0 in the --measure strain, "
          "found " +
          number_text(*a.flc0));
    // Given in the measure of the analysis; the shape is tabulated in engineering strain.
    const double eng = (o.measure == StrainMeasure::kTrue          ? std::exp(*a.flc0)
                        : o.measure == StrainMeasure::kEngineering ? 1.0 + *a.flc0
                                                                   : std::sqrt(1.0 + 2.0 * *a.flc0)) -
                       1.0;
    o.flc_description = "FLC0 = " + number_text(*a.flc0) + " (" + measure_word(o.measure) + "), standard shape";
    o.flc = standard_shape_flc(eng, o.measure, o.flc_description);
  }
  o.zones.necking_margin = a.necking_margin;
  o.zones.thinning_limit_pct = a.thinning_limit;
  o.zones.min_stretch = a.min_stretch;
  validate_for_the_command_line(o.zones);
  for (std::size_t k = 0; k < a.sections.size(); ++k)
    o.sections.push_back(parse_section(a.sections[k], "--section " + std::to_string(k + 1)));
  o.neck = a.neck;
  if (a.neck && a.sections.empty())
    throw UsageError("--neck: evaluates a neck along a section: give one or more --section");
  validate_for_the_command_line(o);
  return o;
}

PlotOptions plot_options(const std::string& size, const std::string& view) {
  PlotOptions o;
  o.size = render::parse_size(size, "--size");
  o.fit_height = size == "1200x900";  // the default: cut to a long part's proportions
  o.view = render::parse_view(view, "--view");
  return o;
}

StrainMeasure parse_measure(const std::string& text, const std::string& option) {
  std::string t = text;
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
  if (t == "true" || t == "logarithmic" || t == "natural") return StrainMeasure::kTrue;
  if (t == "engineering") return StrainMeasure::kEngineering;
  if (t == "lagrangian" || t == "green") return StrainMeasure::kLagrangian;
  throw UsageError(option + ": expected true, engineering or lagrangian, found '" + text + "'");
}

GridReadOptions grid_read_options(const AnalyseFlags& a) {
  GridReadOptions o;
  o.format = parse_format(a.format);
  o.delimiter = parse_delimiter(a.delimiter);
  if (!a.columns.empty()) o.columns = parse_column_map(a.columns);
  if (a.id == "row") {
    o.id_from_row = true;
  } else if (!a.id.empty()) {
    o.id_columns = parse_id_columns(a.id);
  }
  if (!a.id.empty() && o.columns.count("id"))
    throw UsageError("--id: the id is given twice, also as --columns id=" + o.columns.at("id") + "; give one");
  if (a.positions == "reference")
    o.positions = io::Positions::kReference;
  else if (a.positions == "current")
    o.positions = io::Positions::kCurrent;
  else if (!a.positions.empty())
    throw UsageError("--positions: expected 'reference' or 'current', found '" + a.positions + "'");
  if (o.positions != io::Positions::kAsFormat && o.format == io::MeasurementFormat::kPlain)
    throw UsageError(
        "--positions: applies to --format gom, matchid, vic3d or dice; with a plain file, name the "
        "position columns X,Y,Z (reference) or x,y,z (current) in --columns");
  if (a.decimal == "auto")
    o.decimal = io::kDetectDecimal;
  else if (a.decimal == "point" || a.decimal == ".")
    o.decimal = '.';
  else if (a.decimal == "comma" || a.decimal == ",")
    o.decimal = ',';
  else
    throw UsageError("--decimal: expected 'auto', 'point' or 'comma', found '" + a.decimal + "'");
  if (o.decimal == ',' && o.delimiter == ',')
    throw UsageError(
        "--decimal comma: the delimiter cannot be a comma too (give --delimiter semicolon, or leave it auto)");
  if (a.skip_lines < 0) throw UsageError("--skip-lines: must be >= 0, found " + std::to_string(a.skip_lines));
  if (a.header_line < 0) throw UsageError("--header-line: must be >= 1, found " + std::to_string(a.header_line));
  if (a.header_line > 0 && a.skip_lines > 0) throw UsageError("give either --skip-lines or --header-line, not both");
  o.skip_lines = a.skip_lines;
  o.header_line = a.header_line;
  if (a.units.empty()) throw UsageError("--units: empty");
  check_units_text(a.units);
  o.units = a.units;
  if (!std::isnan(a.pixel_size) && !(a.pixel_size > 0 && std::isfinite(a.pixel_size)))
    throw UsageError("--pixel-size: must be > 0 (length units per pixel), found " + std::to_string(a.pixel_size));
  o.pixel_size = a.pixel_size;
  if (!std::isnan(a.pitch) && !(a.pitch > 0 && std::isfinite(a.pitch)))
    throw UsageError("--pitch: must be > 0, found " + std::to_string(a.pitch));
  o.pitch = a.pitch;
  if (!std::isnan(a.pitch) && (o.columns.count("X") || o.columns.count("Y") || o.columns.count("Z")))
    throw UsageError("--pitch: gives the undeformed positions X, Y, Z; do not map them in --columns too");
  if (!std::isnan(a.pitch) && !a.undeformed.empty())
    throw UsageError("--pitch: gives the undeformed positions; give no --undeformed file with it");
  try {
    o.validate();  // what is left: contradictions inside --columns
  } catch (const UsageError& e) {
    std::string m = e.what();
    const std::string prefix = "GridReadOptions::columns: ";
    if (m.rfind(prefix, 0) == 0) m = "--columns: " + m.substr(prefix.size());
    throw UsageError(m);
  }
  return o;
}

io::MeasurementFormat parse_format(const std::string& text) {
  if (const auto f = io::format_by_name(text)) return *f;
  throw UsageError("--format: unknown format '" + text + "' (expected one of " + io::format_names() + ")");
}

namespace {

// Splits  a,b,"c, d"  at the commas outside double quotes; the quotes are removed.
std::vector<std::string> split_outside_quotes(const std::string& text) {
  std::vector<std::string> items(1);
  bool quoted = false;
  for (const char c : text) {
    if (c == '"')
      quoted = !quoted;
    else if (c == ',' && !quoted)
      items.emplace_back();
    else
      items.back() += c;
  }
  return items;
}

}  // namespace

std::vector<std::string> parse_id_columns(const std::string& text) {
  std::vector<std::string> out = split_outside_quotes(text);
  for (const std::string& name : out)
    if (name.empty())
      throw UsageError("--id: expected column names separated by commas (e.g. x_pic,y_pic) or 'row', found '" + text +
                       "'");
  return out;
}

std::map<std::string, std::string> parse_column_map(const std::string& text) {
  std::map<std::string, std::string> out;
  for (const std::string& item : split_outside_quotes(text)) {
    const std::size_t eq = item.find('=');
    if (item.empty() || eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw UsageError("--columns: expected NAME=COLUMN pairs separated by commas (e.g. X=x0,u=disp_x), found '" +
                       item + "'");
    const std::string key = item.substr(0, eq);
    if (!io::is_grid_column_key(key))
      throw UsageError("--columns: unknown name '" + key + "' (expected one of id X Y Z x y z u v w i j sigma)");
    out[key] = item.substr(eq + 1);
  }
  return out;
}

char parse_delimiter(const std::string& text) {
  if (text == "auto") return io::kDetectDelimiter;
  if (text == "tab" || text == "\\t") return '\t';
  if (text == "comma") return ',';
  if (text == "semicolon") return ';';
  if (text == "space") return ' ';
  if (text.size() == 1 && text[0] != '"' && text[0] != '#') return text[0];
  throw UsageError("--delimiter: expected one character (not '\"' or '#') or auto/tab/comma/semicolon/space, found '" +
                   text + "'");
}

}  // namespace sf::gsa

#include "common/io/grid_rows.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/io/length_units.hpp"

namespace sf::io::detail {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

enum Triple : int { kReference = 0, kCurrent = 1, kDisplacement = 2 };
const std::array<std::array<const char*, 3>, 3> kTripleKeys = {{{"X", "Y", "Z"}, {"x", "y", "z"}, {"u", "v", "w"}}};
const std::array<const char*, 3> kTripleWords = {"reference positions", "current positions", "displacements"};

// A column layout to try: which triples, by name, and where they came from.
struct Candidate {
  std::array<std::optional<ColumnTriple>, 3> triples;
  bool pixels = false;
};

std::string join(const std::vector<std::string>& parts, const char* sep = ", ") {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : sep) + p;
  return out;
}

std::string triple_text(const ColumnTriple& t) {
  std::vector<std::string> parts;
  for (const std::string& n : t)
    if (!n.empty()) parts.push_back(n);
  return join(parts);
}

// The header's names with their units split off, and lookups by full or base name.
class Header {
 public:
  // Hashed lookups (the first column of a name wins): the header test runs on up to 1000
  // lines of every format, so a lookup must not cost a pass over a line's fields.
  explicit Header(const std::vector<std::string>& names) : names_(names) {
    split_.reserve(names.size());
    by_name_.reserve(names.size());
    for (std::size_t c = 0; c < names.size(); ++c) {
      split_.push_back(split_unit(names[c]));
      by_name_.emplace(names[c], c);
      if (split_[c].has_unit) by_base_.emplace(split_[c].base, c);
    }
  }
  // The column named `name`, else the first whose name is `name` with a unit ("X [mm]").
  std::optional<std::size_t> find(const std::string& name) const {
    if (name.empty()) return std::nullopt;
    if (const auto it = by_name_.find(name); it != by_name_.end()) return it->second;
    if (const auto it = by_base_.find(name); it != by_base_.end()) return it->second;
    return std::nullopt;
  }
  const NameAndUnit& unit(std::size_t c) const { return split_[c]; }
  const std::string& name(std::size_t c) const { return names_[c]; }
  const std::vector<std::string>& names() const { return names_; }

 private:
  std::vector<std::string> names_;
  std::vector<NameAndUnit> split_;
  std::unordered_map<std::string, std::size_t> by_name_, by_base_;
};

// The resolved columns of one candidate layout, or why it did not resolve.
struct Plan {
  // Per triple: absent, or three columns (nothing: the planar z, taken as 0).
  std::array<std::optional<std::array<std::optional<std::size_t>, 3>>, 3> triples;
  bool pixels = false;
  bool planar = false;
  std::vector<std::size_t> id;  // empty: the row number
  std::optional<std::size_t> i, j, sigma, match, stage;
  Candidate candidate;
  // Failure: the first name not found and how many names were found before.
  std::string missing;
  std::string missing_why;
  int found = 0, n_missing = 0;
  int score() const { return found - n_missing; }
  bool ok() const { return missing.empty(); }
};

std::map<std::string, std::string>::const_iterator mapped(const GridReadOptions& o, const char* key) {
  return o.columns.find(key);
}

// The user's triple for `t` when --columns maps any of its keys (the others are their
// own names).
std::optional<ColumnTriple> user_triple(const GridReadOptions& o, int t) {
  ColumnTriple names;
  bool any = false;
  for (int k = 0; k < 3; ++k) {
    const auto it = mapped(o, kTripleKeys[t][k]);
    any = any || it != o.columns.end();
    names[k] = it != o.columns.end() ? it->second : kTripleKeys[t][k];
  }
  if (!any) return std::nullopt;
  return names;
}

// The layouts to try, in order (the format's, with --positions and --columns applied).
std::vector<Candidate> candidates(const FormatSpec& spec, const GridReadOptions& o, FileRole role) {
  std::array<std::optional<ColumnTriple>, 3> user;
  int n_user = 0;
  for (int t = 0; t < 3; ++t) {
    user[t] = user_triple(o, t);
    n_user += user[t] ? 1 : 0;
  }
  std::vector<Candidate> out;
  if (n_user >= 2) {
    Candidate c;
    c.triples = user;
    if (n_user == 3) c.triples[kCurrent].reset();  // validate() rejects this; X + u wins as before
    out.push_back(c);
  } else {
    for (const FormatLayout& layout : spec.layouts) {
      Candidate c;
      c.pixels = layout.pixels;
      const std::array<const ColumnTriple*, 3> from = {&layout.reference, &layout.current, &layout.displacement};
      for (int t = 0; t < 3; ++t)
        if (!(*from[t])[0].empty()) c.triples[t] = *from[t];
      // --positions: the position triple of a layout with displacements moves to the side asked for.
      if (o.positions != Positions::kAsFormat && c.triples[kDisplacement] &&
          (c.triples[kReference].has_value() != c.triples[kCurrent].has_value())) {
        const auto positions = c.triples[kReference] ? c.triples[kReference] : c.triples[kCurrent];
        c.triples[kReference].reset();
        c.triples[kCurrent].reset();
        c.triples[o.positions == Positions::kReference ? kReference : kCurrent] = positions;
      }
      for (int t = 0; t < 3; ++t)
        if (user[t]) {
          c.triples[t] = user[t];
          c.pixels = false;
        }
      int n = 0;
      for (const auto& t : c.triples) n += t ? 1 : 0;
      if (n == 3) {  // the user's triple wins: drop one of the format's, the current positions first
        for (const int t : {kCurrent, kReference, kDisplacement})
          if (!user[t]) {
            c.triples[t].reset();
            break;
          }
      }
      out.push_back(c);
    }
  }
  // A file of one state needs only its current positions; with a pitch, the reference
  // positions come from the grid indices.
  const bool pitch = std::isfinite(o.pitch);
  if (role == FileRole::kOneState || pitch) {
    std::vector<Candidate> more = out;
    for (const Candidate& c : more)
      if (c.triples[kCurrent] && (c.triples[kReference] || c.triples[kDisplacement])) {
        Candidate alone;
        alone.pixels = c.pixels;
        alone.triples[kCurrent] = c.triples[kCurrent];
        out.push_back(alone);
      }
    if (spec.format == MeasurementFormat::kPlain && n_user < 2 && !user[kReference] && !user[kDisplacement]) {
      Candidate alone;
      alone.triples[kCurrent] = user[kCurrent] ? *user[kCurrent] : ColumnTriple{"x", "y", "z"};
      out.push_back(alone);
    }
  }
  if (pitch)
    for (Candidate& c : out)
      if (c.triples[kCurrent]) {
        c.triples[kReference].reset();
        c.triples[kDisplacement].reset();
      }
  // Without duplicates, in order.
  std::vector<Candidate> unique;
  for (const Candidate& c : out) {
    const bool seen =
        std::any_of(unique.begin(), unique.end(), [&](const Candidate& u) { return u.triples == c.triples; });
    if (!seen) unique.push_back(c);
  }
  return unique;
}

Plan resolve(const Candidate& c, const Header& h, const FormatSpec& spec, const GridReadOptions& o, FileRole role,
             const std::string& stage_column) {
  Plan plan;
  plan.candidate = c;
  plan.pixels = c.pixels;
  // Every name is looked up (the count of those found picks the layout a message is
  // about); the first one missing is the one named.
  auto need = [&](const std::string& name, const std::string& why = "") -> std::optional<std::size_t> {
    const auto col = h.find(name);
    if (col) {
      ++plan.found;
    } else {
      ++plan.n_missing;
      if (plan.ok()) {
        plan.missing = name.empty() ? "?" : name;
        plan.missing_why = why;
      }
    }
    return col;
  };
  // Positions and displacements; planar data has no z columns at all.
  bool any_z = false, no_z = false;
  std::string first_z;
  for (int t = 0; t < 3; ++t) {
    if (!c.triples[t]) continue;
    std::array<std::optional<std::size_t>, 3> cols;
    for (int k = 0; k < 3; ++k) {
      const std::string& name = (*c.triples[t])[k];
      if (k == 2 && (name.empty() || (spec.planar && !h.find(name)))) {
        no_z = true;
        if (first_z.empty()) first_z = name;
        continue;
      }
      cols[k] = need(name);
      if (k == 2) any_z = true;
    }
    plan.triples[t] = cols;
  }
  if (plan.ok() && any_z && no_z) {
    plan.missing = first_z;
    ++plan.n_missing;
    plan.missing_why = "the other out-of-plane columns are there";
  }
  plan.planar = no_z && !any_z;
  // The key.
  if (o.id_from_row) {
  } else if (!o.id_columns.empty()) {
    for (const std::string& name : o.id_columns) plan.id.push_back(need(name).value_or(0));
  } else if (const auto it = o.columns.find("id"); it != o.columns.end()) {
    plan.id.push_back(need(it->second).value_or(0));
  } else if (plan.ok()) {
    bool got = false;
    for (const auto& set : spec.ids) {
      std::vector<std::size_t> cols;
      for (const std::string& name : set)
        if (const auto col = h.find(name)) cols.push_back(*col);
      if (cols.size() == set.size()) {
        plan.id = cols;
        plan.found += static_cast<int>(cols.size());
        got = true;
        break;
      }
    }
    if (!got && role == FileRole::kOneState && !spec.ids.empty()) {
      plan.missing = join(spec.ids.front());
      plan.missing_why = "the key that joins the files of a pair or series";
      ++plan.n_missing;
    }
  }
  // Grid indices: needed with a pitch.
  const auto ii = mapped(o, "i"), jj = mapped(o, "j");
  const std::string iname = ii != o.columns.end() ? ii->second : spec.i.empty() ? "i" : spec.i;
  const std::string jname = jj != o.columns.end() ? jj->second : spec.j.empty() ? "j" : spec.j;
  if (std::isfinite(o.pitch) || ii != o.columns.end() || jj != o.columns.end()) {
    const std::string why = std::isfinite(o.pitch) ? "the grid indices that place the marks with the pitch" : "";
    plan.i = need(iname, why);
    plan.j = need(jname, why);
  } else if (plan.ok()) {
    plan.i = h.find(iname);
    plan.j = h.find(jname);
    if (!plan.i || !plan.j) plan.i = plan.j = std::nullopt;
  }
  // The uncertainty, and the columns of the invalid-point rule.
  if (const auto it = o.columns.find("sigma"); it != o.columns.end()) {
    plan.sigma = need(it->second);
  } else if (plan.ok()) {
    for (const std::string& name : spec.sigma)
      if ((plan.sigma = h.find(name))) break;
  }
  if (spec.invalid == InvalidRule::kDiceMatch) plan.match = h.find("MATCH");
  if (!stage_column.empty()) plan.stage = need(stage_column, "the stage column");
  return plan;
}

std::string format_label(const FormatSpec& spec) { return "--format " + spec.name; }

// Names a candidate reads, for messages: "X, Y, Z, U, V, W".
std::string candidate_text(const Candidate& c) {
  std::vector<std::string> parts;
  for (const auto& t : c.triples)
    if (t) parts.push_back(triple_text(*t));
  return join(parts);
}

[[noreturn]] void throw_missing(const std::string& path, int line, const Plan& best, const FormatSpec& spec,
                                const Header& h, const std::vector<Candidate>& layouts, bool auto_plain = false) {
  std::string detail;
  if (auto_plain) detail = "nor does the header hold the columns and key of --format gom, matchid, vic3d or dice; ";
  if (best.missing == "X" && h.find("i") && h.find("j"))
    detail += "with grid indices i, j, a pitch (--pitch) places the undeformed marks; ";
  if (!best.missing_why.empty()) detail = best.missing_why + "; ";
  if (spec.format != MeasurementFormat::kPlain) {
    // The layout that came closest first, then the others the format also reads.
    std::vector<std::string> others;
    for (const Candidate& c : layouts)
      if (c.triples != best.candidate.triples) others.push_back(candidate_text(c));
    detail += format_label(spec) + " reads " + candidate_text(best.candidate);
    if (!others.empty()) detail += " (or " + join(others, "; or ") + ")";
    detail += "; ";
  }
  throw InputError(located_message(
      path, line, 0, fmt::format("missing required column '{}' ({}found: {})", best.missing, detail, join(h.names()))));
}

// "# units: U" in the comment lines before the header (as the grid writer puts it), or
// the length entry of GOM/ZEISS's "# Units: length:mm angle:deg time:s" (the first line
// of a GOM Correlate / ARAMIS surface-component CSV export).
std::string file_unit(const CsvTable& t) {
  std::string unit;
  auto trimmed = [](std::string_view v) {
    const auto a = v.find_first_not_of(" \t\r"), b = v.find_last_not_of(" \t\r");
    return a == std::string_view::npos ? std::string() : std::string(v.substr(a, b - a + 1));
  };
  for (const auto& [line, text] : t.preamble()) {
    std::string_view s(text);
    const auto p = s.find_first_not_of(" \t#");
    if (p == std::string_view::npos || s.find('#') > p) continue;
    s.remove_prefix(p);
    if (s.substr(0, 6) == "units:") {
      unit = trimmed(s.substr(6));
    } else if (s.substr(0, 6) == "Units:") {
      // Only its "length:" entry is a length unit; without one the line says nothing here.
      const auto at = s.find("length:", 6);
      if (at == std::string_view::npos) continue;
      std::string_view v = s.substr(at + 7);
      v = v.substr(0, v.find_first_of(" \t\r"));
      unit = trimmed(v);
    }
  }
  return unit;
}

// The factor from column `col`'s unit to the options' unit; nothing for a column in
// pixels without a pixel size when `soft` (the caller then does without it).
std::optional<double> scale_of(const CsvTable& t, const Header& h, std::size_t col, bool pixels,
                               const std::string& unit_of_file, const GridReadOptions& o, bool soft,
                               const std::string& lengths_of = "") {
  const NameAndUnit& nu = h.unit(col);
  std::string unit = nu.has_unit ? nu.unit : pixels ? "px" : unit_of_file;
  auto fail = [&](const std::string& what) -> double {
    throw InputError(located_message(t.file_name(), t.header_line(), static_cast<int>(col + 1),
                                     fmt::format("column '{}' {}", h.name(col), what)));
  };
  if (!nu.has_unit && unit.empty()) {
    // Taken to be in the options' unit, unless the format says it holds lengths (metric
    // coordinates of a calibrated system) and pixels are asked for.
    if (!lengths_of.empty() && is_pixel_unit(o.units))
      return fail(
          fmt::format("holds lengths ({} writes calibrated coordinates), which cannot be read in pixels "
                      "(--units {}); give the length unit of the calibration, e.g. --units mm",
                      lengths_of, o.units));
    return 1.0;
  }
  if (is_pixel_unit(unit)) {
    if (is_pixel_unit(o.units)) return 1.0;
    if (std::isfinite(o.pixel_size)) return o.pixel_size;
    if (soft) return std::nullopt;
    return fail(
        fmt::format("is in image pixels; give the pixel size (gsa analyse --pixel-size, in {} per pixel) or "
                    "read in pixels (--units px)",
                    o.units));
  }
  const auto mm = millimetres_per(unit);
  if (!mm) {
    if (unit.empty()) return fail(fmt::format("is dimensionless ('[{}]'), not a length", nu.unit));
    return fail(fmt::format("is in '{}', which is not a length unit gsa converts ({})", unit, known_length_units()));
  }
  if (is_pixel_unit(o.units)) {
    if (std::isfinite(o.pixel_size) && o.pixel_size > 0) return 1.0;  // no length per pixel known the other way
    return fail(fmt::format("is in {}, which cannot be converted to pixels (--units px)", unit));
  }
  const auto target = millimetres_per(o.units);
  if (!target)
    return fail(fmt::format("is in {}, but the unit to read in, '{}' (--units), is not a length unit gsa converts ({})",
                            unit, o.units, known_length_units()));
  return *mm / *target;
}

CsvOptions csv_options(const FormatSpec& spec, const GridReadOptions& o) {
  CsvOptions co;
  co.delimiter = o.delimiter;
  co.skip_lines = o.skip_lines;
  co.header_line = o.header_line;
  co.decimal = o.decimal;
  co.brackets_in_header = spec.brackets || spec.format == MeasurementFormat::kPlain;
  return co;
}

// True when one of the format's key column sets is all in the header.
bool has_key(const FormatSpec& spec, const Header& h) {
  return std::any_of(spec.ids.begin(), spec.ids.end(), [&](const std::vector<std::string>& set) {
    return std::all_of(set.begin(), set.end(), [&](const std::string& name) { return h.find(name).has_value(); });
  });
}

// --format auto: the formats whose header test passes on the first lines of the file (a
// preset only with its key columns: "x, y, z, u, v, w" alone would fit both the plain
// file and MatchID 2023, which read x differently). One preset: that preset; none: plain;
// several presets: an error asking for --format.
struct Detected {
  MeasurementFormat format = MeasurementFormat::kPlain;
  bool found = false;  // a preset was found (else plain)
};

Detected detect_format(const std::string& path, const GridReadOptions& o, const std::string& stage_column) {
  std::string head;
  {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    for (int n = 0; n < 300 && std::getline(in, line); ++n) head += line + '\n';
  }
  std::vector<const FormatSpec*> presets;
  int header_line = 0;
  for (const FormatSpec& spec : format_specs()) {
    if (spec.format == MeasurementFormat::kPlain) continue;
    // The preset's own layouts, as for a file holding both states and without the
    // pitch: its layouts cut down to current positions would take any "id, x, y, z".
    GridReadOptions oo = o;
    oo.format = spec.format;
    oo.pitch = std::numeric_limits<double>::quiet_NaN();
    const FileRole full = FileRole::kBothStates;
    const std::vector<Candidate> layouts = candidates(spec, oo, full);
    bool hit = false;
    CsvOptions co = csv_options(spec, oo);
    co.header_test = [&](const std::vector<std::string>& names) {
      const Header h(names);
      const bool ok = has_key(spec, h) && std::any_of(layouts.begin(), layouts.end(), [&](const Candidate& c) {
                        return resolve(c, h, spec, oo, full, stage_column).ok();
                      });
      hit = hit || ok;
      return ok;
    };
    try {
      const CsvTable t = read_csv_string(head, path, co);
      if (hit) header_line = t.header_line();
    } catch (const InputError&) {
      // A row cut short at the end of the first lines; `hit` says what matters.
    }
    if (hit) presets.push_back(&spec);
  }
  Detected d;
  if (presets.empty()) return d;
  if (presets.size() > 1) {
    std::vector<std::string> names;
    for (const FormatSpec* p : presets) names.push_back(p->name);
    throw InputError(located_message(path, header_line, 0,
                                     fmt::format("the header fits more than one measuring system's format ({}); "
                                                 "choose one with --format",
                                                 join(names))));
  }
  d.format = presets.front()->format;
  d.found = true;
  return d;
}

}  // namespace

GridRows read_grid_rows(const std::string& path, const GridReadOptions& options, FileRole role,
                        const std::string& stage_column) {
  options.validate();
  GridReadOptions o = options;
  bool detected = false, auto_plain = false;
  if (o.format == MeasurementFormat::kAuto) {
    // With --columns the user names the columns: the plain layout they extend.
    const Detected d = o.columns.empty() ? detect_format(path, o, stage_column) : Detected{};
    o.format = d.format;
    detected = d.found;
    auto_plain = !d.found && o.columns.empty();
    if (o.format == MeasurementFormat::kPlain && o.positions != Positions::kAsFormat)
      throw InputError(located_message(
          path, 0, 0,
          "--positions applies to a measuring system's format, and the header fits none of them; give --format"));
  }
  const FormatSpec& spec = format_spec(o.format);
  const std::vector<Candidate> layouts = candidates(spec, o, role);
  auto passes = [&](const std::vector<std::string>& names) {
    const Header h(names);
    return std::any_of(layouts.begin(), layouts.end(),
                       [&](const Candidate& c) { return resolve(c, h, spec, o, role, stage_column).ok(); });
  };
  CsvOptions co = csv_options(spec, o);
  co.header_test = passes;
  const CsvTable t = read_csv(path, co);
  const Header h(t.names());

  // The first layout that resolves, else the message of the one that came closest.
  std::optional<Plan> plan;
  Plan best;
  best.found = std::numeric_limits<int>::min() / 2;
  for (const Candidate& c : layouts) {
    Plan p = resolve(c, h, spec, o, role, stage_column);
    if (p.ok()) {
      plan = std::move(p);
      break;
    }
    if (p.score() > best.score()) best = std::move(p);
  }
  if (!plan) throw_missing(t.file_name(), t.header_line(), best, spec, h, layouts, auto_plain);

  GridRows out;
  out.path = path;
  if (options.decimal == kDetectDecimal && t.decimal() == ',')
    out.notes.push_back(path +
                        ": numbers with a decimal comma (found in the data; --decimal point reads them otherwise)");
  const std::string unit_of_file = file_unit(t);
  // Scale of each position and displacement column.
  std::array<std::array<double, 3>, 3> scale{};
  std::vector<std::string> converted;
  for (int tr = 0; tr < 3; ++tr) {
    if (!plan->triples[tr]) continue;
    for (int k = 0; k < 3; ++k) {
      scale[tr][k] = 1.0;
      if (const auto col = (*plan->triples[tr])[k]) {
        scale[tr][k] = *scale_of(t, h, *col, plan->pixels, unit_of_file, o, false,
                                 spec.format == MeasurementFormat::kPlain ? "" : format_label(spec));
        if (scale[tr][k] != 1.0) converted.push_back(h.name(*col));
      }
    }
  }
  double sigma_scale = 1.0;
  if (plan->sigma) {
    const auto s =
        scale_of(t, h, *plan->sigma, spec.sigma_pixels && !h.unit(*plan->sigma).has_unit, unit_of_file, o, true);
    if (s) {
      sigma_scale = *s;
      out.has_sigma = true;
    } else {
      out.notes.push_back(
          fmt::format("{}: column '{}' (uncertainty) is in image pixels and no pixel size was given: "
                      "not read (--pixel-size converts it)",
                      path, h.name(*plan->sigma)));
    }
  }
  const auto& tri = plan->triples;
  out.has_reference = tri[kReference].has_value() || (tri[kCurrent] && tri[kDisplacement]) || std::isfinite(o.pitch);
  out.has_displacement = tri[kDisplacement].has_value();
  out.has_ij = plan->i.has_value() && plan->j.has_value();

  // What was read, in words, for the user (not for the plain grid file).
  if (spec.format != MeasurementFormat::kPlain) {
    std::vector<std::string> parts;
    for (int tr = 0; tr < 3; ++tr)
      if (tri[tr]) parts.push_back(triple_text(*plan->candidate.triples[tr]) + " = " + kTripleWords[tr]);
    std::string key = plan->id.empty() ? "row number" : "";
    for (const std::size_t c : plan->id) key += (key.empty() ? "" : ", ") + h.name(c);
    out.notes.push_back(fmt::format("{}: {} ({}): {}; key {}{}{}", path,
                                    detected ? "format found from the header: " + spec.name : format_label(spec),
                                    spec.title, join(parts, "; "), key,
                                    std::isfinite(o.pitch) ? "; reference positions from i, j and the pitch" : "",
                                    detected ? " (--format chooses another)" : ""));
  }
  if (!converted.empty()) out.notes.push_back(fmt::format("{}: converted to {}: {}", path, o.units, join(converted)));
  if (plan->planar) out.notes.push_back(path + ": no out-of-plane columns: planar (2-D) data, Z = z = 0");
  if (plan->id.empty() && !o.id_from_row)
    out.notes.push_back(path + ": no id column: the marks are numbered by row (1, 2, ...)");

  std::vector<std::string> id_names;
  for (const std::size_t c : plan->id) id_names.push_back(h.name(c));
  out.id_text = plan->id.empty() ? "row number" : join(id_names);

  const std::size_t n = t.n_rows();
  out.rows.resize(n);
  std::unordered_map<std::string, std::size_t> seen;
  seen.reserve(n);
  for (std::size_t r = 0; r < n; ++r) {
    GridRow& row = out.rows[r];
    row.line = t.line(r);
    // Id.
    if (plan->id.empty()) {
      row.id = std::to_string(r + 1);
    } else {
      row.id_column = t.char_column(r, plan->id.front());
      for (std::size_t k = 0; k < plan->id.size(); ++k) {
        const std::string_view cell = t.cell(r, plan->id[k]);
        if (cell.empty())
          throw InputError(located_message(
              t.file_name(), row.line, t.char_column(r, plan->id[k]),
              plan->id.size() == 1 ? std::string("empty id") : "empty id cell in column '" + id_names[k] + "'"));
        if (k > 0) row.id += '_';
        row.id += cell;
      }
    }
    if (plan->stage) row.stage = std::string(t.cell(r, *plan->stage));
    const std::string key = plan->stage ? row.stage + '\n' + row.id : row.id;
    const auto [it, fresh] = seen.emplace(key, r);
    if (!fresh) {
      std::string what = fmt::format("duplicate id '{}'", row.id);
      if (plan->id.size() > 1) what += " (from columns " + out.id_text + ")";
      if (plan->stage) what += fmt::format(" in stage '{}'", row.stage);
      throw InputError(located_message(t.file_name(), row.line, std::max(row.id_column, 1),
                                       fmt::format("{} (first at line {}); ids must be unique{}", what,
                                                   t.line(it->second), plan->stage ? " within a stage" : "")));
    }
    // Positions and displacements.
    std::array<Vec3, 3> v = {Vec3::Constant(kNaN), Vec3::Constant(kNaN), Vec3::Constant(kNaN)};
    std::array<bool, 3> all_zero = {true, true, true};
    for (int tr = 0; tr < 3; ++tr) {
      if (!tri[tr]) continue;
      bool missing = false;
      for (int k = 0; k < 3; ++k) {
        double value = 0.0;
        if (const auto col = (*tri[tr])[k]) value = t.number(r, *col, /*allow_missing=*/true);
        if (std::isnan(value)) missing = true;
        if (value != 0.0) all_zero[tr] = false;
        v[tr][k] = value * scale[tr][k];
      }
      if (missing) v[tr].setConstant(kNaN);
    }
    row.reference = tri[kReference]                         ? v[kReference]
                    : (tri[kCurrent] && tri[kDisplacement]) ? Vec3(v[kCurrent] - v[kDisplacement])
                                                            : Vec3::Constant(kNaN);
    row.current = tri[kCurrent]                             ? v[kCurrent]
                  : (tri[kReference] && tri[kDisplacement]) ? Vec3(v[kReference] + v[kDisplacement])
                                                            : Vec3::Constant(kNaN);
    double sigma = plan->sigma ? t.number(r, *plan->sigma, /*allow_missing=*/true) : kNaN;
    // The format's rule for points it could not measure.
    switch (spec.invalid) {
      case InvalidRule::kNone:
        break;
      case InvalidRule::kEmptyCells:
        // ARAMIS's neutral nodemap export (x_undef.. with u, v, w) writes a facet it could
        // not measure as reference position 0, 0, 0 with nan displacements: that position
        // is not a measurement either. (Elsewhere, e.g. MatchID, a point at the origin
        // whose displacement failed keeps its reference position.)
        if (spec.format == MeasurementFormat::kGom && tri[kReference] && tri[kDisplacement] &&
            !v[kDisplacement].allFinite() && all_zero[kReference])
          row.reference.setConstant(kNaN);
        row.flagged_reference = out.has_reference && !row.reference.allFinite();
        row.flagged_current = !row.current.allFinite();
        break;
      case InvalidRule::kVicSigma: {
        bool failed = false;
        if (plan->sigma) {
          failed = sigma < 0;
        } else {
          failed = true;
          for (int tr = 0; tr < 3; ++tr)
            if (tri[tr] && !all_zero[tr]) failed = false;
        }
        if (failed) {
          row.reference.setConstant(kNaN);
          row.current.setConstant(kNaN);
        }
        row.flagged_reference = out.has_reference && !row.reference.allFinite();
        row.flagged_current = !row.current.allFinite();
        break;
      }
      case InvalidRule::kDiceMatch: {
        bool failed = false;
        const double match = plan->match ? t.number(r, *plan->match, true) : kNaN;
        if (!std::isnan(match))
          failed = match != 0.0;
        else if (plan->sigma)
          failed = sigma < 0;
        if (failed) row.current.setConstant(kNaN);
        row.flagged_reference = out.has_reference && !row.reference.allFinite();
        row.flagged_current = !row.current.allFinite();
        break;
      }
    }
    if (out.has_sigma) row.sigma = sigma > 0 ? sigma * sigma_scale : kNaN;
    // Grid indices, and the nominal reference position from them.
    if (out.has_ij && !t.is_missing(r, *plan->i) && !t.is_missing(r, *plan->j)) {
      row.i = t.integer(r, *plan->i);
      row.j = t.integer(r, *plan->j);
    }
    if (std::isfinite(o.pitch)) {
      row.flagged_reference = false;
      row.reference = row.i == kNoGridIndex
                          ? Vec3::Constant(kNaN)
                          : Vec3(static_cast<double>(row.j) * o.pitch, static_cast<double>(row.i) * o.pitch, 0.0);
    }
  }
  return out;
}

}  // namespace sf::io::detail

#include "common/io/grid_series.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <regex>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/io/grid_rows.hpp"

namespace sf::io {

namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// "surface-1_12.500 s" -> 12.5: a trailing number of seconds in a stage name.
double time_of_name(const std::string& name) {
  static const std::regex kSeconds(R"((?:^|[_ ])([-+]?[0-9]+(?:\.[0-9]+)?) ?s$)");
  std::smatch m;
  if (std::regex_search(name, m, kSeconds)) return std::stod(m[1].str());
  return kNaN;
}

// A stage value that is a number is its time.
double time_of_value(const std::string& value) {
  static const std::regex kNumber(R"([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)");
  if (std::regex_match(value, kNumber)) return std::stod(value);
  return time_of_name(value);
}

bool stage_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".csv" || ext == ".txt" || ext == ".tsv" || ext == ".dat";
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  const bool eq = fs::equivalent(a, b, ec);
  return !ec && eq;
}

// The series under construction: marks by id, and each stage's rows until the number of
// marks is known.
struct Builder {
  GridSeries s;
  std::unordered_map<std::string, Index> index;
  std::vector<Vec3> undeformed;
  std::vector<std::uint8_t> flagged;
  std::vector<double> sigma;
  std::vector<long> i, j;
  bool any_sigma = false;
  struct StageRows {
    GridStage stage;
    std::vector<std::pair<Index, detail::GridRow>> rows;
    bool has_sigma = false;
  };
  std::vector<StageRows> stages;

  Index add(const std::string& id) {
    const auto [it, fresh] = index.emplace(id, static_cast<Index>(s.ids.size()));
    if (fresh) {
      s.ids.push_back(id);
      s.where.emplace_back();
      undeformed.push_back(Vec3::Constant(kNaN));
      flagged.push_back(0);
      sigma.push_back(kNaN);
      i.push_back(kNoGridIndex);
      j.push_back(kNoGridIndex);
    }
    return it->second;
  }
  // The undeformed state of mark p from a row's position `x`.
  void set_undeformed(Index p, const Vec3& x, bool flag, const detail::GridRow& row, const std::string& path) {
    const auto k = static_cast<std::size_t>(p);
    undeformed[k] = x;
    flagged[k] = flag && !x.allFinite();
    sigma[k] = row.sigma;
    i[k] = row.i;
    j[k] = row.j;
    s.where[k] = path + ":" + std::to_string(row.line);
  }

  GridSeries finish() {
    const Index n = static_cast<Index>(s.ids.size());
    s.undeformed.resize(n, 3);
    for (Index p = 0; p < n; ++p) s.undeformed.row(p) = undeformed[static_cast<std::size_t>(p)].transpose();
    if (std::any_of(flagged.begin(), flagged.end(), [](std::uint8_t f) { return f != 0; }))
      s.not_measured_undeformed = flagged;
    if (any_sigma) s.sigma_undeformed = sigma;
    if (s.has_ij) {
      s.i = i;
      s.j = j;
    }
    for (StageRows& sr : stages) {
      GridStage& g = sr.stage;
      g.deformed = Points3::Constant(n, 3, kNaN);
      g.where.assign(static_cast<std::size_t>(n), "");
      std::vector<std::uint8_t> flags(static_cast<std::size_t>(n), 0);
      if (sr.has_sigma) g.sigma.assign(static_cast<std::size_t>(n), kNaN);
      bool any_flag = false;
      for (const auto& [p, row] : sr.rows) {
        const auto k = static_cast<std::size_t>(p);
        g.deformed.row(p) = row.current.transpose();
        g.where[k] = g.source + ":" + std::to_string(row.line);
        flags[k] = row.flagged_current ? 1 : 0;
        any_flag = any_flag || row.flagged_current;
        if (sr.has_sigma) g.sigma[k] = row.sigma;
      }
      if (any_flag) g.not_measured = std::move(flags);
      s.stages.push_back(std::move(g));
    }
    return std::move(s);
  }
};

// The rule text of the format, for the series.
std::string rule_of(const GridReadOptions& o) {
  const FormatSpec& spec = format_spec(o.format);
  return spec.invalid == InvalidRule::kNone ? "" : spec.invalid_text;
}

// A note when a stage's reference positions (as the format's layout reads them) differ
// from the series' by about the displacement: its position columns then likely hold the
// other state, and --positions should say so.
void check_positions(const detail::GridRows& rows, const Builder& b, const std::string& reference,
                     std::vector<std::string>& notes) {
  if (!rows.has_reference || !rows.has_displacement) return;
  double diff2 = 0, u2 = 0, extent = 0;
  int count = 0;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& row : rows.rows) {
    const auto it = b.index.find(row.id);
    if (it == b.index.end()) continue;
    const Vec3& ref = b.undeformed[static_cast<std::size_t>(it->second)];
    if (!ref.allFinite() || !row.reference.allFinite() || !row.current.allFinite()) continue;
    diff2 += (row.reference - ref).squaredNorm();
    u2 += (row.current - row.reference).squaredNorm();
    lo = lo.cwiseMin(ref);
    hi = hi.cwiseMax(ref);
    ++count;
  }
  if (count < 3) return;
  extent = (hi - lo).norm();
  if (std::sqrt(u2) > 1e-6 * extent * std::sqrt(static_cast<double>(count)) && diff2 > 0.25 * u2)
    notes.push_back(fmt::format(
        "{}: its reference positions (position columns, with the displacements) differ from those of {} by about the "
        "displacement (RMS {:.3g} against {:.3g}): the position columns may hold the other state; check the "
        "positions option (gsa analyse --positions reference|current)",
        rows.path, reference, std::sqrt(diff2 / count), std::sqrt(u2 / count)));
}

}  // namespace

bool natural_less(std::string_view a, std::string_view b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && is_digit(a[ie])) ++ie;
      while (je < b.size() && is_digit(b[je])) ++je;
      std::size_t is = i, js = j;
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      const std::string_view na = a.substr(is, ie - is), nb = b.substr(js, je - js);
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
      ++i;
      ++j;
    }
  }
  if ((a.size() - i) != (b.size() - j)) return (a.size() - i) < (b.size() - j);
  return a < b;  // equal under the natural order ("a01", "a1"): by text, for a strict order
}

std::vector<std::string> stage_files(const std::vector<std::string>& paths, const std::string& exclude) {
  std::vector<std::string> files;
  for (const std::string& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<std::string> found;
      for (const auto& e : fs::directory_iterator(p, ec)) {
        const std::string name = e.path().filename().string();
        if (name.empty() || name[0] == '.' || !e.is_regular_file() || !stage_extension(e.path())) continue;
        found.push_back(e.path().string());
      }
      if (found.empty())
        throw InputError(located_message(p, 0, 0, "no stage files (csv, txt, tsv or dat) in this folder"));
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(p, ec)) {
      files.push_back(p);
    } else {
      throw InputError(located_message(p, 0, 0, "no such file or folder"));
    }
  }
  std::sort(files.begin(), files.end(), [](const std::string& a, const std::string& b) { return natural_less(a, b); });
  std::vector<std::string> out;
  for (const std::string& f : files) {
    if (!exclude.empty() && same_file(f, exclude)) continue;
    if (std::any_of(out.begin(), out.end(), [&](const std::string& g) { return same_file(f, g); })) continue;
    out.push_back(f);
  }
  return out;
}

GridData GridSeries::stage_grid(std::size_t k) const {
  const GridStage& st = stages.at(k);
  GridData g;
  g.ids = ids;
  g.undeformed = undeformed;
  g.deformed = st.deformed;
  g.has_ij = has_ij;
  g.i = i;
  g.j = j;
  g.where = where;
  for (std::size_t p = 0; p < g.where.size(); ++p)
    if (g.where[p].empty()) g.where[p] = st.where[p];
  g.sources = sources.empty() || sources.front() == st.source ? std::vector<std::string>{st.source}
                                                              : std::vector<std::string>{sources.front(), st.source};
  g.sigma_undeformed = sigma_undeformed;
  g.sigma_deformed = st.sigma;
  if (!not_measured_undeformed.empty() || !st.not_measured.empty()) {
    g.not_measured.assign(ids.size(), 0);
    for (std::size_t p = 0; p < ids.size(); ++p) {
      if (!not_measured_undeformed.empty() && not_measured_undeformed[p]) g.not_measured[p] |= kNotMeasuredUndeformed;
      if (!st.not_measured.empty() && st.not_measured[p]) g.not_measured[p] |= kNotMeasuredDeformed;
    }
  }
  g.not_measured_rule = not_measured_rule;
  g.units = units;
  g.notes = notes;
  return g;
}

namespace detail {

GridSeries build_series(const std::string& reference, const std::vector<std::string>& files, const GridReadOptions& o) {
  o.validate();
  if (std::isfinite(o.pitch) && !reference.empty())
    throw UsageError("the pitch gives the undeformed positions: give no reference (undeformed) file with it");
  Builder b;
  b.s.units = o.units;
  b.s.not_measured_rule = rule_of(o);
  std::size_t reference_rows = 0;
  if (!reference.empty()) {
    GridRows rows = read_grid_rows(reference, o, FileRole::kOneState);
    b.s.sources.push_back(reference);
    b.s.has_ij = rows.has_ij;
    b.any_sigma = rows.has_sigma;
    b.s.notes.insert(b.s.notes.end(), rows.notes.begin(), rows.notes.end());
    for (const GridRow& row : rows.rows)
      b.set_undeformed(b.add(row.id), row.current, row.flagged_current, row, reference);
    reference_rows = rows.rows.size();
  }
  bool first_stage = true;
  for (const std::string& f : files) {
    GridRows rows = read_grid_rows(f, o, reference.empty() ? FileRole::kBothStates : FileRole::kOneState);
    if (o.id_from_row && !reference.empty() && rows.rows.size() != reference_rows)
      throw InputError(located_message(f, 0, 0,
                                       fmt::format("{} rows, but the reference file {} has {}: joining by row order "
                                                   "needs the same rows in every file",
                                                   rows.rows.size(), reference, reference_rows)));
    b.s.sources.push_back(f);
    for (const std::string& note : rows.notes)
      if (std::find(b.s.notes.begin(), b.s.notes.end(), note) == b.s.notes.end()) b.s.notes.push_back(note);
    if (!reference.empty()) check_positions(rows, b, reference, b.s.notes);
    if (reference.empty() && first_stage) b.s.has_ij = rows.has_ij;
    first_stage = false;
    Builder::StageRows sr;
    sr.stage.name = fs::path(f).stem().string();
    sr.stage.time = time_of_name(sr.stage.name);
    sr.stage.source = f;
    sr.has_sigma = rows.has_sigma;
    for (GridRow& row : rows.rows) {
      Index p = 0;
      if (!reference.empty()) {
        const auto it = b.index.find(row.id);
        if (it == b.index.end())
          throw InputError(located_message(f, row.line, std::max(row.id_column, 1),
                                           fmt::format("id '{}' ({}) is not in the reference (undeformed) file {}",
                                                       row.id, rows.id_text, reference)));
        p = it->second;
      } else {
        p = b.add(row.id);
        const auto k = static_cast<std::size_t>(p);
        if (!b.undeformed[k].allFinite() && row.reference.allFinite()) {
          b.set_undeformed(p, row.reference, false, row, f);
          b.any_sigma = b.any_sigma || rows.has_sigma;
        } else if (!b.undeformed[k].allFinite() && row.flagged_reference) {
          b.flagged[k] = 1;
          if (b.s.where[k].empty()) b.s.where[k] = f + ":" + std::to_string(row.line);
        }
      }
      sr.rows.emplace_back(p, std::move(row));
    }
    b.stages.push_back(std::move(sr));
  }
  return b.finish();
}

}  // namespace detail

GridSeries read_grid_series(const std::string& reference, const std::vector<std::string>& stages,
                            const GridReadOptions& options) {
  const std::vector<std::string> files = stage_files(stages, reference);
  if (files.empty())
    throw InputError(located_message(stages.empty() ? reference : stages.front(), 0, 0,
                                     "no stage files besides the reference file"));
  return detail::build_series(reference, files, options);
}

GridSeries read_grid_series_column(const std::string& path, const std::string& stage_column, const GridReadOptions& o,
                                   const std::string& reference_stage) {
  if (stage_column.empty()) throw UsageError("read_grid_series_column: no stage column given");
  detail::GridRows rows = detail::read_grid_rows(
      path, o, reference_stage.empty() ? detail::FileRole::kBothStates : detail::FileRole::kOneState, stage_column);
  // The stages in natural order of their values.
  std::vector<std::string> values;
  for (const auto& row : rows.rows)
    if (std::find(values.begin(), values.end(), row.stage) == values.end()) values.push_back(row.stage);
  std::sort(values.begin(), values.end(),
            [](const std::string& a, const std::string& b) { return natural_less(a, b); });
  if (!reference_stage.empty() && std::find(values.begin(), values.end(), reference_stage) == values.end()) {
    std::string list;
    for (const auto& v : values) list += (list.empty() ? "" : ", ") + v;
    throw InputError(located_message(
        path, 0, 0, fmt::format("no rows of the reference stage '{}' (stages: {})", reference_stage, list)));
  }
  Builder b;
  b.s.units = o.units;
  b.s.not_measured_rule = rule_of(o);
  b.s.sources = {path};
  b.s.notes = rows.notes;
  b.s.has_ij = rows.has_ij;
  b.any_sigma = rows.has_sigma;
  if (!reference_stage.empty()) {
    for (const auto& row : rows.rows)
      if (row.stage == reference_stage) b.set_undeformed(b.add(row.id), row.current, row.flagged_current, row, path);
  }
  std::unordered_map<std::string, std::size_t> stage_of;
  for (const std::string& v : values) {
    if (v == reference_stage) continue;
    stage_of[v] = b.stages.size();
    Builder::StageRows sr;
    sr.stage.name = v;
    sr.stage.time = time_of_value(v);
    sr.stage.source = path;
    sr.has_sigma = rows.has_sigma;
    b.stages.push_back(std::move(sr));
  }
  // Rows in file order; without a reference stage, a mark's undeformed position is its
  // reference position in the first stage (natural order) that has one.
  std::vector<std::size_t> order(rows.rows.size());
  for (std::size_t r = 0; r < order.size(); ++r) order[r] = r;
  if (reference_stage.empty()) {
    for (const auto& row : rows.rows) b.add(row.id);  // ids in file order
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
      return natural_less(rows.rows[x].stage, rows.rows[y].stage);
    });
  }
  for (const std::size_t r : order) {
    detail::GridRow& row = rows.rows[r];
    if (row.stage == reference_stage) continue;
    Index p = 0;
    if (!reference_stage.empty()) {
      const auto it = b.index.find(row.id);
      if (it == b.index.end())
        throw InputError(located_message(path, row.line, std::max(row.id_column, 1),
                                         fmt::format("id '{}' of stage '{}' is not in the reference stage '{}'", row.id,
                                                     row.stage, reference_stage)));
      p = it->second;
    } else {
      p = b.add(row.id);
      const auto k = static_cast<std::size_t>(p);
      if (!b.undeformed[k].allFinite() && row.reference.allFinite())
        b.set_undeformed(p, row.reference, false, row, path);
      else if (!b.undeformed[k].allFinite() && row.flagged_reference)
        b.flagged[k] = 1;
    }
    b.stages[stage_of.at(row.stage)].rows.emplace_back(p, std::move(row));
  }
  return b.finish();
}

}  // namespace sf::io

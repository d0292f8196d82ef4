#include "common/io/grid_file.hpp"

#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/grid_rows.hpp"
#include "common/io/grid_series.hpp"

namespace sf::io {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void write_comment(std::ostream& out, const std::string& text) {
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find('\n', start);
    out << "# " << text.substr(start, end == std::string::npos ? std::string::npos : end - start) << "\n";
    if (end == std::string::npos) break;
    start = end + 1;
  }
}

[[noreturn]] void bad_option(const std::string& field, const std::string& problem) {
  throw UsageError("GridReadOptions::" + field + ": " + problem);
}

}  // namespace

bool is_grid_column_key(std::string_view key) {
  for (const std::string_view k : kGridColumnKeys)
    if (k == key) return true;
  return false;
}

void GridReadOptions::validate() const {
  for (const auto& [key, name] : columns) {
    if (!is_grid_column_key(key)) bad_option("columns", "unknown key '" + key + "'");
    if (name.empty()) bad_option("columns", "no column name for '" + key + "'");
  }
  auto mapped = [&](std::initializer_list<const char*> keys) {
    for (const char* k : keys)
      if (columns.count(k)) return true;
    return false;
  };
  if (mapped({"X", "Y", "Z"}) && mapped({"x", "y", "z"}) && mapped({"u", "v", "w"}))
    bad_option("columns",
               "reference positions (X, Y, Z), current positions (x, y, z) and displacements (u, v, w) "
               "all mapped; map two of them");
  if (format == MeasurementFormat::kPlain && positions != Positions::kAsFormat)
    bad_option("positions",
               "applies to a measuring system's format; in the plain grid file the names say it "
               "(X, Y, Z reference, x, y, z current positions)");
  if (!id_columns.empty() && columns.count("id"))
    bad_option("id_columns", "give the id columns once, not also as columns id=...");
  if (id_from_row && (!id_columns.empty() || columns.count("id")))
    bad_option("id_from_row", "the id is either the row number or taken from columns");
  for (const std::string& c : id_columns)
    if (c.empty()) bad_option("id_columns", "an empty column name");
  if (decimal != '.' && decimal != ',' && decimal != kDetectDecimal)
    bad_option("decimal", std::string("must be '.', ',' or kDetectDecimal, found '") + decimal + "'");
  if (decimal == ',' && delimiter == ',') bad_option("decimal", "',' needs a delimiter other than ','");
  if (skip_lines < 0) bad_option("skip_lines", "must be >= 0, found " + std::to_string(skip_lines));
  if (header_line < 0) bad_option("header_line", "must be >= 1, found " + std::to_string(header_line));
  if (header_line > 0 && header_line <= skip_lines)
    bad_option("header_line", "line " + std::to_string(header_line) + " is among the " + std::to_string(skip_lines) +
                                  " skipped lines");
  if (units.empty()) bad_option("units", "empty");
  if (!std::isnan(pixel_size) && !(pixel_size > 0 && std::isfinite(pixel_size)))
    bad_option("pixel_size", "must be > 0, found " + std::to_string(pixel_size));
  if (!std::isnan(pitch) && !(pitch > 0 && std::isfinite(pitch)))
    bad_option("pitch", "must be > 0, found " + std::to_string(pitch));
  if (!std::isnan(pitch) && mapped({"X", "Y", "Z"}))
    bad_option("pitch", "gives the reference positions; do not also map X, Y, Z");
}

GridData read_grid_file(const std::string& path, const GridReadOptions& options) {
  detail::GridRows rows = detail::read_grid_rows(path, options, detail::FileRole::kBothStates);
  GridData g;
  g.sources = {path};
  g.units = options.units;
  g.notes = std::move(rows.notes);
  const std::size_t n = rows.rows.size();
  const Index ni = static_cast<Index>(n);
  g.ids.resize(n);
  g.where.resize(n);
  g.undeformed.resize(ni, 3);
  g.deformed.resize(ni, 3);
  g.has_ij = rows.has_ij;
  if (g.has_ij) {
    g.i.resize(n);
    g.j.resize(n);
  }
  if (rows.has_sigma) {
    g.sigma_undeformed.resize(n);
    g.sigma_deformed.resize(n);
  }
  std::vector<std::uint8_t> flags(n, 0);
  bool any_flag = false;
  for (std::size_t r = 0; r < n; ++r) {
    detail::GridRow& row = rows.rows[r];
    const Index p = static_cast<Index>(r);
    g.ids[r] = std::move(row.id);
    g.where[r] = path + ":" + std::to_string(row.line);
    g.undeformed.row(p) = row.reference.transpose();
    g.deformed.row(p) = row.current.transpose();
    if (g.has_ij) {
      g.i[r] = row.i;
      g.j[r] = row.j;
    }
    if (rows.has_sigma) g.sigma_undeformed[r] = g.sigma_deformed[r] = row.sigma;
    flags[r] = static_cast<std::uint8_t>((row.flagged_reference ? kNotMeasuredUndeformed : 0) |
                                         (row.flagged_current ? kNotMeasuredDeformed : 0));
    any_flag = any_flag || flags[r] != 0;
  }
  if (any_flag) g.not_measured = std::move(flags);
  const FormatSpec& spec = format_spec(options.format);
  if (spec.invalid != InvalidRule::kNone) g.not_measured_rule = spec.invalid_text;
  return g;
}

GridData read_grid_file_pair(const std::string& undeformed_path, const std::string& deformed_path,
                             const GridReadOptions& options) {
  return detail::build_series(undeformed_path, {deformed_path}, options).stage_grid(0);
}

struct GridFileWriter::Impl {
  bool with_ij;
  std::size_t n_extra;
  CsvWriter csv;
  Impl(std::ostream& out, bool ij, std::size_t extra, std::vector<std::string> header)
      : with_ij(ij), n_extra(extra), csv(out, std::move(header)) {}

  void row(std::string_view id, const Vec3& undeformed, const Vec3& deformed, const std::vector<double>& extra) {
    if (id.empty()) throw std::logic_error("GridFileWriter: empty id");
    if (extra.size() != n_extra)
      throw std::logic_error("GridFileWriter: " + std::to_string(extra.size()) + " extra values for " +
                             std::to_string(n_extra) + " extra columns");
    csv.begin_row().add(id);
    for (const Vec3* v : {&undeformed, &deformed}) {
      const bool known = v->allFinite();  // a position is digitised as a whole or not at all
      for (int k = 0; k < 3; ++k) csv.add(known ? (*v)[k] : kNaN);
    }
  }

  void end(const std::vector<double>& extra) {
    for (const double v : extra) csv.add(v);
    csv.end_row();
  }
};

GridFileWriter::GridFileWriter(std::ostream& out, const GridWriteOptions& options) {
  for (const std::string& c : options.comments) write_comment(out, c);
  if (!options.units.empty()) write_comment(out, "units: " + options.units);
  std::vector<std::string> header = {"id", "X", "Y", "Z", "x", "y", "z"};
  if (options.with_ij) header.insert(header.end(), {"i", "j"});
  for (const std::string& c : options.extra_columns) {
    if (is_grid_column_key(c)) throw std::logic_error("GridFileWriter: extra column '" + c + "' is a grid file key");
    header.push_back(c);
  }
  impl_ = std::make_unique<Impl>(out, options.with_ij, options.extra_columns.size(), std::move(header));
}

GridFileWriter::~GridFileWriter() = default;

void GridFileWriter::add(std::string_view id, const Vec3& undeformed, const Vec3& deformed,
                         const std::vector<double>& extra) {
  if (impl_->with_ij) throw std::logic_error("GridFileWriter: this grid has i, j columns; give them");
  impl_->row(id, undeformed, deformed, extra);
  impl_->end(extra);
}

void GridFileWriter::add(std::string_view id, const Vec3& undeformed, const Vec3& deformed, long i, long j,
                         const std::vector<double>& extra) {
  if (!impl_->with_ij) throw std::logic_error("GridFileWriter: this grid has no i, j columns");
  impl_->row(id, undeformed, deformed, extra);
  for (const long v : {i, j}) {
    if (v == kNoGridIndex)
      impl_->csv.add(kNaN);
    else
      impl_->csv.add(v);
  }
  impl_->end(extra);
}

void write_grid_file(const std::string& path, const GridData& grid, const GridWriteOptions& options) {
  GridWriteOptions o = options;
  o.with_ij = grid.has_ij;
  o.extra_columns.clear();  // GridData holds the contract's columns only
  write_file_atomic(path, [&](std::ostream& out) {
    GridFileWriter w(out, o);
    for (Index p = 0; p < grid.n_points(); ++p) {
      const Vec3 X = grid.undeformed.row(p).transpose(), x = grid.deformed.row(p).transpose();
      const auto k = static_cast<std::size_t>(p);
      if (grid.has_ij)
        w.add(grid.ids[k], X, x, grid.i[k], grid.j[k]);
      else
        w.add(grid.ids[k], X, x);
    }
  });
}

}  // namespace sf::io

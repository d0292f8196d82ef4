#include "common/io/grid_file.hpp"

#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"

namespace sf::io {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string mapped(const GridReadOptions& o, const std::string& key) {
  auto it = o.columns.find(key);
  return it == o.columns.end() ? key : it->second;
}

CsvTable load(const std::string& path, const GridReadOptions& options) {
  CsvOptions co;
  co.delimiter = options.delimiter;
  return read_csv(path, co);
}

std::string where_of(const CsvTable& t, std::size_t row) { return t.file_name() + ":" + std::to_string(t.line(row)); }

// Reads a 3-vector from columns (a, b, c); a row with any missing entry is all NaN.
void read_xyz(const CsvTable& t, std::size_t row, const std::array<std::size_t, 3>& cols, double* out) {
  bool missing = false;
  for (int k = 0; k < 3; ++k) {
    out[k] = t.number(row, cols[k], /*allow_missing=*/true);
    if (std::isnan(out[k])) missing = true;
  }
  if (missing) out[0] = out[1] = out[2] = kNaN;
}

void read_ij(const CsvTable& t, const GridReadOptions& o, GridData& g, std::size_t row, Index p, bool& first) {
  const auto ci = t.find_column(mapped(o, "i")), cj = t.find_column(mapped(o, "j"));
  if (first) {
    g.has_ij = ci.has_value() && cj.has_value();
    first = false;
  }
  if (!g.has_ij) return;
  if (t.is_missing(row, *ci) || t.is_missing(row, *cj)) {
    g.i[p] = g.j[p] = kNoGridIndex;
    return;
  }
  g.i[p] = t.integer(row, *ci);
  g.j[p] = t.integer(row, *cj);
}

// Reads row r's id and records it in `seen` (id -> row); empty or repeated ids
// are input errors naming the file, line and column (and the first occurrence).
std::string take_id(const CsvTable& t, std::size_t r, std::size_t col, std::unordered_map<std::string, std::size_t>& seen) {
  std::string id(t.cell(r, col));
  if (id.empty()) throw InputError(located_message(t.file_name(), t.line(r), t.char_column(r, col), "empty id"));
  auto [it, fresh] = seen.emplace(id, r);
  if (!fresh)
    throw InputError(located_message(t.file_name(), t.line(r), t.char_column(r, col),
                                     "duplicate id '" + id + "' (first at line " + std::to_string(t.line(it->second)) +
                                         "); ids must be unique"));
  return id;
}

void resize(GridData& g, std::size_t n) {
  g.ids.resize(n);
  g.undeformed.resize(static_cast<Index>(n), 3);
  g.deformed.resize(static_cast<Index>(n), 3);
  g.i.resize(n);
  g.j.resize(n);
  g.where.resize(n);
}

void drop_ij_unless_present(GridData& g) {
  if (g.has_ij) return;
  g.i.clear();
  g.j.clear();
}

void write_comment(std::ostream& out, const std::string& text) {
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find('\n', start);
    out << "# " << text.substr(start, end == std::string::npos ? std::string::npos : end - start) << "\n";
    if (end == std::string::npos) break;
    start = end + 1;
  }
}

}  // namespace

bool is_grid_column_key(std::string_view key) {
  for (const std::string_view k : kGridColumnKeys)
    if (k == key) return true;
  return false;
}

GridData read_grid_file(const std::string& path, const GridReadOptions& options) {
  const CsvTable t = load(path, options);
  GridData g;
  g.sources = {path};
  const std::size_t n = t.n_rows();
  const std::size_t cid = t.column_index(mapped(options, "id"));
  const std::array<std::size_t, 3> cu = {t.column_index(mapped(options, "X")), t.column_index(mapped(options, "Y")),
                                         t.column_index(mapped(options, "Z"))};
  const bool displacement = options.columns.count("u") || options.columns.count("v") || options.columns.count("w");
  std::array<std::size_t, 3> cd;
  if (displacement) {
    cd = {t.column_index(mapped(options, "u")), t.column_index(mapped(options, "v")), t.column_index(mapped(options, "w"))};
  } else {
    cd = {t.column_index(mapped(options, "x")), t.column_index(mapped(options, "y")), t.column_index(mapped(options, "z"))};
  }
  resize(g, n);
  std::unordered_map<std::string, std::size_t> seen;
  bool first = true;
  for (std::size_t r = 0; r < n; ++r) {
    const Index p = static_cast<Index>(r);
    g.ids[r] = take_id(t, r, cid, seen);
    read_xyz(t, r, cu, g.undeformed.row(p).data());
    read_xyz(t, r, cd, g.deformed.row(p).data());
    if (displacement) g.deformed.row(p) += g.undeformed.row(p);
    read_ij(t, options, g, r, p, first);
    g.where[r] = where_of(t, r);
  }
  drop_ij_unless_present(g);
  return g;
}

GridData read_grid_file_pair(const std::string& undeformed_path, const std::string& deformed_path,
                             const GridReadOptions& options) {
  const CsvTable tu = load(undeformed_path, options), td = load(deformed_path, options);
  GridData g;
  g.sources = {undeformed_path, deformed_path};
  auto cols = [&](const CsvTable& t) {
    return std::array<std::size_t, 3>{t.column_index(mapped(options, "x")), t.column_index(mapped(options, "y")),
                                      t.column_index(mapped(options, "z"))};
  };
  const std::size_t uid = tu.column_index(mapped(options, "id")), did = td.column_index(mapped(options, "id"));
  const auto cu = cols(tu), cd = cols(td);
  const std::size_t n = tu.n_rows();
  resize(g, n);
  g.deformed.setConstant(kNaN);
  std::unordered_map<std::string, std::size_t> index;
  bool first = true;
  for (std::size_t r = 0; r < n; ++r) {
    const Index p = static_cast<Index>(r);
    g.ids[r] = take_id(tu, r, uid, index);
    read_xyz(tu, r, cu, g.undeformed.row(p).data());
    read_ij(tu, options, g, r, p, first);
    g.where[r] = where_of(tu, r);
  }
  std::unordered_map<std::string, std::size_t> seen_deformed;
  for (std::size_t r = 0; r < td.n_rows(); ++r) {
    const std::string id = take_id(td, r, did, seen_deformed);
    auto it = index.find(id);
    if (it == index.end())
      throw InputError(located_message(td.file_name(), td.line(r), td.char_column(r, did),
                                       "id '" + id + "' is not in the undeformed file " + undeformed_path));
    read_xyz(td, r, cd, g.deformed.row(static_cast<Index>(it->second)).data());
  }
  drop_ij_unless_present(g);
  return g;
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
    if (v == kNoGridIndex) impl_->csv.add(kNaN);
    else impl_->csv.add(v);
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
      if (grid.has_ij) w.add(grid.ids[k], X, x, grid.i[k], grid.j[k]);
      else w.add(grid.ids[k], X, x);
    }
  });
}

}  // namespace sf::io

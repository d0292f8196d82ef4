#include "gsa/grid.hpp"

#include <cmath>
#include <limits>
#include <set>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"

namespace sf::gsa {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const std::set<std::string>& known_keys() {
  static const std::set<std::string> keys = {"id", "X", "Y", "Z", "x", "y", "z", "u", "v", "w", "i", "j"};
  return keys;
}

std::string mapped(const GridReadOptions& o, const std::string& key) {
  auto it = o.columns.find(key);
  return it == o.columns.end() ? key : it->second;
}

io::CsvTable load(const std::string& path, const GridReadOptions& options) {
  io::CsvOptions co;
  co.delimiter = options.delimiter;
  return io::read_csv(path, co);
}

std::string where_of(const io::CsvTable& t, std::size_t row) {
  return t.file_name() + ":" + std::to_string(t.line(row));
}

// Reads a 3-vector from columns (a, b, c); a row with any missing entry is all NaN.
void read_xyz(const io::CsvTable& t, std::size_t row, const std::array<std::size_t, 3>& cols, double* out) {
  bool missing = false;
  for (int k = 0; k < 3; ++k) {
    out[k] = t.number(row, cols[k], /*allow_missing=*/true);
    if (std::isnan(out[k])) missing = true;
  }
  if (missing) out[0] = out[1] = out[2] = kNaN;
}

void read_ij(const io::CsvTable& t, const GridReadOptions& o, GridData& g, std::size_t row,
             Index p, bool& first) {
  const auto ci = t.find_column(mapped(o, "i")), cj = t.find_column(mapped(o, "j"));
  if (first) {
    g.has_ij = ci.has_value() && cj.has_value();
    first = false;
  }
  if (!g.has_ij) return;
  if (t.is_missing(row, *ci) || t.is_missing(row, *cj)) {
    g.i[p] = g.j[p] = std::numeric_limits<long>::min();
    return;
  }
  g.i[p] = t.integer(row, *ci);
  g.j[p] = t.integer(row, *cj);
}

// Reads row r's id and records it in `seen` (id -> row); empty or repeated ids
// are input errors naming the file, line and column (and the first occurrence).
std::string take_id(const io::CsvTable& t, std::size_t r, std::size_t col,
                    std::unordered_map<std::string, std::size_t>& seen) {
  std::string id(t.cell(r, col));
  if (id.empty()) throw InputError(located_message(t.file_name(), t.line(r), t.char_column(r, col), "empty id"));
  auto [it, fresh] = seen.emplace(id, r);
  if (!fresh)
    throw InputError(located_message(t.file_name(), t.line(r), t.char_column(r, col),
                                     "duplicate id '" + id + "' (first at line " + std::to_string(t.line(it->second)) +
                                         "); ids must be unique"));
  return id;
}

}  // namespace

std::map<std::string, std::string> parse_column_map(const std::string& text) {
  std::map<std::string, std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    const std::size_t eq = item.find('=');
    if (item.empty() || eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw UsageError("--columns: expected NAME=COLUMN pairs separated by commas (e.g. X=x0,u=disp_x), found '" +
                       item + "'");
    const std::string key = item.substr(0, eq);
    if (!known_keys().count(key))
      throw UsageError("--columns: unknown name '" + key + "' (expected one of id X Y Z x y z u v w i j)");
    out[key] = item.substr(eq + 1);
    start = end + 1;
  }
  return out;
}

char parse_delimiter(const std::string& text) {
  if (text == "tab" || text == "\\t") return '\t';
  if (text == "comma") return ',';
  if (text == "semicolon") return ';';
  if (text == "space") return ' ';
  if (text.size() == 1) return text[0];
  throw UsageError("--delimiter: expected one character or tab/comma/semicolon/space, found '" + text + "'");
}

GridData read_grid(const std::string& path, const GridReadOptions& options) {
  const io::CsvTable t = load(path, options);
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
  g.ids.resize(n);
  g.undeformed.resize(n, 3);
  g.deformed.resize(n, 3);
  g.i.resize(n);
  g.j.resize(n);
  g.where.resize(n);
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
  if (!g.has_ij) {
    g.i.clear();
    g.j.clear();
  }
  return g;
}

GridData read_grid_pair(const std::string& undeformed_path, const std::string& deformed_path,
                        const GridReadOptions& options) {
  const io::CsvTable tu = load(undeformed_path, options), td = load(deformed_path, options);
  GridData g;
  g.sources = {undeformed_path, deformed_path};
  auto cols = [&](const io::CsvTable& t) {
    return std::array<std::size_t, 3>{t.column_index(mapped(options, "x")), t.column_index(mapped(options, "y")),
                                      t.column_index(mapped(options, "z"))};
  };
  const std::size_t uid = tu.column_index(mapped(options, "id")), did = td.column_index(mapped(options, "id"));
  const auto cu = cols(tu), cd = cols(td);
  const std::size_t n = tu.n_rows();
  g.ids.resize(n);
  g.undeformed.resize(n, 3);
  g.deformed.setConstant(n, 3, kNaN);
  g.i.resize(n);
  g.j.resize(n);
  g.where.resize(n);
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
  if (!g.has_ij) {
    g.i.clear();
    g.j.clear();
  }
  return g;
}

}  // namespace sf::gsa

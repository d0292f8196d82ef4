#pragma once
// The grid file (CONTRACT.md "Grid file"): the digitised marks of a sheet before and
// after forming. `gsa analyse` reads it; `gsa synth` and `simform run --grid-out` write it.
// This is the one place that knows its columns.
//
// One file, CSV by the rules of common/io/csv.hpp (UTF-8, '#' comment lines, one header
// row, column order free, names case-sensitive):
//
//   # units: mm
//   id,X,Y,Z,x,y,z,i,j
//   P0_0,-50,-50,0,-46.7351,-46.7351,45.0739,0,0
//   P0_2,-40,-50,0,,,,0,2
//
//   column    required  meaning
//   id        yes       label of the mark: unique, not empty
//   X, Y, Z   yes       undeformed position
//   x, y, z   yes       deformed position
//   i, j      no        integer grid row and column of the mark
//
// Other columns (a writer's own, e.g. `gsa digitise`'s reprojection errors) are ignored.
//
// An empty cell or "nan" means "not digitised in that state": a position with any
// coordinate missing counts as missing as a whole. Rows come in any order.
//
// Two files instead of one: an undeformed and a deformed file, each with columns
// id, x, y, z (i, j optional, taken from the undeformed file), joined on id. A mark
// missing from the deformed file has no deformed position; an id of the deformed file
// that the undeformed file lacks is an error.
//
// Keys can be mapped to other column names (GridReadOptions::columns). When u, v or w
// is mapped, those columns are displacements and the deformed position is X + u.
//
// Errors are sf::InputError naming the file, line and field:
//   "grid.csv:4:3: expected a number in column 'Y', found '2x'"
//   "grid.csv:5:1: duplicate id 'p1' (first at line 2); ids must be unique"

#include <array>
#include <limits>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "common/core/types.hpp"

namespace sf::io {

// Every key a grid file's columns can stand for: id X Y Z x y z u v w i j.
inline constexpr std::array<std::string_view, 12> kGridColumnKeys = {"id", "X", "Y", "Z", "x", "y",
                                                                     "z",  "u", "v", "w", "i", "j"};
bool is_grid_column_key(std::string_view key);

// The grid index of a mark whose i or j cell is empty.
inline constexpr long kNoGridIndex = std::numeric_limits<long>::min();

struct GridReadOptions {
  char delimiter = ',';
  // Key (kGridColumnKeys) -> the column's name in the file; unmapped keys are their own
  // names.
  std::map<std::string, std::string> columns;
};

// The marks of a grid file.
struct GridData {
  std::vector<std::string> ids;
  Points3 undeformed;  // n x 3; a row of NaN where not digitised
  Points3 deformed;    // n x 3; a row of NaN where not digitised
  bool has_ij = false;
  std::vector<long> i, j;          // grid row and column (n each) when has_ij; kNoGridIndex where empty
  std::vector<std::string> where;  // "file:line" of each mark, for messages
  std::vector<std::string> sources;  // the file(s) read

  Index n_points() const { return static_cast<Index>(ids.size()); }
  bool has_undeformed(Index p) const { return undeformed.row(p).allFinite(); }
  bool has_deformed(Index p) const { return deformed.row(p).allFinite(); }
};

// Reads one grid file. Throws sf::InputError naming the file (and line and column) when it
// cannot be read, lacks a required column, holds a malformed number, an empty or repeated id.
GridData read_grid_file(const std::string& path, const GridReadOptions& options = {});
// Reads the two-file form, joined on id; rows in the undeformed file's order.
GridData read_grid_file_pair(const std::string& undeformed_path, const std::string& deformed_path,
                             const GridReadOptions& options = {});

struct GridWriteOptions {
  // Comment lines written first, each as "# " + line (a line break in a comment starts
  // another comment line).
  std::vector<std::string> comments;
  std::string units;     // not empty: a last comment line "# units: U"
  bool with_ij = false;  // GridFileWriter: columns i, j after z
  // GridFileWriter: more numeric columns after the contract's (after i, j), a writer's own
  // per-mark figures (e.g. `gsa digitise`'s views and reprojection errors). Readers of the
  // grid file ignore them. A name that is a contract key (kGridColumnKeys) is a programming
  // error (std::logic_error).
  std::vector<std::string> extra_columns;
};

// Writes a grid file row by row (for writers that compute the marks one at a time):
//
//   io::write_file_atomic(path, [&](std::ostream& out) {
//     io::GridWriteOptions o{{"simform --grid-out: 11 x 11 marks on ply 'top'"}, "mm", true};
//     io::GridFileWriter w(out, o);
//     w.add("m0_0", X, x, 0, 0);
//   });
//
// Header id,X,Y,Z,x,y,z (and i,j, then the extra columns). Numbers are written in the
// shortest form that reads back to the same double; a position with a NaN coordinate is
// written as empty cells (not digitised), and so is a NaN extra value. What it writes,
// read_grid_file() reads back exactly.
class GridFileWriter {
 public:
  // Writes the comment lines and the header.
  GridFileWriter(std::ostream& out, const GridWriteOptions& options);
  ~GridFileWriter();
  GridFileWriter(const GridFileWriter&) = delete;
  GridFileWriter& operator=(const GridFileWriter&) = delete;

  // One mark. The first form needs options.with_ij == false, the second true; an empty id,
  // the wrong form, or `extra` not one value per options.extra_columns is a programming
  // error (std::logic_error). kNoGridIndex writes an empty cell.
  void add(std::string_view id, const Vec3& undeformed, const Vec3& deformed, const std::vector<double>& extra = {});
  void add(std::string_view id, const Vec3& undeformed, const Vec3& deformed, long i, long j,
           const std::vector<double>& extra = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes `grid` to `path` atomically (io/atomic_file.hpp), with i, j when grid.has_ij
// (options.with_ij and options.extra_columns are ignored). Throws sf::Error naming the
// path when it cannot write.
void write_grid_file(const std::string& path, const GridData& grid, const GridWriteOptions& options = {});

}  // namespace sf::io

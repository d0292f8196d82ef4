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
//   id        yes       label of the mark: unique, not empty (without it: the row number)
//   X, Y, Z   yes       undeformed (reference) position
//   x, y, z   yes       deformed (current) position
//   u, v, w   no        displacement x - X: with X, Y, Z instead of x, y, z, or with x, y, z
//                       instead of X, Y, Z (then X = x - u)
//   i, j      no        integer grid row and column of the mark
//   sigma     no        uncertainty of the measured positions (length), for fit weights
//
// Other columns (a writer's own, e.g. `gsa digitise`'s reprojection errors) are ignored.
//
// An empty cell or "nan" means "not digitised in that state": a position with any
// coordinate missing counts as missing as a whole. Rows come in any order.
//
// Two files instead of one: an undeformed and a deformed file, each with columns
// id, x, y, z (i, j optional, taken from the undeformed file), joined on id. A mark
// missing from the deformed file has no deformed position; an id of the deformed file
// that the undeformed file lacks is an error. In the two-file form (and the stage
// series, common/io/grid_series.hpp) each file stands for one state: its position is
// x, y, z, or X + u where the file has reference positions and displacements.
//
// Measuring-system exports (GridReadOptions::format, common/io/measurement_formats.hpp)
// name these columns otherwise, put a preamble before the header, mark points they could
// not measure, carry units in brackets ("coor.X [mm]") and uncertainties. The reader
// finds the header as the first line holding the columns it needs (and the delimiter
// with it), converts bracketed units (and "# units: U" comment lines before the header)
// to GridReadOptions::units, and keeps the points the system marked invalid, with no
// position in that state and a not_measured flag.
//
// Errors are sf::InputError naming the file, line and field:
//   "grid.csv:4:3: expected a number in column 'Y', found '2x'"
//   "grid.csv:5:1: duplicate id 'p1' (first at line 2); ids must be unique"
//   "vic.csv:1: missing required column 'W' (--format vic3d reads X, Y, Z, U, V, W; found: ...)"
//   "dice.txt:22:2: column 'COORDINATE_X' is in image pixels; ..."

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/csv.hpp"
#include "common/io/measurement_formats.hpp"

namespace sf::io {

// Every key a grid file's columns can stand for: id X Y Z x y z u v w i j sigma.
inline constexpr std::array<std::string_view, 13> kGridColumnKeys = {"id", "X", "Y", "Z", "x", "y",    "z",
                                                                     "u",  "v", "w", "i", "j", "sigma"};
bool is_grid_column_key(std::string_view key);

// The grid index of a mark whose i or j cell is empty.
inline constexpr long kNoGridIndex = std::numeric_limits<long>::min();

struct GridReadOptions {
  // The column layout (measurement_formats.hpp); plain is the grid file above. kAuto:
  // the preset whose columns and key the header holds (a note says which), else plain;
  // with `columns` given, plain.
  MeasurementFormat format = MeasurementFormat::kPlain;
  // Field separator; kDetectDelimiter: found with the header (',', ';', tab or blanks).
  char delimiter = kDetectDelimiter;
  // Key (kGridColumnKeys) -> the column's name in the file (with or without its unit in
  // brackets). A key of a triple (X Y Z, x y z, u v w) replaces the format's names for
  // that triple; its other keys are then their own names.
  std::map<std::string, std::string> columns;
  // The id made of several columns, their cells joined by '_' (e.g. {"x_pic", "y_pic"});
  // empty: the format's key (columns["id"] when mapped).
  std::vector<std::string> id_columns;
  // The id is the row number (1, 2, ... in file order), as when there is no id column in
  // the one-file form; in the two-file form and series, rows are then joined by order.
  bool id_from_row = false;
  // What the position columns of a format with displacements hold (not for plain).
  Positions positions = Positions::kAsFormat;
  int skip_lines = 0;   // lines 1..N are not read (then the header is searched)
  int header_line = 0;  // > 0: the header is this line (1-based)
  char decimal = '.';   // decimal separator: '.', ',' or kDetectDecimal (csv.hpp; a note says when ',')'
  // The length unit of the positions read; columns in other units are converted
  // (length_units.hpp). Text that is no known length unit only names the unit.
  std::string units = "mm";
  // Length units per image pixel, for columns in pixels (DICe 2-D, sigma of VIC-3D and
  // DICe); NaN: not given (pixel columns are then an error, or a note for sigma).
  double pixel_size = std::numeric_limits<double>::quiet_NaN();
  // > 0: nominal undeformed positions from the grid indices: X = j * pitch, Y = i * pitch,
  // Z = 0 (j along X, i along Y); the file's reference positions are not read.
  double pitch = std::numeric_limits<double>::quiet_NaN();

  // Throws sf::UsageError naming the field for contradictory or out-of-range values.
  void validate() const;
};

// Bits of GridData::not_measured.
inline constexpr std::uint8_t kNotMeasuredUndeformed = 1;
inline constexpr std::uint8_t kNotMeasuredDeformed = 2;

// The marks of a grid file.
struct GridData {
  std::vector<std::string> ids;
  Points3 undeformed;  // n x 3; a row of NaN where not digitised
  Points3 deformed;    // n x 3; a row of NaN where not digitised
  bool has_ij = false;
  std::vector<long> i, j;            // grid row and column (n each) when has_ij; kNoGridIndex where empty
  std::vector<std::string> where;    // "file:line" of each mark, for messages
  std::vector<std::string> sources;  // the file(s) read
  // Uncertainty of each measured position (a standard deviation, in `units`), for fit
  // weights w = 1/sigma^2: n entries, or empty when the input gives none; NaN for a mark
  // without one. A file holding both states gives the same value to both.
  std::vector<double> sigma_undeformed, sigma_deformed;
  // Marks the measuring system flagged as not measured in a state (its invalid-point
  // rule, not_measured_rule): kNotMeasuredUndeformed / kNotMeasuredDeformed bits, n
  // entries; empty when none is flagged. The position in a flagged state is NaN.
  std::vector<std::uint8_t> not_measured;
  std::string not_measured_rule;  // e.g. "sigma < 0 (the row is written as zeros)"
  std::string units = "mm";       // length unit of the positions and sigma
  // What the reader assumed, converted or could not use, one line each, for the user
  // (e.g. "vic.csv: sigma is in pixels and no pixel size was given: not used").
  std::vector<std::string> notes;

  Index n_points() const { return static_cast<Index>(ids.size()); }
  bool has_undeformed(Index p) const { return undeformed.row(p).allFinite(); }
  bool has_deformed(Index p) const { return deformed.row(p).allFinite(); }
  bool not_measured_undeformed(Index p) const {
    return !not_measured.empty() && (not_measured[static_cast<std::size_t>(p)] & kNotMeasuredUndeformed);
  }
  bool not_measured_deformed(Index p) const {
    return !not_measured.empty() && (not_measured[static_cast<std::size_t>(p)] & kNotMeasuredDeformed);
  }
};

// Reads one grid file (both states in each row). Throws sf::InputError naming the file (and
// line and column) when it cannot be read, lacks a required column, holds a malformed
// number, an empty or repeated id, or a unit that cannot be converted.
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

#pragma once
// The rows of one measurement file as the grid readers take them (grid_file.cpp,
// grid_series.cpp): each row's id, reference and current position in the options' unit,
// the invalid-point flags of its format, its uncertainty and grid indices. Which columns
// hold what is resolved here, from the format's layouts (measurement_formats.hpp), the
// user's column map and the header; the header is found by that resolution.

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/grid_file.hpp"

namespace sf::io::detail {

// What a file must give: both states in each row (the one-file form), or one state
// (a file of the two-file form or of a stage series: its current position).
enum class FileRole { kBothStates, kOneState };

struct GridRow {
  std::string id;
  Vec3 reference = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  // X; NaN where unknown
  Vec3 current = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());    // x; NaN where unknown
  bool flagged_reference = false;                           // the format's rule marked the reference state not measured
  bool flagged_current = false;                             // ... the current state
  double sigma = std::numeric_limits<double>::quiet_NaN();  // in the options' unit
  long i = kNoGridIndex, j = kNoGridIndex;
  int line = 0;       // line in the file
  int id_column = 0;  // 1-based character column of the id's first field (0: row number)
  std::string stage;  // the stage column's cell, when asked for
};

struct GridRows {
  std::string path;
  std::vector<GridRow> rows;
  bool has_ij = false;
  bool has_sigma = false;         // sigma values were read (and converted)
  bool has_reference = false;     // the layout gives reference positions (or the pitch does)
  bool has_displacement = false;  // the layout has displacement columns
  std::string id_text;            // "id", "x_pic, y_pic" or "row number", for messages
  std::vector<std::string> notes;
};

// Reads `path` as `role` needs. stage_column: when not empty, the column whose cell is each
// row's stage (ids are then unique per stage, not per file).
GridRows read_grid_rows(const std::string& path, const GridReadOptions& options, FileRole role,
                        const std::string& stage_column = "");

}  // namespace sf::io::detail

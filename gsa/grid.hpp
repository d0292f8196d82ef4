#pragma once
// Reading digitised grids (CONTRACT.md "Grid file").
//
// One file: columns id, X, Y, Z (undeformed), x, y, z (deformed), optional i, j.
// Two files: --undeformed U.csv --deformed D.csv, each id, x, y, z (+ i, j), joined on id.
// Column names can be mapped (--columns "X=x0,Y=y0,Z=z0,u=u,v=v,w=w"): with
// displacement columns u, v, w the deformed position is X + u.
// Empty cells and "nan" mean "not digitised in that state".

#include <map>
#include <string>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa {

struct GridReadOptions {
  char delimiter = ',';
  // Contract name -> column name in the file (keys: id X Y Z x y z u v w i j).
  std::map<std::string, std::string> columns;
};

// Parses "--columns" text "X=x0,Y=y0" (throws sf::UsageError naming --columns).
std::map<std::string, std::string> parse_column_map(const std::string& text);
// Parses a delimiter option: one character, or "tab", "comma", "semicolon", "space".
char parse_delimiter(const std::string& text);

struct GridData {
  std::vector<std::string> ids;
  Points3 undeformed;  // n x 3, NaN row entries where not digitised
  Points3 deformed;    // n x 3, NaN row entries where not digitised
  bool has_ij = false;
  std::vector<long> i, j;  // grid row/column when has_ij
  std::vector<std::string> where;  // "file:line" of each point, for messages
  std::vector<std::string> sources;

  Index n_points() const { return static_cast<Index>(ids.size()); }
  bool has_undeformed(Index p) const { return undeformed.row(p).allFinite(); }
  bool has_deformed(Index p) const { return deformed.row(p).allFinite(); }
};

GridData read_grid(const std::string& path, const GridReadOptions& options = {});
GridData read_grid_pair(const std::string& undeformed_path, const std::string& deformed_path,
                        const GridReadOptions& options = {});

}  // namespace sf::gsa

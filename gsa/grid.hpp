#pragma once
// The marks `gsa analyse` takes in: gsa's names for the grid file of
// common/io/grid_file.hpp, where the format is defined, read and written
// (CONTRACT.md "Grid file").

#include <string>

#include "common/io/grid_file.hpp"

namespace sf::gsa {

using GridData = io::GridData;
using GridReadOptions = io::GridReadOptions;

inline GridData read_grid(const std::string& path, const GridReadOptions& options = {}) {
  return io::read_grid_file(path, options);
}
inline GridData read_grid_pair(const std::string& undeformed_path, const std::string& deformed_path,
                               const GridReadOptions& options = {}) {
  return io::read_grid_file_pair(undeformed_path, deformed_path, options);
}

}  // namespace sf::gsa

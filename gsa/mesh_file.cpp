#include "gsa/mesh_file.hpp"

#include <fstream>
#include <nlohmann/json.hpp>

#include "common/core/error.hpp"
#include "common/io/json.hpp"

namespace sf::gsa {

mesh::SurfaceMesh read_mesh_file(const std::string& path) {
  // io::read_json: a missing file, a folder, bad JSON (line and column) or a number
  // beyond the range of a double are input errors naming the file.
  const nlohmann::json j = io::read_json(path);
  if (!j.is_object() || !j.contains("nodes") || !j.contains("elements") || !j["nodes"].is_array() ||
      !j["elements"].is_array())
    throw InputError(path + ": expected an object with arrays \"nodes\" and \"elements\"");
  const auto& jn = j["nodes"];
  const auto& je = j["elements"];
  if (jn.size() < 4 || je.empty()) throw InputError(path + ": a mesh needs at least 4 nodes and 1 element");
  Points3 nodes(static_cast<Index>(jn.size()), 3);
  for (std::size_t n = 0; n < jn.size(); ++n) {
    if (!jn[n].is_array() || jn[n].size() != 3)
      throw InputError(path + ": nodes[" + std::to_string(n) + "]: expected [x, y, z]");
    for (int k = 0; k < 3; ++k) {
      if (!jn[n][k].is_number())
        throw InputError(path + ": nodes[" + std::to_string(n) + "][" + std::to_string(k) + "]: expected a number");
      nodes(static_cast<Index>(n), k) = jn[n][k].get<double>();
    }
  }
  std::vector<std::array<Index, 4>> elements(je.size());
  for (std::size_t e = 0; e < je.size(); ++e) {
    if (!je[e].is_array() || je[e].size() != 4)
      throw InputError(path + ": elements[" + std::to_string(e) + "]: expected [n0, n1, n2, n3]");
    for (int k = 0; k < 4; ++k) {
      if (!je[e][k].is_number_integer())
        throw InputError(path + ": elements[" + std::to_string(e) + "][" + std::to_string(k) +
                         "]: expected a node id (integer)");
      elements[e][k] = je[e][k].get<Index>();
    }
  }
  return mesh::mesh_from_corners(nodes, elements, path);
}

}  // namespace sf::gsa

#include "gsa/surfaces_file.hpp"

#include <fstream>
#include <nlohmann/json.hpp>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"

namespace sf::gsa {

namespace {
nlohmann::json rows_of(const MatX& m) {
  nlohmann::json a = nlohmann::json::array();
  for (Index r = 0; r < m.rows(); ++r) a.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return a;
}

MatX matrix_of(const nlohmann::json& a, Index rows, const std::string& where) {
  if (!a.is_array() || static_cast<Index>(a.size()) != rows)
    throw InputError(where + ": expected " + std::to_string(rows) + " rows [x, y, z]");
  MatX m(rows, 3);
  for (Index r = 0; r < rows; ++r) {
    const auto& row = a[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 3) throw InputError(where + "[" + std::to_string(r) + "]: expected [x, y, z]");
    for (int c = 0; c < 3; ++c) {
      if (!row[static_cast<std::size_t>(c)].is_number())
        throw InputError(where + "[" + std::to_string(r) + "]: expected numbers");
      m(r, c) = row[static_cast<std::size_t>(c)].get<double>();
    }
  }
  return m;
}
}  // namespace

void write_surfaces_file(const std::string& path, const mesh::SurfaceMesh& mesh, const MatX& undeformed,
                         const MatX& deformed, const std::string& units) {
  nlohmann::json j;
  j["format"] = "gsa fitted surfaces";
  j["version"] = 1;
  j["units"] = units;
  j["nodes"] = mesh.n_nodes();
  nlohmann::json els = nlohmann::json::array();
  for (const mesh::Element& el : mesh.elements()) {
    nlohmann::json e;
    e["nodes"] = {el.nodes[0], el.nodes[1], el.nodes[2], el.nodes[3]};
    e["shape"] = el.shape == mesh::ElementShape::kCollapsed ? "collapsed" : "quad";
    nlohmann::json sc = nlohmann::json::array();
    for (const auto& s : el.scale) sc.push_back({s[0], s[1]});
    e["scale"] = sc;
    e["apex_angle"] = {el.apex_angle[0], el.apex_angle[1]};
    els.push_back(std::move(e));
  }
  j["elements"] = std::move(els);
  j["undeformed"] = rows_of(undeformed);
  j["deformed"] = rows_of(deformed);
  io::write_file_atomic(path, [&](std::ostream& os) { os << j.dump() << "\n"; });
}

FittedSurfaces read_surfaces_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the fitted surfaces file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  if (!j.is_object() || j.value("format", "") != "gsa fitted surfaces")
    throw InputError(path + ": not a fitted surfaces file (expected \"format\": \"gsa fitted surfaces\")");
  if (j.value("version", 0) != 1)
    throw InputError(path + ": version " + j.value("version", nlohmann::json(nullptr)).dump() +
                     " not understood (this gsa reads version 1)");
  if (!j.contains("nodes") || !j["nodes"].is_number_integer() || j["nodes"].get<Index>() < 1)
    throw InputError(path + ": \"nodes\": expected the number of nodes");
  if (!j.contains("elements") || !j["elements"].is_array() || j["elements"].empty())
    throw InputError(path + ": \"elements\": expected an array of elements");
  FittedSurfaces s;
  if (j.contains("units") && j["units"].is_string()) s.units = j["units"].get<std::string>();
  const Index n_nodes = j["nodes"].get<Index>();
  s.mesh.add_nodes(n_nodes);
  const auto& els = j["elements"];
  for (std::size_t e = 0; e < els.size(); ++e) {
    const std::string where = path + ": elements[" + std::to_string(e) + "]";
    const auto& je = els[e];
    mesh::Element el;
    try {
      const auto nodes = je.at("nodes").get<std::vector<Index>>();
      const auto scale = je.at("scale").get<std::vector<std::array<double, 2>>>();
      const auto apex = je.at("apex_angle").get<std::array<double, 2>>();
      const std::string shape = je.at("shape").get<std::string>();
      if (nodes.size() != 4 || scale.size() != 4) throw InputError(where + ": expected 4 nodes and 4 scale pairs");
      for (int k = 0; k < 4; ++k) {
        if (nodes[static_cast<std::size_t>(k)] < 0 || nodes[static_cast<std::size_t>(k)] >= n_nodes)
          throw InputError(where + ": node " + std::to_string(nodes[static_cast<std::size_t>(k)]) + " out of range");
        el.nodes[static_cast<std::size_t>(k)] = nodes[static_cast<std::size_t>(k)];
        el.scale[static_cast<std::size_t>(k)] = scale[static_cast<std::size_t>(k)];
      }
      if (shape != "quad" && shape != "collapsed") throw InputError(where + ": shape must be quad or collapsed");
      el.shape = shape == "collapsed" ? mesh::ElementShape::kCollapsed : mesh::ElementShape::kQuad;
      el.apex_angle = apex;
    } catch (const nlohmann::json::exception& ex) {
      throw InputError(where + ": expected nodes, shape, scale and apex_angle (" + std::string(ex.what()) + ")");
    }
    s.mesh.add_element(el);
  }
  s.undeformed = matrix_of(j.value("undeformed", nlohmann::json()), s.mesh.n_dofs(), path + ": undeformed");
  s.deformed = matrix_of(j.value("deformed", nlohmann::json()), s.mesh.n_dofs(), path + ": deformed");
  s.mesh.geometry() = s.undeformed;
  s.mesh.build_topology();
  return s;
}

}  // namespace sf::gsa

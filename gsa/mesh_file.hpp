#pragma once
// User-supplied surface meshes for `gsa analyse --mesh FILE` (docs/usage.md, "Your own mesh").
//
// JSON, in the grid's length unit:
//   {
//     "nodes":    [[x, y, z], ...],                 // corner nodes, ids from 0 in this order
//     "elements": [[n0, n1, n2, n3], ...]           // local order (0,0) (1,0) (0,1) (1,1)
//   }
// xi1 runs from n0 to n1 (and n2 to n3), xi2 from n0 to n2; all elements must be
// listed in the same orientation. [a, a, n2, n3] is a collapsed (3-noded) element
// with its apex at node a (e.g. the pole of a dome). The nodes should lie near the
// undeformed marks: they are the starting surface of the undeformed fit.

#include <string>

#include "common/mesh/surface_mesh.hpp"

namespace sf::gsa {

mesh::SurfaceMesh read_mesh_file(const std::string& path);

}  // namespace sf::gsa

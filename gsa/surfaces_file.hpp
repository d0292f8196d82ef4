#pragma once
// surfaces.json: the two fitted bicubic Hermite surfaces of a `gsa analyse` run (surface
// method), so that a results folder can be evaluated again anywhere, not only at its
// marks (`gsa compare` maps fields through it; docs/usage.md "Results folder").
//
//   {
//     "format": "gsa fitted surfaces", "version": 1, "units": "mm",
//     "nodes": N,
//     "elements": [{"nodes": [n0, n1, n2, n3], "shape": "quad" | "collapsed",
//                   "scale": [[S1, S2] x 4], "apex_angle": [a0, a1]}, ...],
//     "undeformed": [[x, y, z] x 4N],     // nodal parameters by arc length, dof 4n + d
//     "deformed":   [[x, y, z] x 4N]      // (common/mesh/surface_mesh.hpp)
//   }
// Numbers are written with round-trip precision: read back, the surfaces are the same
// to the last bit.

#include <string>

#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::gsa {

struct FittedSurfaces {
  mesh::SurfaceMesh mesh;     // topology built; geometry() = undeformed parameters
  MatX undeformed, deformed;  // n_dofs x 3
  std::string units = "mm";
};

void write_surfaces_file(const std::string& path, const mesh::SurfaceMesh& mesh, const MatX& undeformed,
                         const MatX& deformed, const std::string& units);
// Throws sf::InputError naming the file and the entry for anything malformed.
FittedSurfaces read_surfaces_file(const std::string& path);

}  // namespace sf::gsa

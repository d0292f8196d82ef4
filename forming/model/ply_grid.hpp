#pragma once
// The structure of a ply built on a structured rectangle
// (mesh::make_rectangle_mesh(origin, x, y, Lx, Ly, n1, n2)): the numbering of its surface
// nodes, elements and sides, which boundary conditions, edge loads and outputs refer to.
//
//                 y1 (j = n2)
//        s 8 ------ s 9 ------ s 10 ----- s 11        surface node (i, j) = j (n1 + 1) + i
//         |  e 3     |  e 4     |  e 5     |          element (i, j)      = j n1 + i
//   x0   s 4 ------ s 5 ------ s 6 ------ s 7   x1    (n1 = 3, n2 = 2 drawn)
//  (i=0)  |  e 0     |  e 1     |  e 2     |  (i=n1)  ply node of surface node s in layer l
//        s 0 ------ s 1 ------ s 2 ------ s 3         (0 bottom, 1 top): s + l n_s
//                 y0 (j = 0)                          (forming/model/ply_mesh.hpp)
//
// Sides x0 / x1 are the edges x = x0 and x = x0 + Lx, y0 / y1 likewise; kBottom is the
// bottom face z = origin z (symmetry planes only).
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "forming/model/loads.hpp"

namespace sf::forming {

enum class PlySide { kX0, kX1, kY0, kY1, kBottom };
// "x0", "x1", "y0", "y1", "bottom" (the case-file names).
std::string to_string(PlySide side);

struct PlyGrid {
  int n1 = 0;  // elements along x
  int n2 = 0;  // elements along y

  Index n_surface_nodes() const { return static_cast<Index>(n1 + 1) * (n2 + 1); }
  Index surface_node(int i, int j) const { return static_cast<Index>(j) * (n1 + 1) + i; }
  Index element(int i, int j) const { return static_cast<Index>(j) * n1 + i; }
  // Surface nodes of a side, along it in ascending order (kBottom: every surface node).
  std::vector<Index> side_surface_nodes(PlySide side) const;
  // The side faces of the bricks along an edge side of body `body` (none for kBottom).
  std::vector<FaceRef> side_faces(int body, PlySide side) const;
};

}  // namespace sf::forming

#include "forming/model/ply_grid.hpp"

namespace sf::forming {

std::string to_string(PlySide side) {
  switch (side) {
    case PlySide::kX0:
      return "x0";
    case PlySide::kX1:
      return "x1";
    case PlySide::kY0:
      return "y0";
    case PlySide::kY1:
      return "y1";
    case PlySide::kBottom:
      return "bottom";
  }
  return "?";
}

std::vector<Index> PlyGrid::side_surface_nodes(PlySide side) const {
  std::vector<Index> out;
  switch (side) {
    case PlySide::kX0:
      for (int j = 0; j <= n2; ++j) out.push_back(surface_node(0, j));
      break;
    case PlySide::kX1:
      for (int j = 0; j <= n2; ++j) out.push_back(surface_node(n1, j));
      break;
    case PlySide::kY0:
      for (int i = 0; i <= n1; ++i) out.push_back(surface_node(i, 0));
      break;
    case PlySide::kY1:
      for (int i = 0; i <= n1; ++i) out.push_back(surface_node(i, n2));
      break;
    case PlySide::kBottom:
      for (Index s = 0; s < n_surface_nodes(); ++s) out.push_back(s);
      break;
  }
  return out;
}

std::vector<FaceRef> PlyGrid::side_faces(int body, PlySide side) const {
  std::vector<FaceRef> out;
  switch (side) {
    case PlySide::kX0:
      for (int j = 0; j < n2; ++j) out.push_back({body, element(0, j), BrickFace::kXi1Min});
      break;
    case PlySide::kX1:
      for (int j = 0; j < n2; ++j) out.push_back({body, element(n1 - 1, j), BrickFace::kXi1Max});
      break;
    case PlySide::kY0:
      for (int i = 0; i < n1; ++i) out.push_back({body, element(i, 0), BrickFace::kXi2Min});
      break;
    case PlySide::kY1:
      for (int i = 0; i < n1; ++i) out.push_back({body, element(i, n2 - 1), BrickFace::kXi2Max});
      break;
    case PlySide::kBottom:  // a face, not an edge
      break;
  }
  return out;
}

}  // namespace sf::forming

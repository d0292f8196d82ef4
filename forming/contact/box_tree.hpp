#pragma once
// A bounding-volume hierarchy of axis-aligned boxes (contact search): which boxes hold a
// point, within a margin. Built top-down by splitting the boxes at the median of their
// centres along the longest axis of the centres' spread, down to leaves of at most
// kLeafSize boxes.
//
// Cost: building O(n log n) for n boxes (nth_element per level); a query visits the
// nodes whose boxes hold the point, O(log n + k) for k hits when the boxes are about
// as large as their spacing (faces of a mesh). Contact rebuilds the tree from the
// current face boxes at every assembly (bench/simform_contact_bench.cpp measures it).
#include <vector>

#include "common/core/types.hpp"
#include "forming/contact/contact_surface.hpp"

namespace sf::forming {

class BoxTree {
 public:
  static constexpr int kLeafSize = 4;
  BoxTree() = default;
  explicit BoxTree(std::vector<Box> boxes);

  // Indices of the boxes that hold p within `margin` (mm), appended to `hits` (cleared
  // first), in no particular order.
  void query(const Vec3& p, double margin, std::vector<Index>& hits) const;
  Index n_boxes() const { return static_cast<Index>(boxes_.size()); }
  Index n_nodes() const { return static_cast<Index>(nodes_.size()); }

 private:
  struct Node {
    Box box;
    int left = -1, right = -1;  // children (internal node)
    int first = 0, count = 0;   // range of order_ (leaf: count > 0)
  };
  int build(int first, int count);

  std::vector<Box> boxes_;
  std::vector<Index> order_;
  std::vector<Node> nodes_;
};

}  // namespace sf::forming

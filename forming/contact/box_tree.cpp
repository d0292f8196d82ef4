#include "forming/contact/box_tree.hpp"

#include <algorithm>
#include <numeric>
#include <utility>

namespace sf::forming {

BoxTree::BoxTree(std::vector<Box> boxes) : boxes_(std::move(boxes)) {
  order_.resize(boxes_.size());
  std::iota(order_.begin(), order_.end(), Index{0});
  nodes_.reserve(2 * boxes_.size() / kLeafSize + 2);
  if (!boxes_.empty()) build(0, static_cast<int>(boxes_.size()));
}

int BoxTree::build(int first, int count) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Box box, centres;
  for (int i = first; i < first + count; ++i) {
    const Box& b = boxes_[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])];
    box.add(b.lo);
    box.add(b.hi);
    centres.add(0.5 * (b.lo + b.hi));
  }
  nodes_[static_cast<std::size_t>(id)].box = box;
  if (count <= kLeafSize) {
    nodes_[static_cast<std::size_t>(id)].first = first;
    nodes_[static_cast<std::size_t>(id)].count = count;
    return id;
  }
  int axis = 0;
  (centres.hi - centres.lo).maxCoeff(&axis);
  const int half = count / 2;
  const auto begin = order_.begin() + first;
  std::nth_element(begin, begin + half, begin + count, [&](Index a, Index b) {
    const Box& ba = boxes_[static_cast<std::size_t>(a)];
    const Box& bb = boxes_[static_cast<std::size_t>(b)];
    return ba.lo[axis] + ba.hi[axis] < bb.lo[axis] + bb.hi[axis];
  });
  const int left = build(first, half);
  const int right = build(first + half, count - half);
  nodes_[static_cast<std::size_t>(id)].left = left;
  nodes_[static_cast<std::size_t>(id)].right = right;
  return id;
}

void BoxTree::query(const Vec3& p, double margin, std::vector<Index>& hits) const {
  hits.clear();
  if (nodes_.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[static_cast<std::size_t>(stack[--top])];
    if (!n.box.contains(p, margin)) continue;
    if (n.count > 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const Index b = order_[static_cast<std::size_t>(i)];
        if (boxes_[static_cast<std::size_t>(b)].contains(p, margin)) hits.push_back(b);
      }
      continue;
    }
    stack[top++] = n.left;
    stack[top++] = n.right;
  }
}

}  // namespace sf::forming

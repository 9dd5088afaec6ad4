#include "meshes/aabb_tree.hpp"

#include <algorithm>
#include <numeric>

namespace kerf {

AabbTree::AabbTree(const std::vector<Eigen::AlignedBox3d>& boxes, int leaf_size) {
  if (boxes.empty()) return;
  m_primitives.resize(boxes.size());
  std::iota(m_primitives.begin(), m_primitives.end(), 0);
  m_nodes.reserve(2 * boxes.size() / static_cast<std::size_t>(std::max(1, leaf_size)) + 2);
  build(boxes, 0, static_cast<int>(boxes.size()), std::max(1, leaf_size));
}

std::int32_t AabbTree::build(const std::vector<Eigen::AlignedBox3d>& boxes, int begin, int end, int leaf_size) {
  const auto index = static_cast<std::int32_t>(m_nodes.size());
  m_nodes.emplace_back();
  Eigen::AlignedBox3d box;
  for (int i = begin; i < end; ++i) box.extend(boxes[static_cast<std::size_t>(m_primitives[static_cast<std::size_t>(i)])]);
  m_nodes[static_cast<std::size_t>(index)].box = box;
  if (end - begin <= leaf_size) {
    m_nodes[static_cast<std::size_t>(index)].first = begin;
    m_nodes[static_cast<std::size_t>(index)].count = end - begin;
    return index;
  }
  // Median split along the longest axis of the box of centres: depth <= log2(n) + 1, far
  // below max_depth for any mesh that fits in memory.
  Eigen::AlignedBox3d centres;
  for (int i = begin; i < end; ++i) centres.extend(boxes[static_cast<std::size_t>(m_primitives[static_cast<std::size_t>(i)])].center());
  int axis = 0;
  centres.sizes().maxCoeff(&axis);
  const int mid = begin + (end - begin) / 2;
  std::nth_element(m_primitives.begin() + begin, m_primitives.begin() + mid, m_primitives.begin() + end,
                   [&](std::int32_t a, std::int32_t b) {
                     return boxes[static_cast<std::size_t>(a)].center()[axis] < boxes[static_cast<std::size_t>(b)].center()[axis];
                   });
  const std::int32_t left = build(boxes, begin, mid, leaf_size);
  const std::int32_t right = build(boxes, mid, end, leaf_size);
  m_nodes[static_cast<std::size_t>(index)].left = left;
  m_nodes[static_cast<std::size_t>(index)].right = right;
  return index;
}

} // namespace kerf

#pragma once
// AabbTree: a bounding-volume hierarchy over axis-aligned boxes (one per triangle or
// tetrahedron), built once, queried without allocation — the spatial index behind the surface
// queries and the contact-length computation of the realtime side.

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <vector>

namespace kerf {

class AabbTree {
public:
  AabbTree() = default;

  /// Build over `boxes` (one per primitive; primitive ids are the indices into `boxes`).
  /// Median split on the longest axis; leaves hold up to `leaf_size` primitives.
  explicit AabbTree(const std::vector<Eigen::AlignedBox3d>& boxes, int leaf_size = 4);

  [[nodiscard]] bool empty() const { return m_nodes.empty(); }
  [[nodiscard]] const Eigen::AlignedBox3d& bounds() const { return m_nodes.front().box; }

  /// Calls `visit(primitive)` for every primitive whose box intersects `query`.
  /// Allocates nothing: traversal uses a fixed stack (depth is bounded by the median split).
  template <class Visit> void for_each_overlapping(const Eigen::AlignedBox3d& query, Visit&& visit) const;

  /// Best-first search: `box_lower_bound(box)` returns a lower bound of the cost of any primitive
  /// inside `box`; `visit(primitive)` evaluates one and returns its cost. Subtrees whose bound is
  /// not below the best cost so far are skipped. Returns the best cost (or `best` if none better).
  template <class Bound, class Visit>
  double for_each_nearest(double best, Bound&& box_lower_bound, Visit&& visit) const;

private:
  struct Node {
    Eigen::AlignedBox3d box;
    std::int32_t left = -1;  ///< child index, or -1 for a leaf
    std::int32_t right = -1;
    std::int32_t first = 0;  ///< leaf: range in m_primitives
    std::int32_t count = 0;
  };
  static constexpr int max_depth = 64;

  std::int32_t build(const std::vector<Eigen::AlignedBox3d>& boxes, int begin, int end, int leaf_size);

  std::vector<Node> m_nodes;
  std::vector<std::int32_t> m_primitives;
};

template <class Visit>
void AabbTree::for_each_overlapping(const Eigen::AlignedBox3d& query, Visit&& visit) const {
  if (m_nodes.empty()) return;
  std::array<std::int32_t, max_depth> stack{};
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = m_nodes[static_cast<std::size_t>(stack[--top])];
    if (!node.box.intersects(query)) continue;
    if (node.left < 0) {
      for (int i = 0; i < node.count; ++i) visit(m_primitives[static_cast<std::size_t>(node.first + i)]);
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
}

template <class Bound, class Visit>
double AabbTree::for_each_nearest(double best, Bound&& box_lower_bound, Visit&& visit) const {
  if (m_nodes.empty()) return best;
  std::array<std::int32_t, max_depth> stack{};
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = m_nodes[static_cast<std::size_t>(stack[--top])];
    if (box_lower_bound(node.box) >= best) continue;
    if (node.left < 0) {
      for (int i = 0; i < node.count; ++i) {
        const double cost = visit(m_primitives[static_cast<std::size_t>(node.first + i)]);
        if (cost < best) best = cost;
      }
    } else {
      // Visit the nearer child first (pushed last) so pruning bites early.
      const double dl = box_lower_bound(m_nodes[static_cast<std::size_t>(node.left)].box);
      const double dr = box_lower_bound(m_nodes[static_cast<std::size_t>(node.right)].box);
      if (dl < dr) {
        stack[top++] = node.right;
        stack[top++] = node.left;
      } else {
        stack[top++] = node.left;
        stack[top++] = node.right;
      }
    }
  }
  return best;
}

} // namespace kerf

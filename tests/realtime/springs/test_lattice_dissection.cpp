// The lattice's geometric nested dissection (realtime/springs/lattice_dissection.hpp): a
// permutation whose separators come after what they separate, whose factor fill (the elimination
// game on the cells' coupling graph, counted here independently of CHOLMOD) is below the natural
// order's, and which CHOLMOD keeps against AMD on a full block.

#include "realtime/springs/cell_stiffness.hpp"
#include "realtime/springs/lattice_dissection.hpp"
#include "realtime/springs/network_system.hpp"
#include "tests/realtime/springs/network_fixtures.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace kerf {
namespace {

/// Off-diagonal entries of the Cholesky factor of a matrix whose graph couples every two lattice
/// points sharing a cell (|Δ| <= 1 on every axis), eliminated in order `rank` (the elimination
/// game: eliminating a point joins its later neighbours into a clique; Rose, Tarjan & Lueker,
/// SIAM J. Comput. 5(2), 1976).
long factor_fill(const Eigen::Vector3i& np, const std::vector<int>& rank) {
  const int count = np.prod();
  std::vector<int> point_of(static_cast<std::size_t>(count));
  for (int p = 0; p < count; ++p) point_of[static_cast<std::size_t>(rank[static_cast<std::size_t>(p)])] = p;
  std::vector<std::set<int>> later(static_cast<std::size_t>(count)); // by rank
  for (int p = 0; p < count; ++p) {
    const Eigen::Vector3i g(p % np.x(), (p / np.x()) % np.y(), p / (np.x() * np.y()));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i q = g + Eigen::Vector3i(dx, dy, dz);
          if ((q.array() < 0).any() || (q.array() >= np.array()).any() || q == g) continue;
          const int r = rank[static_cast<std::size_t>(q.x() + np.x() * (q.y() + np.y() * q.z()))];
          if (r > rank[static_cast<std::size_t>(p)]) later[static_cast<std::size_t>(rank[static_cast<std::size_t>(p)])].insert(r);
        }
  }
  long fill = 0;
  for (int j = 0; j < count; ++j) {
    auto& s = later[static_cast<std::size_t>(j)];
    fill += static_cast<long>(s.size());
    if (s.empty()) continue;
    const int parent = *s.begin();
    for (const int r : s)
      if (r != parent) later[static_cast<std::size_t>(parent)].insert(r);
  }
  return fill;
}

TEST(LatticeDissection, IsAPermutationWithTheMiddlePlaneLast) {
  for (const Eigen::Vector3i& np : {Eigen::Vector3i(9, 9, 8), Eigen::Vector3i(5, 3, 4), Eigen::Vector3i(1, 1, 1),
                                   Eigen::Vector3i(13, 5, 5)}) {
    const std::vector<int> rank = lattice_nested_dissection(np);
    std::vector<int> sorted = rank;
    std::sort(sorted.begin(), sorted.end());
    for (int k = 0; k < np.prod(); ++k) ASSERT_EQ(sorted[static_cast<std::size_t>(k)], k);
    // The top separator: the middle plane of the longest axis (the first of equal ones), ranked last.
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (np[a] > np[axis]) axis = a;
    if (np[axis] < 3) continue;
    const int m = (np[axis] - 1) / 2;
    const int plane = np.prod() / np[axis];
    for (int p = 0; p < np.prod(); ++p) {
      const Eigen::Vector3i g(p % np.x(), (p / np.x()) % np.y(), p / (np.x() * np.y()));
      EXPECT_EQ(g[axis] == m, rank[static_cast<std::size_t>(p)] >= np.prod() - plane) << "point " << p;
    }
  }
}

TEST(LatticeDissection, FillsLessThanTheNaturalOrder) {
  // The 8³ block with its base fixed: 9 x 9 x 8 free points. Natural order: a band of one
  // z-layer plus a row plus one (~9·9 + 9 + 1 = 91 later neighbours per point); nested
  // dissection: separators of at most 9 x 9 points, for George's O(n^(4/3)) fill in 3-D.
  const Eigen::Vector3i np(9, 9, 8);
  std::vector<int> natural(static_cast<std::size_t>(np.prod()));
  for (int p = 0; p < np.prod(); ++p) natural[static_cast<std::size_t>(p)] = p;
  const long dissected = factor_fill(np, lattice_nested_dissection(np));
  const long banded = factor_fill(np, natural);
  // Counted: 31 625 and 51 687 coupled point pairs (x 9, plus the 3 x 3 diagonal blocks: 2.9·10⁵
  // and 4.7·10⁵ entries of L).
  EXPECT_LT(dissected, 0.7 * banded);
  EXPECT_GT(dissected, 0);
}

TEST(LatticeDissection, CholmodKeepsItAgainstAmdOnAFullBlock) {
  // NetworkSystem gives CHOLMOD both orderings and keeps the one with the smaller factor: on the
  // full 8³ clay block with a fixed base (the benchmark's), nested dissection (CHOLMOD's own
  // count: 2.94·10⁵ entries in L against AMD's 3.23·10⁵).
  const double h = 2.5e-3;
  SpringNetwork net = test::full_block(8, h, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0);
  for (int n = 0; n < net.node_count; ++n)
    if (test::grid_of(net, n).z() == 0) net.constraint[static_cast<std::size_t>(n)] = fix_all;
  NetworkSystem system(net);
  EXPECT_EQ(system.fill_ordering(), NetworkSystem::FillOrdering::lattice_nested_dissection);
  EXPECT_EQ(system.dof_count(), 3 * 9 * 9 * 8);
}

} // namespace
} // namespace kerf

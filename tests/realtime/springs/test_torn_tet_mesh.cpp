// The tear carried into the fine mesh (paper 000 §2.2, Fig. 5): a network divided by hand along
// the grid plane x = 25 mm of a 60 x 20 x 20 mm bar whose tetrahedra do not follow that plane
// (7.5 x 10 x 10 mm box cells against 5 mm network cells), so tetrahedra cross the exposed faces
// and must be divided. Expected: two components whose volumes add up to the original (an exact
// tiling) and equal the two parts (closed form: 25 x 20 x 20 and 35 x 20 x 20 mm^3), no inverted
// tetrahedron.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/springs/torn_tet_mesh.hpp"
#include "realtime/springs/vertex_tearing.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>

namespace kerf {
namespace {

TEST(TornTetMesh, DividedBarKeepsItsVolume) {
  const TetMesh mesh = box_tet_mesh({0.0, -0.01, 0.0}, {0.06, 0.01, 0.02}, 8, 2, 2);
  NetworkBlock block;
  block.origin = {0.0, -0.01, 0.0};
  block.cell_size = 0.005;
  block.cells = {12, 4, 4};
  SpringNetwork net = build_spring_network(block, std::vector<bool>(12 * 4 * 4, true), CellStiffness{1, 1, 1, 0}, 1000.0, 0.0);
  // Split every vertex on x = 25 mm: the cells at x >= 25 mm take copies.
  std::map<int, int> copy_of;
  for (int c = 0; c < net.cell_count(); ++c) {
    if (net.cell_index[static_cast<std::size_t>(c)].x() < 5) continue;
    for (int& id : net.cell_nodes[static_cast<std::size_t>(c)])
      if (std::abs(net.rest(0, id) - 0.025) < 1e-12) {
        auto [it, inserted] = copy_of.emplace(id, net.node_count);
        if (inserted) net.rest.col(net.node_count++) = net.rest.col(id);
        id = it->second;
      }
  }
  std::vector<int> parent(static_cast<std::size_t>(net.node_capacity())), label(static_cast<std::size_t>(net.cell_count()));
  ASSERT_EQ(network_pieces(net, parent, label), 2);

  const TornTetMesh torn = split_tet_mesh(mesh, net);
  EXPECT_GT(torn.mesh.tets.rows(), mesh.tets.rows()); // tetrahedra were divided
  // Components by shared nodes, their volumes, and every tetrahedron's orientation.
  std::vector<int> root(static_cast<std::size_t>(torn.mesh.nodes.rows()));
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&root](int a) {
    while (root[static_cast<std::size_t>(a)] != a) a = root[static_cast<std::size_t>(a)];
    return a;
  };
  for (int t = 0; t < torn.mesh.tets.rows(); ++t)
    for (int k = 1; k < 4; ++k) {
      const int a = find(torn.mesh.tets(t, k)), b = find(torn.mesh.tets(t, 0));
      if (a != b) root[static_cast<std::size_t>(a)] = b;
    }
  std::map<int, double> volume;
  for (int t = 0; t < torn.mesh.tets.rows(); ++t) {
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = torn.mesh.nodes.row(torn.mesh.tets(t, k)).transpose();
    const double v = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0;
    EXPECT_GT(v, 0.0) << "tetrahedron " << t;
    volume[find(torn.mesh.tets(t, 0))] += v;
  }
  ASSERT_EQ(volume.size(), 2u);
  // The bar's volume in closed form.
  const double original = 0.06 * 0.02 * 0.02;
  double sum = 0.0;
  std::vector<double> parts;
  for (const auto& [r, v] : volume) parts.push_back(v), sum += v;
  std::sort(parts.begin(), parts.end());
  EXPECT_NEAR(parts[0], 0.025 * 0.02 * 0.02, 1e-9 * original);
  EXPECT_NEAR(parts[1], 0.035 * 0.02 * 0.02, 1e-9 * original);
  EXPECT_NEAR(sum, original, 1e-9 * original);
}

} // namespace
} // namespace kerf

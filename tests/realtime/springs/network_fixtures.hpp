#pragma once
// Small networks for the spring tests: a full block of cells with chosen constraints.

#include "realtime/springs/spring_network.hpp"

#include <vector>

namespace kerf::test {

/// A full n x n x n block of cubes of edge h at the origin (every cell kept).
inline SpringNetwork full_block(int n, double h, const CellStiffness& stiffness, double density = 1000.0,
                                double damping_time = 0.0) {
  NetworkBlock block;
  block.cell_size = h;
  block.cells = Eigen::Vector3i::Constant(n);
  return build_spring_network(block, std::vector<bool>(static_cast<std::size_t>(n * n * n), true), stiffness, density,
                              damping_time);
}

/// Grid coordinates of node p (rest position / h).
inline Eigen::Vector3i grid_of(const SpringNetwork& net, int p) {
  return ((net.rest.col(p) - net.block.origin) / net.block.cell_size).array().round().cast<int>();
}

} // namespace kerf::test

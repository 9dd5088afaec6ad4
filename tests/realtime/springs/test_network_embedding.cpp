// Embedding (paper 000 §2.1): both the trilinear and the Coons-patch interpolation reproduce
// any affine motion of the network exactly (each interpolates the linear functions exactly:
// trilinear shape functions sum to one and reproduce coordinates, Hermite edge curves with
// central-difference tangents reproduce linear data on a uniform grid).

#include "realtime/springs/network_embedding.hpp"
#include "tests/realtime/springs/network_fixtures.hpp"

#include <gtest/gtest.h>

#include <random>

namespace kerf {
namespace {

TEST(NetworkEmbedding, ReproducesAffineMotionExactly) {
  const double h = 2e-3;
  const SpringNetwork net = test::full_block(3, h, CellStiffness{1.0, 1.0, 1.0, 0.0});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::MatrixXd points(500, 3);
  for (int p = 0; p < points.rows(); ++p)
    for (int i = 0; i < 3; ++i) points(p, i) = 3 * h * u(rng);
  points.row(0) << 0.0, 0.0, 0.0;             // a corner of the block
  points.row(1) << 3 * h, 3 * h, 3 * h;       // the opposite corner
  points.row(2) << h, 1.5 * h, 2 * h;         // on cell faces
  Eigen::Matrix3d A;
  A << 1.2, 0.1, -0.3, 0.05, 0.9, 0.2, -0.1, 0.3, 1.1;
  const Eigen::Vector3d b(1e-3, -2e-3, 5e-4);
  Eigen::Matrix3Xd x = net.rest;
  for (int n = 0; n < net.node_count; ++n) x.col(n) = A * net.rest.col(n) + b;
  for (const EmbeddingScheme scheme : {EmbeddingScheme::trilinear, EmbeddingScheme::coons}) {
    const NetworkEmbedding embedding(net, points, scheme);
    EXPECT_EQ(embedding.embedded_count(), points.rows());
    Eigen::MatrixXd out(points.rows(), 3);
    embedding.apply(net, x, out);
    for (int p = 0; p < points.rows(); ++p)
      EXPECT_LT((out.row(p).transpose() - (A * points.row(p).transpose() + b)).norm(), 1e-15) << "point " << p;
  }
}

TEST(NetworkEmbedding, CoonsDiffersFromTrilinearUnderBending) {
  // Under a non-affine (quadratic) motion the Coons patch uses the neighbours' nodes and so
  // differs from trilinear inside a cell, while both interpolate the nodes themselves.
  const double h = 1.0;
  const SpringNetwork net = test::full_block(3, h, CellStiffness{1.0, 1.0, 1.0, 0.0});
  Eigen::Matrix3Xd x = net.rest;
  for (int n = 0; n < net.node_count; ++n) x(2, n) += 0.1 * net.rest(0, n) * net.rest(0, n);
  Eigen::MatrixXd points(2, 3);
  points.row(0) << 1.5, 1.5, 1.5;
  points.row(1) << 1.0, 1.0, 1.0; // a node
  Eigen::MatrixXd tri(2, 3), coons(2, 3);
  NetworkEmbedding(net, points, EmbeddingScheme::trilinear).apply(net, x, tri);
  NetworkEmbedding(net, points, EmbeddingScheme::coons).apply(net, x, coons);
  // Exact field z + 0.1 x²: at x = 1.5 it is 1.725; trilinear gives the chord 1.75, the
  // Hermite edge with central-difference tangents the exact parabola 1.725.
  EXPECT_NEAR(tri(0, 2), 1.75, 1e-12);
  EXPECT_NEAR(coons(0, 2), 1.725, 1e-12);
  EXPECT_NEAR(tri(1, 2), 1.1, 1e-12);
  EXPECT_NEAR(coons(1, 2), 1.1, 1e-12);
}

} // namespace
} // namespace kerf

// Patch tests of the finite-strain reference.
// 1. An affine deformation imposed on the whole boundary of a distorted mesh is reproduced to
//    round-off inside (any conforming element that contains the linear polynomials passes;
//    Zienkiewicz & Taylor, The Finite Element Method, vol. 1, §9.3).
// 2. MacNeal & Harder's 3-D patch test (Finite Elem. Anal. Des. 1 (1985) 3–20, §2.1): on their
//    seven-hexahedron patch (here split into tetrahedra), u = 1e-3 (2x + y + z)/2,
//    v = 1e-3 (x + 2y + z)/2, w = 1e-3 (x + y + 2z)/2 with E = 1e6, ν = 0.25 gives the exact
//    stresses σ_x = σ_y = σ_z = 2000, τ_xy = τ_yz = τ_zx = 400 in linear elasticity; the
//    finite-strain solver reaches them in the small-strain limit (displacements scaled by 1e-4).

#include "reference/finite_strain_solver.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <random>

namespace kerf::reference {
namespace {

double signed_volume(const TetMesh& mesh, Eigen::Index t) {
  const Eigen::Vector3d a = mesh.nodes.row(mesh.tets(t, 0));
  return (Eigen::Vector3d(mesh.nodes.row(mesh.tets(t, 1))) - a)
      .cross(Eigen::Vector3d(mesh.nodes.row(mesh.tets(t, 2))) - a)
      .dot(Eigen::Vector3d(mesh.nodes.row(mesh.tets(t, 3))) - a);
}

class AffinePatch : public ::testing::TestWithParam<int> {};

TEST_P(AffinePatch, AffineDeformationIsReproducedInside) {
  // A 3x3x3 box whose interior nodes are moved randomly by up to 10% of a cell.
  TetMesh mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.03, 0.02, 0.02), 3, 3, 3);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  const Eigen::Vector3d cell(0.01, 0.02 / 3.0, 0.02 / 3.0);
  const TetMesh undistorted = mesh;
  std::vector<int> interior;
  for (Eigen::Index v = 0; v < mesh.nodes.rows(); ++v) {
    const Eigen::Vector3d X = mesh.nodes.row(v);
    if (X.minCoeff() > 1e-9 && X[0] < 0.03 - 1e-9 && X[1] < 0.02 - 1e-9 && X[2] < 0.02 - 1e-9) {
      for (int k = 0; k < 3; ++k) mesh.nodes(v, k) += jitter(rng) * cell[k];
      interior.push_back(static_cast<int>(v));
    }
  }
  ASSERT_EQ(interior.size(), 8u);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) // the distortion inverts no element
    ASSERT_GT(signed_volume(mesh, t) * signed_volume(undistorted, t), 0.0) << "tet " << t;
  // 15% stretch, shear and a rotation: a finite affine deformation F = I + G.
  Eigen::Matrix3d G;
  G << 0.15, 0.05, -0.02, 0.03, -0.04, 0.06, -0.05, 0.02, 0.1;
  const Eigen::Vector3d b(1e-3, -2e-3, 5e-4);
  SolverSettings settings;
  settings.degree = GetParam();
  FiniteStrainSolver solver(test::affine_problem(mesh, G, b, LawKind::neo_hookean, 1e6, 0.3), settings);
  const EquilibriumReport r = solver.solve({1.0, Eigen::Vector3d::Zero()});
  ASSERT_TRUE(r.converged) << r.failure;
  for (int v : interior) {
    const Eigen::Vector3d X = mesh.nodes.row(v);
    EXPECT_LT((solver.displacement_at(X) - (G * X + b)).norm(), 1e-12) << "node " << v;
  }
  // Homogeneous stress: every quadrature point has the same Cauchy stress.
  const auto stresses = solver.quadrature_cauchy_stresses();
  for (const auto& s : stresses) EXPECT_LT((s - stresses.front()).norm(), 1e-7 * stresses.front().norm());
}

INSTANTIATE_TEST_SUITE_P(Degrees, AffinePatch, ::testing::Values(1, 2));

TEST(MacNealHarder, StressesAreExactInTheSmallStrainLimit) {
  Eigen::Matrix3d G; // u = G X: rows are the gradients of u, v, w
  G << 1.0, 0.5, 0.5, 0.5, 1.0, 0.5, 0.5, 0.5, 1.0;
  const double scale = 1e-4; // small-strain limit: strains of 1e-7
  G *= 1e-3 * scale;
  for (LawKind law : {LawKind::neo_hookean, LawKind::st_venant_kirchhoff}) {
    SolverSettings settings;
    settings.degree = 1;
    FiniteStrainSolver solver(test::affine_problem(test::macneal_harder_patch(), G, Eigen::Vector3d::Zero(), law, 1e6, 0.25),
                              settings);
    const EquilibriumReport r = solver.solve({1.0, Eigen::Vector3d::Zero()});
    ASSERT_TRUE(r.converged) << r.failure;
    Eigen::Matrix3d exact; // MacNeal & Harder (1985): σ = 2000, τ = 400
    exact << 2000, 400, 400, 400, 2000, 400, 400, 400, 2000;
    const auto stresses = solver.quadrature_cauchy_stresses();
    ASSERT_EQ(stresses.size() % (7u * 24u), 0u); // 7 hexahedra x 24 tetrahedra x quadrature points
    for (const auto& s : stresses) EXPECT_LT((s / scale - exact).cwiseAbs().maxCoeff(), 1e-4 * 2000);
  }
}

} // namespace
} // namespace kerf::reference

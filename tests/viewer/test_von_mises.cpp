// von_mises_stress against closed forms of the compressible neo-Hookean law
// σ = (μ/J)(b − I) + (λ ln J / J) I on single tetrahedra under homogeneous deformations.

#include "viewer/von_mises.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>

using namespace kerf;

namespace {

/// A reference tetrahedron and its image under x = F X.
struct Deformed {
  Eigen::MatrixXd rest, deformed;
  Eigen::MatrixXi tets;
};

Deformed deform(const Eigen::Matrix3d& F) {
  Deformed d;
  d.rest.resize(4, 3);
  d.rest << 0, 0, 0, 1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3;
  d.deformed = (F * d.rest.transpose()).transpose();
  d.tets.resize(1, 4);
  d.tets << 0, 1, 2, 3;
  return d;
}

constexpr double E = 1e6, nu = 0.3;
const double mu = E / (2 * (1 + nu));

} // namespace

// Frame indifference: a rigid rotation leaves the body unstressed.
TEST(VonMises, RigidRotationIsUnstressed) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Deformed d = deform(R);
  EXPECT_NEAR(von_mises_stress(d.rest, d.deformed, d.tets, E, nu)(0), 0.0, 1e-6 * E);
}

// A pure dilatation F = α I has a purely hydrostatic stress: no deviator, σ_vM = 0.
TEST(VonMises, DilatationHasNoDeviator) {
  const Deformed d = deform(1.1 * Eigen::Matrix3d::Identity());
  EXPECT_NEAR(von_mises_stress(d.rest, d.deformed, d.tets, E, nu)(0), 0.0, 1e-9 * E);
}

// Isochoric uniaxial stretch F = diag(s, 1/√s, 1/√s): J = 1, σ = μ (b − I), b = diag(s², 1/s, 1/s),
// so σ_vM = |σ₁ − σ₂| = μ |s² − 1/s| (axisymmetric stress state).
TEST(VonMises, IsochoricStretchClosedForm) {
  for (double s : {0.8, 1.05, 1.3, 2.0}) {
    const Deformed d = deform(Eigen::Vector3d(s, 1 / std::sqrt(s), 1 / std::sqrt(s)).asDiagonal());
    EXPECT_NEAR(von_mises_stress(d.rest, d.deformed, d.tets, E, nu)(0), mu * std::abs(s * s - 1 / s), 1e-9 * E) << s;
  }
}

// Simple shear F = I + γ e_x ⊗ e_y: J = 1, σ = μ (b − I) with b − I = [[γ², γ, 0], [γ, 0, 0], 0],
// deviator s = σ − μγ²/3 I, σ_vM² = 3/2 s:s = μ² (γ⁴ + 3γ²).
TEST(VonMises, SimpleShearClosedForm) {
  const double g = 0.2;
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 1) = g;
  const Deformed d = deform(F);
  EXPECT_NEAR(von_mises_stress(d.rest, d.deformed, d.tets, E, nu)(0), mu * std::sqrt(std::pow(g, 4) + 3 * g * g), 1e-9 * E);
}

TEST(VonMises, InvertedTetrahedronGetsZeroAndBadConstantsThrow) {
  const Deformed d = deform(Eigen::Vector3d(-1, 1, 1).asDiagonal());
  EXPECT_EQ(von_mises_stress(d.rest, d.deformed, d.tets, E, nu)(0), 0.0);
  EXPECT_THROW(von_mises_stress(d.rest, d.deformed, d.tets, 0.0, nu), std::invalid_argument);
  EXPECT_THROW(von_mises_stress(d.rest, d.deformed, d.tets, E, 0.5), std::invalid_argument);
}

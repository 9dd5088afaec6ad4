// DCS and CFF (paper 002 §2.4, Eq. 1) as free functions, against the paper's formulas written
// out here independently.

#include "realtime/voxel/cutting_resistance.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace kerf;

TEST(DepthCuttingStiffness, IsPointZeroSixSixEPerMillimetreOfDepth) {
  // Paper 002 §2.4: coefficient 0.066 E per mm of depth; E = 20 N/mm -> 1.32 N per mm.
  const double e = 2.0e4; // [N/m] = 20 N/mm
  EXPECT_NEAR(depth_cutting_stiffness_force(e, 1e-3), 0.066 * 20.0, 1e-12);
  EXPECT_NEAR(depth_cutting_stiffness_force(e, 0.5e-3), 0.066 * 20.0 * 0.5, 1e-12);
  EXPECT_EQ(depth_cutting_stiffness_force(e, 0.0), 0.0);
  EXPECT_EQ(depth_cutting_stiffness_force(e, -1e-4), 0.0);
  EXPECT_EQ(depth_cutting_stiffness_force(e, std::nan("")), 0.0);
}

TEST(ClipFrictionForce, MatchesEquationOneAsPrinted) {
  // Eq. (1) exactly as printed in paper 002, evaluated the naive way (fine where Cl is not
  // orders of magnitude above Cw).
  const auto eq1 = [](double m, double e, double cw, double dz, double cl) {
    return m * e * cw * dz * (std::sqrt(cl * cl + cw * cw) - cl) / cl * std::cos(std::atan(cl / cw));
  };
  for (double cl : {1e-6, 2e-5, 1e-4, 5e-4, 1e-3})
    for (double dz : {1e-5, 2e-4, 5e-4})
      for (double cw : {1e-5, 2e-5, 1e-4}) {
        const double expected = eq1(0.8, 2e7, cw, dz, cl);
        EXPECT_NEAR(clip_friction_force(0.8, 2e7, cw, dz, cl), expected, 1e-9 * expected)
            << "Cl " << cl << " dz " << dz << " Cw " << cw;
      }
  // Cl = Cw: (sqrt 2 - 1) cos 45° = (sqrt 2 - 1)/sqrt 2.
  EXPECT_NEAR(clip_friction_force(1.0, 1.0, 1.0, 1.0, 1.0), (std::sqrt(2.0) - 1.0) / std::sqrt(2.0), 1e-15);
  // Long cuts: Fh -> M E Cw dz Cw^3 / (2 Cl^3) (series of Eq. 1), where the naive form cancels.
  const double cl = 1.0, cw = 1e-5;
  EXPECT_NEAR(clip_friction_force(1.0, 1.0, cw, 1.0, cl), cw * cw * cw * cw / (2.0 * cl * cl * cl), 1e-6 * 5e-21);
}

TEST(ClipFrictionForce, NoCutNoForce) {
  EXPECT_EQ(clip_friction_force(0.8, 2e7, 2e-5, 5e-4, 0.0), 0.0);
  EXPECT_EQ(clip_friction_force(0.8, 2e7, 2e-5, 0.0, 1e-4), 0.0);
  EXPECT_EQ(clip_friction_force(0.8, 2e7, 0.0, 5e-4, 1e-4), 0.0);
}

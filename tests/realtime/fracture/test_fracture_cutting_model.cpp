// FractureCuttingModel against paper 001's closed forms on a structured box (no gmsh): the
// deflection responses (Eqs. 7, 8 with §6's power laws), the cutting force J_c l (Eq. 10), the
// energy balance of cutting (Eqs. 3–5 with dU = 0: work = J_c x cut area), recoverable work in
// pure deformation (§3, Fig. 1a), the mode sequence of Fig. 5 and re-entry into a crack.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/fracture/fracture_cutting_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace kerf;

namespace {

// Rectangular prism of paper 001 §5.1: 40 mm long (x), 20 mm wide (y), 15 mm deep (z).
TetMesh potato_box() { return box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 8, 4, 3); }

FractureCuttingSetup razor(double toughness = 200.0) {
  FractureCuttingSetup s;
  s.blade.edge_direction = Eigen::Vector3d::UnitY();
  s.blade.cutting_direction = -Eigen::Vector3d::UnitZ();
  s.blade.edge_length = 0.030;
  s.fracture_toughness = {toughness};
  s.response.rupture_force_per_length = 400.0; // f_r [N/m]
  s.response.rupture_deflection = 0.002;       // δ_r
  s.response.deformation_1_exponent = 2;
  s.response.crack_deflection = 0.0005;        // δ_c
  s.response.deformation_2_exponent = 1;
  s.response.lateral_stiffness = 2000.0;
  s.response.presliding_stiffness = 5000.0;
  s.response.presliding_stick_ratio = 0.5;
  s.crack_capture_width = 1e-4;
  return s;
}

struct Sample {
  Eigen::Vector3d position;
  ForceSample out;
};

/// Straight-line moves of the blade's edge midpoint in steps of `step` metres.
std::vector<Eigen::Vector3d> path(std::initializer_list<Eigen::Vector3d> waypoints, double step = 1e-6) {
  std::vector<Eigen::Vector3d> out;
  const Eigen::Vector3d* previous = nullptr;
  for (const Eigen::Vector3d& w : waypoints) {
    if (previous) {
      const int n = static_cast<int>(std::ceil((w - *previous).norm() / step));
      for (int k = 1; k <= n; ++k) out.push_back(*previous + (w - *previous) * (double(k) / n));
    } else {
      out.push_back(w);
    }
    previous = &w;
  }
  return out;
}

std::vector<Sample> drive(FractureCuttingModel& model, const std::vector<Eigen::Vector3d>& positions) {
  std::vector<Sample> samples;
  ToolState tool;
  ForceSample out;
  for (const Eigen::Vector3d& p : positions) {
    tool.position = p;
    model.step({&tool, 1}, 1e-3, {&out, 1});
    samples.push_back({p, out});
  }
  return samples;
}

std::vector<InteractionMode> mode_sequence(const std::vector<Sample>& samples) {
  std::vector<InteractionMode> seq;
  for (const Sample& s : samples)
    if (seq.empty() || seq.back() != s.out.mode) seq.push_back(s.out.mode);
  return seq;
}

const Eigen::Vector3d above(0.020, 0.0, 0.016);
const Eigen::Vector3d depth_10mm(0.020, 0.0, 0.005);

} // namespace

TEST(FractureCuttingModel, ApproachCutRetreatFollowsFigure5) {
  FractureCuttingModel model(potato_box(), razor());
  const auto samples = drive(model, path({above, depth_10mm, above}));
  using M = InteractionMode;
  EXPECT_EQ(mode_sequence(samples),
            (std::vector<M>{M::no_contact, M::deformation_1, M::rupture, M::cutting, M::deformation_2, M::no_contact}));
  EXPECT_EQ(model.non_finite_count(), 0);
}

TEST(FractureCuttingModel, DeformationState1IsLF1) {
  // Eq. 7 with §6's f1: f = l f_r (δ/δ_r)^2, l = 20 mm (the prism's width; the edge is longer).
  FractureCuttingModel model(potato_box(), razor());
  const auto samples = drive(model, path({above, depth_10mm}));
  int checked = 0;
  for (const Sample& s : samples) {
    if (s.out.mode != InteractionMode::deformation_1) continue;
    const double delta = 0.015 - s.position.z();
    EXPECT_NEAR(s.out.force.z(), 0.020 * 400.0 * std::pow(delta / 0.002, 2), 1e-8);
    ++checked;
  }
  EXPECT_GT(checked, 1900); // 2 mm at 1 µm steps
}

TEST(FractureCuttingModel, SteadyCuttingForceIsJcTimesWidth) {
  // Eq. 10: f = J_c l = 200 J/m^2 x 20 mm = 4 N; the crack front trails the edge by δ_c.
  FractureCuttingModel model(potato_box(), razor());
  const auto samples = drive(model, path({above, depth_10mm}));
  int cutting = 0;
  for (const Sample& s : samples) {
    if (s.out.mode != InteractionMode::cutting) continue;
    EXPECT_NEAR(s.out.force.z(), 4.0, 1e-8);
    EXPECT_NEAR(s.out.crack_extent, (0.015 - s.position.z()) - 0.0005, 1e-9);
    ++cutting;
  }
  EXPECT_GT(cutting, 7900);
}

TEST(FractureCuttingModel, RuptureAtDeltaRThenCrackAtXMinusDeltaC) {
  FractureCuttingModel model(potato_box(), razor());
  const auto samples = drive(model, path({above, depth_10mm}));
  int ruptures = 0;
  for (const Sample& s : samples) {
    if (s.out.mode != InteractionMode::rupture) continue;
    ++ruptures;
    const double x = 0.015 - s.position.z();
    EXPECT_GE(x, 0.002 - 1e-9);
    EXPECT_LT(x, 0.002 + 2e-6);
    EXPECT_NEAR(s.out.crack_extent, x - 0.0005, 1e-9);
  }
  EXPECT_EQ(ruptures, 1); // rupture is instantaneous (§4.2): one sample
}

TEST(FractureCuttingModel, CuttingWorkEqualsToughnessTimesCutArea) {
  // Energy balance Eq. 3 with dU = 0 in cutting: the tool's work = J_c a(ds) (Eq. 4).
  FractureCuttingModel model(potato_box(), razor());
  const auto samples = drive(model, path({above, depth_10mm}));
  double work = 0.0, c_first = -1.0, c_last = 0.0;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    if (samples[k].out.mode != InteractionMode::cutting) continue;
    const Eigen::Vector3d f_body = -0.5 * (samples[k].out.force + samples[k - 1].out.force);
    work += f_body.dot(samples[k].position - samples[k - 1].position);
    if (c_first < 0.0) c_first = samples[k - 1].out.crack_extent;
    c_last = samples[k].out.crack_extent;
  }
  const double area = 0.020 * (c_last - c_first);
  EXPECT_NEAR(work, 200.0 * area, 1e-9 * 200.0 * area + 1e-12);
}

TEST(FractureCuttingModel, PureDeformationWorkIsRecovered) {
  // §3, Fig. 1a: without fracture the work done on loading is returned on unloading.
  FractureCuttingModel model(potato_box(), razor());
  const auto samples = drive(model, path({above, {0.020, 0.0, 0.0135}, above}));
  double work = 0.0;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    ASSERT_NE(samples[k].out.mode, InteractionMode::rupture);
    const Eigen::Vector3d f_body = -0.5 * (samples[k].out.force + samples[k - 1].out.force);
    work += f_body.dot(samples[k].position - samples[k - 1].position);
  }
  EXPECT_NEAR(work, 0.0, 1e-12);
}

TEST(FractureCuttingModel, RetreatIsDeformationState2WithF2) {
  // Eq. 8: f = l J_c ((x - c)/δ_c)^1 while 0 <= x - c < δ_c.
  FractureCuttingModel model(potato_box(), razor());
  const auto samples = drive(model, path({above, depth_10mm, above}));
  const double c = 0.010 - 0.0005;
  int checked = 0;
  for (const Sample& s : samples) {
    if (s.out.mode != InteractionMode::deformation_2) continue;
    const double x = 0.015 - s.position.z();
    EXPECT_NEAR(s.out.force.z(), 0.020 * 200.0 * (x - c) / 0.0005, 1e-8);
    EXPECT_NEAR(s.out.crack_extent, c, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 400);
}

TEST(FractureCuttingModel, ReenteringTheCrackStartsInState2) {
  // Paper 001 Fig. 5: contact at a location already cut begins in deformation state 2, then
  // cuts on when the deflection reaches δ_c.
  FractureCuttingModel model(potato_box(), razor());
  drive(model, path({above, depth_10mm, above}));
  const auto again = drive(model, path({above, {0.020, 0.0, 0.003}}));
  using M = InteractionMode;
  EXPECT_EQ(mode_sequence(again), (std::vector<M>{M::no_contact, M::deformation_2, M::cutting}));
}

TEST(FractureCuttingModel, AFreshCutElsewhereStartsInState1) {
  FractureCuttingModel model(potato_box(), razor());
  drive(model, path({above, depth_10mm, above}));
  const Eigen::Vector3d elsewhere(0.010, 0.0, 0.016);
  const auto again = drive(model, path({elsewhere, {0.010, 0.0, 0.010}}));
  using M = InteractionMode;
  EXPECT_EQ(mode_sequence(again), (std::vector<M>{M::no_contact, M::deformation_1, M::rupture, M::cutting}));
}

TEST(FractureCuttingModel, LateralWallAndSlidingFriction) {
  // Cutting with the blade held 0.1 mm off its plane (along x, the normal of the blade's yz
  // plane): wall force -k y = 0.2 N back towards the plane, and
  // once sliding, pre-sliding friction saturates at mu |f_y| opposing the advance.
  FractureCuttingSetup setup = razor();
  setup.friction = true;
  setup.friction_coefficient = 0.5;
  setup.crack_capture_width = 1e-3;
  FractureCuttingModel model(potato_box(), setup);
  drive(model, path({above, {0.020, 0.0, 0.012}}));
  const auto samples = drive(model, path({{0.020, 0.0, 0.012}, {0.0201, 0.0, 0.012}, {0.0201, 0.0, 0.008}}));
  const Sample& last = samples.back();
  EXPECT_EQ(last.out.mode, InteractionMode::cutting);
  EXPECT_NEAR(last.out.force.x(), -2000.0 * 1e-4, 1e-12);
  EXPECT_NEAR(last.out.force.z(), 4.0 + 0.5 * 0.2, 1e-9); // J_c l + mu N, both resisting the advance
}

TEST(FractureCuttingModel, TwoLayersSumTheirToughness) {
  // §6: a body of two layers; the edge is horizontal, so at each depth it lies in one layer:
  // the cutting force is J_upper l above the interface and J_lower l below it.
  TetMesh mesh = box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 8, 4, 5); // interface z = 9 mm
  add_height_layers(mesh, 0.009);
  FractureCuttingSetup setup = razor();
  setup.regions = {"layer_upper", "layer_lower"};
  setup.fracture_toughness = {600.0, 200.0};
  FractureCuttingModel model(mesh, setup);
  const auto samples = drive(model, path({above, {0.020, 0.0, 0.002}}));
  bool saw_upper = false, saw_lower = false;
  for (const Sample& s : samples) {
    if (s.out.mode != InteractionMode::cutting) continue;
    if (s.position.z() > 0.0095) {
      EXPECT_NEAR(s.out.force.z(), 600.0 * 0.020, 1e-8);
      saw_upper = true;
    } else if (s.position.z() < 0.0085) {
      EXPECT_NEAR(s.out.force.z(), 200.0 * 0.020, 1e-8);
      saw_lower = true;
    }
  }
  EXPECT_TRUE(saw_upper && saw_lower);
}

TEST(FractureCuttingModel, NeverReturnsANonFiniteForce) {
  FractureCuttingModel model(potato_box(), razor());
  const double bad[] = {std::nan(""), INFINITY, -INFINITY, 1e300, -1e300};
  ToolState tool;
  ForceSample out;
  for (double b : bad)
    for (int axis = 0; axis < 3; ++axis) {
      tool.position = depth_10mm;
      tool.position[axis] = b;
      model.step({&tool, 1}, 1e-3, {&out, 1});
      EXPECT_TRUE(out.force.allFinite());
      tool.position = depth_10mm;
      model.step({&tool, 1}, 1e-3, {&out, 1});
      EXPECT_TRUE(out.force.allFinite());
    }
}

TEST(FractureCuttingModel, RejectsOutOfRangeParameters) {
  FractureCuttingSetup s = razor();
  s.response.deformation_1_exponent = 4;
  EXPECT_THROW(FractureCuttingModel(potato_box(), s), std::invalid_argument);
  s = razor();
  s.response.crack_deflection = 0.0;
  EXPECT_THROW(FractureCuttingModel(potato_box(), s), std::invalid_argument);
  s = razor();
  s.blade.cutting_direction = Eigen::Vector3d::UnitY();
  EXPECT_THROW(FractureCuttingModel(potato_box(), s), std::invalid_argument);
  s = razor();
  s.fracture_toughness = {-1.0};
  EXPECT_THROW(FractureCuttingModel(potato_box(), s), std::invalid_argument);
}

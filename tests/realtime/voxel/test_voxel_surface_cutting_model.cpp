// The voxel/polygon cutting model of paper 002: local memory, the critical-force advance logic,
// DCS and CFF against their closed forms, the two cutting methods of Fig. 5, modes, finiteness.

#include "realtime/voxel/cutting_resistance.hpp"
#include "tests/realtime/voxel/voxel_test_setup.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace kerf;
using namespace kerf::test;

namespace {
constexpr double mm = 1e-3;
constexpr double r = 0.02e-3; // stick tip radius (paper 002 §3.2)

/// Tip depth below the top face z = top for a tool centre at height z: d = top - (z - r).
double tip_depth(double top, double z) { return top - (z - r); }

/// Runs the constant-depth cut of paper 002 Fig. 5 on the 1 mm cube: down to 0.5 mm at
/// x = 0.1 mm, then along x to 0.9 mm, then out; calls `during_cut` on every cut-phase step.
void constant_depth_cut(VoxelSurfaceCuttingModel& model,
                        const std::function<void(const ToolState&, const ForceSample&)>& during_cut) {
  move(model, {0.1 * mm, 0, 1.1 * mm}, {0.1 * mm, 0, 0.52 * mm}, 1e-3);
  move(model, {0.1 * mm, 0, 0.52 * mm}, {0.9 * mm, 0, 0.52 * mm}, 1e-3, during_cut);
  move(model, {0.9 * mm, 0, 0.52 * mm}, {0.9 * mm, 0, 1.1 * mm}, 1e-3);
}

void proportional_depth_cut(VoxelSurfaceCuttingModel& model,
                            const std::function<void(const ToolState&, const ForceSample&)>& during_cut) {
  move(model, {0.1 * mm, 0, 1.1 * mm}, {0.1 * mm, 0, 1.02 * mm}, 1e-3);
  move(model, {0.1 * mm, 0, 1.02 * mm}, {0.9 * mm, 0, 0.52 * mm}, 1e-3, during_cut);
  move(model, {0.9 * mm, 0, 0.52 * mm}, {0.9 * mm, 0, 1.1 * mm}, 1e-3);
}

} // namespace

TEST(VoxelSurfaceCuttingModel, VoxelMemoryIsLocalSameForOneAndHundredMillimetreBodies) {
  // Paper 002 §4: the grid is built only around the contact, so its memory cannot depend on
  // the body. A 1 mm and a 100 mm cube (and a much finer 1 mm one) hold the same voxel memory,
  // before and after a cut.
  VoxelSurfaceCuttingModel small(cube_surface(1 * mm, 10), sponge_setup());
  VoxelSurfaceCuttingModel fine(cube_surface(1 * mm, 40), sponge_setup());
  VoxelSurfaceCuttingModel large(cube_surface(100 * mm, 10), sponge_setup());
  const std::size_t bytes = small.voxel_memory_bytes();
  EXPECT_EQ(fine.voxel_memory_bytes(), bytes);
  EXPECT_EQ(large.voxel_memory_bytes(), bytes);
  constant_depth_cut(small, {});
  // The large cube: the same cut 0.5 mm below its top face z = 100 mm.
  const Eigen::Vector3d up(0, 0, 99 * mm);
  move(large, Eigen::Vector3d(0.1 * mm, 0, 1.1 * mm) + up, Eigen::Vector3d(0.1 * mm, 0, 0.52 * mm) + up, 1e-3);
  move(large, Eigen::Vector3d(0.1 * mm, 0, 0.52 * mm) + up, Eigen::Vector3d(0.9 * mm, 0, 0.52 * mm) + up, 1e-3);
  EXPECT_GT(small.cut_advances(), 0);
  EXPECT_GT(large.cut_advances(), 0);
  EXPECT_EQ(small.voxel_memory_bytes(), bytes);
  EXPECT_EQ(large.voxel_memory_bytes(), bytes);
  // 10 x 20 x 20 columns' surface points and a fixed neighbourhood buffer: well under the
  // 500^3 = 125 MB of one byte per voxel for a whole-body grid (paper 002 §4).
  EXPECT_LT(bytes, 200000u);
}

TEST(VoxelSurfaceCuttingModel, SurfacePointAdvancesByTheAdvanceLengthExactlyWhenTheForceExceedsTheCriticalValue) {
  VoxelCuttingSetup s = sponge_setup();
  s.damping = 0.0; // the critical comparison uses the elastic force k_e δ_d
  VoxelSurfaceCuttingModel model(cube_surface(1 * mm, 10), s);
  // A slow vertical plunge at x = 0.1 mm: 0.1 µm per step.
  const Eigen::Vector3d from(0.1 * mm, 0, 1.05 * mm), to(0.1 * mm, 0, 0.8 * mm);
  const int steps = 2500;
  ToolState tool;
  tool.velocity = (to - from) / (steps * 1e-3);
  ForceSample out;
  int advances = 0, checked = 0;
  for (int k = 1; k <= steps; ++k) {
    tool.position = from + (to - from) * (static_cast<double>(k) / steps);
    // Before the step: the surface point under the tip (if a grid exists), and the tip depth.
    double before = std::nan("");
    int i = 0, j = 0;
    const double d = tip_depth(1 * mm, tool.position.z());
    if (model.in_contact_episode() && model.grid().column_at(0.0, 0.0, i, j)) before = model.grid().surface_depth(i, j);
    model.step({&tool, 1}, 1e-3, {&out, 1});
    if (std::isnan(before) || !model.grid().column_at(0.0, 0.0, i, j)) continue;
    const double after = model.grid().surface_depth(i, j);
    // Expected from the model's definition alone: F = k_e (d - s) vs the 0.3 N critical force.
    const double force = s.contact_stiffness * (d - before);
    if (force > s.critical_force_depth) {
      EXPECT_NEAR(after - before, s.advance_length, 1e-15) << "step " << k;
      ++advances;
    } else {
      EXPECT_EQ(after, before) << "step " << k;
    }
    ++checked;
  }
  EXPECT_GT(checked, 2000);
  // 0.23 mm of travel below the surface, one advance each 0.02 mm once 15 µm deep: about 11.
  EXPECT_GE(advances, 10);
  EXPECT_LE(advances, 12);
  EXPECT_EQ(advances, model.depth_advances());
}

TEST(VoxelSurfaceCuttingModel, CuttingFrontAdvancesOneAdvanceLengthPerCriticalCrossing) {
  VoxelCuttingSetup s = sponge_setup();
  s.depth_cutting_stiffness = false;
  s.clip_friction = false;
  VoxelSurfaceCuttingModel model(cube_surface(1 * mm, 10), s);
  move(model, {0.1 * mm, 0, 1.1 * mm}, {0.1 * mm, 0, 0.82 * mm}, 1e-3);
  // Along x at constant depth, 1 µm per step: the front (one column = one advance length
  // ahead) must advance exactly every 20 µm of travel, each time the wall force k_e δ_c crosses
  // 0.1 N, i.e. δ_c crosses 5 µm.
  std::vector<double> advance_x;
  long last = model.cut_advances();
  double peak = 0.0;
  move(model, {0.1 * mm, 0, 0.82 * mm}, {0.6 * mm, 0, 0.82 * mm}, 1e-3, [&](const ToolState& t, const ForceSample& f) {
    if (model.cut_advances() != last) {
      EXPECT_GT(model.last_cutting_elastic_force(), s.critical_force_cutting);
      advance_x.push_back(t.position.x());
      last = model.cut_advances();
    } else {
      EXPECT_LE(model.last_cutting_elastic_force(), s.critical_force_cutting);
    }
    peak = std::max(peak, -f.force.x());
  });
  ASSERT_GT(advance_x.size(), 20u);
  for (std::size_t k = 2; k < advance_x.size(); ++k)
    EXPECT_NEAR(advance_x[k] - advance_x[k - 1], s.advance_length, 1.01e-6) << "advance " << k;
  // The force felt along x never exceeds the critical force plus the friction of the bottom.
  EXPECT_LE(peak, s.critical_force_cutting + 1e-12 + s.friction_coefficient * 0.3);
}

TEST(VoxelSurfaceCuttingModel, DepthCuttingStiffnessAddsPointZeroSixSixEDepthWhileCutting) {
  // Two models on the same constant-depth cut, DCS on and off (CFF off in both). The advance
  // logic compares elastic forces only, so both cut alike; while cutting, the force with DCS
  // exceeds the one without by 0.066 E d (paper 002 §2.4), E = k_e, d = tip depth (computed here
  // from the trajectory), against the tangential motion (regularised direction, as coded).
  VoxelCuttingSetup on = sponge_setup(), off = sponge_setup();
  on.clip_friction = off.clip_friction = false;
  off.depth_cutting_stiffness = false;
  VoxelSurfaceCuttingModel with(cube_surface(1 * mm, 10), on), without(cube_surface(1 * mm, 10), off);
  std::vector<ForceSample> a, b;
  std::vector<ToolState> states;
  constant_depth_cut(with, [&](const ToolState& t, const ForceSample& f) { a.push_back(f); states.push_back(t); });
  constant_depth_cut(without, [&](const ToolState&, const ForceSample& f) { b.push_back(f); });
  ASSERT_EQ(a.size(), b.size());
  int cutting = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].mode, b[k].mode) << k;
    if (a[k].mode != InteractionMode::cutting) continue;
    const double d = tip_depth(1 * mm, states[k].position.z());
    const double speed = states[k].velocity.norm();
    const double expected = 0.066 * on.contact_stiffness * d * speed / std::hypot(speed, on.regularisation_speed);
    EXPECT_NEAR((b[k].force - a[k].force).x(), expected, 1e-12) << k;
    EXPECT_NEAR((b[k].force - a[k].force).tail<2>().norm(), 0.0, 1e-12) << k;
    ++cutting;
  }
  EXPECT_GT(cutting, 700); // 0.8 mm at 1 µm per step, nearly all of it cutting
  EXPECT_NEAR(0.066 * on.contact_stiffness * 0.5 * mm, 0.66, 1e-12); // 0.066 x 20 N/mm x 0.5 mm
}

TEST(VoxelSurfaceCuttingModel, ClipFrictionMatchesEquationOneEvaluatedIndependently) {
  VoxelCuttingSetup on = sponge_setup(), off = sponge_setup();
  on.depth_cutting_stiffness = off.depth_cutting_stiffness = false;
  off.clip_friction = false;
  VoxelSurfaceCuttingModel with(cube_surface(1 * mm, 10), on), without(cube_surface(1 * mm, 10), off);
  std::vector<ForceSample> a, b;
  std::vector<ToolState> states;
  std::vector<double> cut_length;
  constant_depth_cut(with, [&](const ToolState& t, const ForceSample& f) {
    a.push_back(f);
    states.push_back(t);
    cut_length.push_back(with.cut_length());
  });
  constant_depth_cut(without, [&](const ToolState&, const ForceSample& f) { b.push_back(f); });
  ASSERT_EQ(a.size(), b.size());
  int cutting = 0;
  double largest = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k].mode != InteractionMode::cutting) continue;
    // Eq. (1) as printed: M = 0.8, E = 20 N/mm^2, Cw = r, dz = tip depth, Cl = cut length.
    const double cl = cut_length[k], cw = r, dz = tip_depth(1 * mm, states[k].position.z());
    if (cl == 0.0) { // no advance along the cut yet: Eq. (1) starts with the cut (Cl > 0)
      EXPECT_EQ((b[k].force - a[k].force).norm(), 0.0) << k;
      continue;
    }
    const double fh = 0.8 * 2e7 * cw * dz * (std::sqrt(cl * cl + cw * cw) - cl) / cl * std::cos(std::atan(cl / cw));
    const double speed = states[k].velocity.norm();
    EXPECT_NEAR((b[k].force - a[k].force).x(), fh * speed / std::hypot(speed, on.regularisation_speed), 1e-9 * fh + 1e-15) << k;
    largest = std::max(largest, fh);
    ++cutting;
  }
  EXPECT_GT(cutting, 700);
  // Cl measured from the first advance: at 0.8 mm of cut it is ~0.8 mm; at the start ~Cw.
  EXPECT_NEAR(cut_length.back(), 0.8 * mm, 0.03 * mm);
  EXPECT_GT(largest, 0.01); // the CFF is felt at the start of the cut (Cl ~ Cw) ...
}

TEST(VoxelSurfaceCuttingModel, ConstantDepthCutIsFlatProportionalDepthCutGrows) {
  // Paper 002 Figs. 5–7 with DCS and CFF (case d): the force along the cut follows the depth,
  // flat for the constant-depth cut, growing for the proportional one. Compared: mean force
  // against the cut (-f_x) over the first and the last fifth of the cut phase.
  const auto fifths = [](const std::vector<double>& fx) {
    const std::size_t n = fx.size() / 5;
    double first = 0.0, last = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      first += fx[k] / n;
      last += fx[fx.size() - n + k] / n;
    }
    return std::pair{first, last};
  };
  std::vector<double> constant_fx, proportional_fx;
  VoxelSurfaceCuttingModel constant(cube_surface(1 * mm, 10), sponge_setup());
  constant_depth_cut(constant, [&](const ToolState&, const ForceSample& f) { constant_fx.push_back(-f.force.x()); });
  VoxelSurfaceCuttingModel proportional(cube_surface(1 * mm, 10), sponge_setup());
  proportional_depth_cut(proportional, [&](const ToolState&, const ForceSample& f) { proportional_fx.push_back(-f.force.x()); });
  const auto [c_first, c_last] = fifths(constant_fx);
  const auto [p_first, p_last] = fifths(proportional_fx);
  // Constant depth 0.5 mm: DCS 0.066 x 20 N/mm x 0.5 mm = 0.66 N throughout; within 10 %.
  EXPECT_NEAR(c_first, c_last, 0.1 * c_last);
  EXPECT_GT(c_last, 0.66);
  // Proportional: the depth grows from 0 to 0.5 mm, the DCS with it (mean over the last fifth
  // at ~0.45 mm depth: 0.59 N of DCS, against ~0.05 mm in the first).
  EXPECT_GT(p_last - p_first, 0.4);
  EXPECT_GT(p_last, 1.5 * p_first);
}

TEST(VoxelSurfaceCuttingModel, AStickWiderThanAColumnClearsItsPath) {
  // A knife's stick (docs/models.md, voxel, "A knife"): r = Cw = 0.05 mm, 2.5 columns of 0.02 mm.
  // Drawn at constant depth after the plunge, the columns between its tip and its leading point
  // are cleared with the leading one, so the tip never meets uncut material beneath it: the
  // elastic depth force stays within one critical crossing (0.3 N, plus one advance length's
  // k_e h = 0.4 N when the column it enters was just lowered to a tip one step higher) — a
  // column left standing would press the tip with k_e x 0.48 mm = 9.6 N.
  VoxelCuttingSetup setup = sponge_setup();
  setup.tool_radius = 0.05e-3;
  VoxelSurfaceCuttingModel model(cube_surface(1 * mm, 10), setup);
  const double top_centre = 1.0 * mm + setup.tool_radius;
  move(model, {0.2 * mm, 0, top_centre + 0.05 * mm}, {0.2 * mm, 0, top_centre - 0.48 * mm}, 1e-3);
  double largest = 0.0;
  int steps = 0;
  move(model, {0.2 * mm, 0, top_centre - 0.48 * mm}, {0.7 * mm, 0, top_centre - 0.48 * mm}, 1e-3,
       [&](const ToolState&, const ForceSample& f) {
         ASSERT_TRUE(f.force.allFinite());
         largest = std::max(largest, model.last_depth_elastic_force());
         ++steps;
       });
  EXPECT_GE(steps, 500);
  EXPECT_GT(model.cut_advances(), 20); // the front did advance along the 0.5 mm draw
  EXPECT_LE(largest, setup.critical_force_depth + setup.contact_stiffness * setup.advance_length);
}

TEST(VoxelSurfaceCuttingModel, ModesFollowTheCut) {
  VoxelSurfaceCuttingModel model(cube_surface(1 * mm, 10), sponge_setup());
  std::vector<InteractionMode> modes;
  const auto record = [&](const ToolState&, const ForceSample& f) {
    if (modes.empty() || modes.back() != f.mode) modes.push_back(f.mode);
  };
  move(model, {0.1 * mm, 0, 1.1 * mm}, {0.1 * mm, 0, 0.9 * mm}, 1e-3, record); // touch, deform, cut down
  // Press 8 µm further (after the last advance the tip sits 4-5 µm above the new surface
  // point: it touches without reaching the 15 µm of the critical force), then hold still:
  // pressing without advancing after a cut is deformation 2.
  move(model, {0.1 * mm, 0, 0.9 * mm}, {0.1 * mm, 0, 0.892 * mm}, 1e-5, record);
  ToolState still;
  still.position = {0.1 * mm, 0, 0.892 * mm};
  ForceSample f;
  for (int k = 0; k < 50; ++k) {
    model.step({&still, 1}, 1e-3, {&f, 1});
    record(still, f);
  }
  move(model, {0.1 * mm, 0, 0.892 * mm}, {0.1 * mm, 0, 1.1 * mm}, 1e-3, record); // out
  const std::vector<InteractionMode> expected{InteractionMode::no_contact, InteractionMode::deformation_1,
                                              InteractionMode::cutting, InteractionMode::deformation_2,
                                              InteractionMode::no_contact};
  EXPECT_EQ(modes, expected);
  EXPECT_FALSE(model.in_contact_episode());
}

TEST(VoxelSurfaceCuttingModel, NeverReturnsNaNOrInf) {
  VoxelSurfaceCuttingModel model(cube_surface(1 * mm, 10), sponge_setup());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-0.2 * mm, 1.2 * mm), vel(-1.0, 1.0);
  ToolState tool;
  ForceSample out;
  long nan_inputs = 0;
  for (int k = 0; k < 20000; ++k) {
    // A random walk in and around the cube, with jumps, huge speeds and broken samples.
    if (k % 997 == 0) tool.position = {pos(rng), pos(rng) - 0.5 * mm, pos(rng)};
    else tool.position += Eigen::Vector3d(vel(rng), vel(rng), vel(rng)) * 2e-6;
    tool.velocity = Eigen::Vector3d(vel(rng), vel(rng), vel(rng)) * (k % 101 == 0 ? 1e6 : 1e-3);
    ToolState sent = tool;
    if (k % 1499 == 0) {
      sent.position.x() = std::nan("");
      ++nan_inputs;
    }
    if (k % 1777 == 0) sent.velocity.y() = std::numeric_limits<double>::infinity();
    model.step({&sent, 1}, 1e-3, {&out, 1});
    ASSERT_TRUE(out.force.allFinite()) << k;
    ASSERT_TRUE(std::isfinite(out.crack_extent)) << k;
  }
  EXPECT_EQ(model.non_finite_count(), nan_inputs);
}

TEST(VoxelSurfaceCuttingModel, ResetRestoresTheUncutBody) {
  VoxelSurfaceCuttingModel model(cube_surface(1 * mm, 10), sponge_setup());
  const Eigen::MatrixXd before = model.polygon_vertices();
  std::vector<ForceSample> first, second;
  constant_depth_cut(model, [&](const ToolState&, const ForceSample& f) { first.push_back(f); });
  model.reset();
  EXPECT_EQ(model.polygon_vertices(), before);
  EXPECT_EQ(model.cut_advances(), 0);
  constant_depth_cut(model, [&](const ToolState&, const ForceSample& f) { second.push_back(f); });
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t k = 0; k < first.size(); ++k) EXPECT_EQ(first[k].force, second[k].force) << k;
}

TEST(VoxelSurfaceCuttingModel, RejectsBadParameters) {
  const SurfaceMesh body = cube_surface(1 * mm, 4);
  const auto with = [&](auto change) {
    VoxelCuttingSetup s = sponge_setup();
    change(s);
    return s;
  };
  EXPECT_THROW(VoxelSurfaceCuttingModel(body, with([](auto& s) { s.tool_radius = 0.0; })), std::invalid_argument);
  EXPECT_THROW(VoxelSurfaceCuttingModel(body, with([](auto& s) { s.contact_stiffness = -1.0; })), std::invalid_argument);
  EXPECT_THROW(VoxelSurfaceCuttingModel(body, with([](auto& s) { s.advance_length = 0.0; })), std::invalid_argument);
  EXPECT_THROW(VoxelSurfaceCuttingModel(body, with([](auto& s) { s.critical_force_depth = 0.0; })), std::invalid_argument);
  EXPECT_THROW(VoxelSurfaceCuttingModel(body, with([](auto& s) { s.clip_modulus = 0.0; })), std::invalid_argument);
  EXPECT_THROW(VoxelSurfaceCuttingModel(body, with([](auto& s) { s.grid = {10, 0, 20}; })), std::invalid_argument);
  EXPECT_THROW(VoxelSurfaceCuttingModel(SurfaceMesh{}, sponge_setup()), std::invalid_argument);
}

// The realtime contract (../shared/DESIGN.md): `step` allocates nothing. This program replaces
// the global operator new/delete (all forms, nothrow included) and, outside sanitizer builds,
// glibc's malloc family with counting versions (the technique of
// tests/realtime/fracture/test_no_allocation.cpp), then steps the discrete-edge model through
// approach, cut through two layers, retreat, re-entry into its own cut, with friction, drag
// and a lateral wobble, and requires zero allocations during the steps; then while the geometric
// cut runs on its worker thread; then through paper 000 §4's cut-then-pull (edge+springs).

#include "meshes/box_tet_mesh.hpp"
#include "realtime/edge/background_cut.hpp"
#include "realtime/edge/discrete_edge_cutting_model.hpp"

#include "tests/realtime/counting_allocator.hpp"
#include "tests/realtime/edge/shape_forming_fixture.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <thread>
#include <new>
using kerf::test::allocations;
using kerf::test::set_counting;

using namespace kerf;

TEST(RealtimeContract, DiscreteEdgeModelStepAllocatesNothing) {
  TetMesh mesh = box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 8, 4, 5);
  add_height_layers(mesh, 0.009);
  DiscreteEdgeSetup s;
  s.blade.edge_length = 0.030;
  s.point_count = 64;
  s.materials = {{1e6, 500.0, 20.0}, {1e6, 200.0, 20.0}};
  s.friction_coefficient = 0.3;
  s.channel_capture_width = 1e-4;
  DiscreteEdgeCuttingModel model(CollisionVoxels(mesh, 5e-4, {"layer_upper", "layer_lower"}), s);

  // Sanity check that the counter works at all (direct calls: a new-expression may be elided).
  set_counting(true);
  ::operator delete(::operator new(16));
  set_counting(false);
  ASSERT_GE(allocations.load(), 1);
  allocations = 0;

  ToolState tool;
  ForceSample out;
  long modes_seen = 0;
  set_counting(true);
  for (int pass = 0; pass < 2; ++pass) {     // the second pass re-enters the cut
    for (int k = 0; k <= 30000; ++k) {        // approach, cut 14 mm, retreat, with a lateral wobble
      const double z = k <= 15000 ? 0.016 - 1e-6 * k : 0.001 + 1e-6 * (k - 15000);
      tool.position = {0.020, 5e-5 * std::sin(1e-3 * k), z};
      tool.velocity = {0.0, 5e-5 * std::cos(1e-3 * k), k <= 15000 ? -1e-3 : 1e-3};
      model.step({&tool, 1}, 1e-3, {&out, 1});
      modes_seen |= 1L << static_cast<int>(out.mode);
    }
  }
  set_counting(false);
  EXPECT_EQ(allocations.load(), 0);
  // no-contact, deformation-1, cutting, deformation-2 (the edge model has no rupture instant)
  EXPECT_EQ(modes_seen, 0b11011);
}

TEST(RealtimeContract, EdgeModelStepAllocatesNothingWhileTheGeometricCutRuns) {
  // The edge cuts down through a 40 x 20 x 15 mm block of 36864 tetrahedra at x = 20 mm and out
  // below its base; the pass is handed to the cut's worker thread when the edge leaves the body,
  // and the servo thread keeps stepping (counting its allocations: the counter is per thread) until
  // the worker has applied the cut. So that the overlap does not depend on scheduling, the worker's
  // after-cut hook keeps it busy until the servo thread has stepped 1000 times while it was busy. Then the body is in two halves of 20 x 20 x 15 mm each.
  const TetMesh mesh = box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 32, 16, 12);
  DiscreteEdgeSetup s;
  s.blade.edge_length = 0.030;
  s.point_count = 64;
  s.materials = {{1e6, 500.0, 20.0}};
  DiscreteEdgeCuttingModel model(CollisionVoxels(mesh, 5e-4), s);
  std::atomic<bool> release{false};
  auto hold = [&](const CuttableBody&, const GeometricCutReport&) {
    while (!release.load()) std::this_thread::yield();
  };
  model.attach_geometric_cut(std::make_unique<BackgroundCut>(mesh, s.blade, GeometricCutOptions{}, 4096, hold), 5e-4);

  allocations = 0;
  ToolState tool;
  ForceSample out;
  long steps_while_cutting = 0;
  set_counting(true);
  for (int k = 0; k <= 17000; ++k) { // z from 16 mm to -1 mm, 1 um per step
    tool.position = {0.020, 0.0, 0.016 - 1e-6 * k};
    tool.velocity = {0.0, 0.0, -1e-3};
    model.step({&tool, 1}, 1e-3, {&out, 1});
  }
  tool.velocity.setZero();
  for (long k = 0; model.geometric_cut()->cuts_done() == 0 && k < 100'000'000; ++k) {
    const bool busy = model.geometric_cut()->busy();
    model.step({&tool, 1}, 1e-3, {&out, 1});
    if (busy && ++steps_while_cutting == 1000) release = true;
  }
  set_counting(false);
  release = true;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_GE(steps_while_cutting, 1000);
  ASSERT_EQ(model.geometric_cut()->cuts_done(), 1);
  model.geometric_cut()->wait_until_idle();
  EXPECT_TRUE(model.geometric_cut()->error().empty()) << model.geometric_cut()->error();
  const CuttableBody& body = model.geometric_cut()->body();
  ASSERT_EQ(body.fragment_count(), 2);
  // The halves' volumes, in closed form: 0.020 x 0.020 x 0.015 m^3 each.
  for (double v : body.fragment_volumes()) EXPECT_NEAR(v, 0.020 * 0.020 * 0.015, 1e-12 * 0.020 * 0.020 * 0.015);
}

TEST(RealtimeContract, ShapeFormingStepAllocatesNothingThroughCutHandOverAndPull) {
  // clay_form's sequence on the servo thread: the blade cuts the block in two (the cut and the
  // spring network are built on the worker), the stylus waits until the stage is published, then
  // pulls; every step of the sequence is counted.
  const TetMesh mesh = box_tet_mesh({0.0, -0.020, 0.0}, {0.040, 0.020, 0.020}, 16, 16, 8);
  ShapeFormingModel model(mesh, test::clay_setup());
  std::array<ToolState, 2> tools;
  std::array<ForceSample, 2> forces;
  tools[1].position = {0.008, 0.0, 0.022};
  allocations = 0;
  set_counting(true);
  for (int k = 0; k <= 2200; ++k) {
    tools[0].position = {0.016, 0.0, 0.021 - 1e-5 * k};
    tools[0].velocity = {0.0, 0.0, -0.01};
    model.step(tools, 1e-3, forces);
  }
  tools[0].velocity.setZero();
  for (long k = 0; !model.active_stage() && k < 100'000'000; ++k) model.step(tools, 1e-3, forces);
  const bool staged = model.active_stage() != nullptr;
  for (int k = 1; k <= 200; ++k) {
    tools[1].position = {0.008, 0.0, 0.022 + 1e-5 * k};
    tools[1].velocity = {0.0, 0.0, 0.01};
    model.step(tools, 1e-3, forces);
  }
  set_counting(false);
  EXPECT_EQ(allocations.load(), 0);
  ASSERT_TRUE(staged) << model.edge().geometric_cut()->error();
  EXPECT_LT(forces[1].force.z(), 0.0); // the pull was rendered
}

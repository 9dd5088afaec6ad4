// The realtime contract (../shared/DESIGN.md): `step` allocates nothing. This program replaces
// the global operator new/delete (all forms, nothrow included) and, outside sanitizer builds,
// glibc's malloc family with counting versions (the technique of
// tests/realtime/fracture/test_no_allocation.cpp), then steps the discrete-edge model through
// approach, cut through two layers, retreat, re-entry into its own cut, with friction, drag
// and a lateral wobble, and requires zero allocations during the steps.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/edge/discrete_edge_cutting_model.hpp"

#include "tests/realtime/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
using kerf::test::allocations;
using kerf::test::counting;

using namespace kerf;

TEST(RealtimeContract, DiscreteEdgeModelStepAllocatesNothing) {
  TetMesh mesh = box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 8, 4, 5);
  add_height_layers(mesh, 0.009);
  DiscreteEdgeSetup s;
  s.edge_length = 0.030;
  s.point_count = 64;
  s.materials = {{1e6, 500.0, 20.0}, {1e6, 200.0, 20.0}};
  s.friction_coefficient = 0.3;
  s.channel_capture_width = 1e-4;
  DiscreteEdgeCuttingModel model(CollisionVoxels(mesh, 5e-4, {"layer_upper", "layer_lower"}), s);

  // Sanity check that the counter works at all (direct calls: a new-expression may be elided).
  counting = true;
  ::operator delete(::operator new(16));
  counting = false;
  ASSERT_GE(allocations.load(), 1);
  allocations = 0;

  ToolState tool;
  ForceSample out;
  long modes_seen = 0;
  counting = true;
  for (int pass = 0; pass < 2; ++pass) {     // the second pass re-enters the cut
    for (int k = 0; k <= 30000; ++k) {        // approach, cut 14 mm, retreat, with a lateral wobble
      const double z = k <= 15000 ? 0.016 - 1e-6 * k : 0.001 + 1e-6 * (k - 15000);
      tool.position = {0.020, 5e-5 * std::sin(1e-3 * k), z};
      tool.velocity = {0.0, 5e-5 * std::cos(1e-3 * k), k <= 15000 ? -1e-3 : 1e-3};
      model.step({&tool, 1}, 1e-3, {&out, 1});
      modes_seen |= 1L << static_cast<int>(out.mode);
    }
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  // no-contact, deformation-1, cutting, deformation-2 (the edge model has no rupture instant)
  EXPECT_EQ(modes_seen, 0b11011);
}

// The realtime contract (../shared/DESIGN.md): `step` allocates nothing. This program replaces
// the global operator new/delete and (outside sanitizer builds) glibc's malloc family with
// counting versions, then steps the fracture model through a full approach–cut–dwell–retreat–
// re-entry cycle with friction and two layers, and requires zero allocations during the steps.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/fracture/fracture_cutting_model.hpp"

#include "tests/realtime/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

using kerf::test::allocations;
using kerf::test::set_counting;

using namespace kerf;

TEST(RealtimeContract, FractureModelStepAllocatesNothing) {
  TetMesh mesh = box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 8, 4, 5);
  add_height_layers(mesh, 0.009);

  FractureCuttingSetup s;
  s.blade.edge_length = 0.030;
  s.regions = {"layer_upper", "layer_lower"};
  s.fracture_toughness = {600.0, 200.0};
  s.response = {400.0, 0.002, 2, 0.0005, 1, 2000.0, 5000.0, 0.5};
  s.friction = true;
  s.friction_coefficient = 0.4;
  s.crack_capture_width = 1e-3;
  FractureCuttingModel model(mesh, s);

  // Sanity check that the counter works at all (direct calls: a new-expression may be elided).
  set_counting(true);
  ::operator delete(::operator new(16));
  set_counting(false);
  ASSERT_GE(allocations.load(), 1); // operator new, and the malloc under it where counted
  allocations = 0;

  ToolState tool;
  ForceSample out;
  long modes_seen = 0;
  set_counting(true);
  for (int pass = 0; pass < 2; ++pass) {     // the second pass re-enters the crack
    for (int k = 0; k <= 30000; ++k) {        // approach, cut 14 mm, retreat, with a lateral wobble
      const double z = k <= 15000 ? 0.016 - 1e-6 * k : 0.001 + 1e-6 * (k - 15000);
      tool.position = {0.020, 5e-5 * std::sin(1e-3 * k), z};
      model.step({&tool, 1}, 1e-3, {&out, 1});
      modes_seen |= 1L << static_cast<int>(out.mode);
    }
  }
  set_counting(false);
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_EQ(modes_seen, 0b11111); // every mode was exercised while counting
}

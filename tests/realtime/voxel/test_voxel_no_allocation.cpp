// The realtime contract (../shared/DESIGN.md): `step` allocates nothing. This program replaces
// the global operator new/delete and (outside sanitizer builds) glibc's malloc family with
// counting versions (the technique of tests/realtime/fracture/test_no_allocation.cpp), then
// steps the voxel model through contact, plunge, a cut with grid re-centring, pressing,
// retreat and re-entry into the cut, and requires zero allocations during the steps.

#include "tests/realtime/voxel/voxel_test_setup.hpp"

#include "tests/realtime/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

using kerf::test::allocations;
using kerf::test::set_counting;

using namespace kerf;

TEST(RealtimeContract, VoxelModelStepAllocatesNothing) {
  constexpr double mm = 1e-3;
  VoxelSurfaceCuttingModel model(test::cube_surface(1 * mm, 20), test::sponge_setup());

  // Sanity check that the counter works at all (direct calls: a new-expression may be elided).
  set_counting(true);
  ::operator delete(::operator new(16));
  set_counting(false);
  ASSERT_GE(allocations.load(), 1);
  allocations = 0;

  long modes_seen = 0;
  const auto note = [&](const ToolState&, const ForceSample& f) { modes_seen |= 1L << static_cast<int>(f.mode); };
  set_counting(true);
  for (int pass = 0; pass < 2; ++pass) { // the second pass re-enters the cut
    test::move(model, {0.1 * mm, 0, 1.1 * mm}, {0.1 * mm, 0, 0.6 * mm}, 1e-3, note);
    test::move(model, {0.1 * mm, 0, 0.6 * mm}, {0.9 * mm, 0.05 * mm, 0.5 * mm}, 1e-3, note);
    test::move(model, {0.9 * mm, 0.05 * mm, 0.5 * mm}, {0.9 * mm, 0.05 * mm, 0.5 * mm}, 1e-3, note); // press
    test::move(model, {0.9 * mm, 0.05 * mm, 0.5 * mm}, {0.9 * mm, 0.05 * mm, 1.1 * mm}, 1e-3, note);
  }
  set_counting(false);
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_GT(model.cut_advances(), 0);
  // no-contact, deformation-1, cutting, deformation-2 were all exercised while counting.
  const long expected = (1L << static_cast<int>(InteractionMode::no_contact)) |
                        (1L << static_cast<int>(InteractionMode::deformation_1)) |
                        (1L << static_cast<int>(InteractionMode::cutting)) |
                        (1L << static_cast<int>(InteractionMode::deformation_2));
  EXPECT_EQ(modes_seen, expected);
}

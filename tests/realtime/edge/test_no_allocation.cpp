// The realtime contract (../shared/DESIGN.md): `step` allocates nothing. This program replaces
// the global operator new/delete (all forms, nothrow included) and, outside sanitizer builds,
// glibc's malloc family with counting versions (the technique of
// tests/realtime/fracture/test_no_allocation.cpp), then steps the discrete-edge model through
// approach, cut through two layers, retreat, re-entry into its own cut, with friction, drag
// and a lateral wobble, and requires zero allocations during the steps.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/edge/discrete_edge_cutting_model.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
namespace {
std::atomic<long> allocations{0};
thread_local bool counting = false;
void note_allocation() {
  if (counting) allocations.fetch_add(1, std::memory_order_relaxed);
}
} // namespace

// These replacements pair operator new with std::free through malloc, which is correct, but GCC
// sees free() on a pointer from operator new once delete is inlined and warns.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t size) {
  note_allocation();
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, std::align_val_t align) {
  note_allocation();
  if (void* p = std::aligned_alloc(static_cast<std::size_t>(align), (size + static_cast<std::size_t>(align) - 1) / static_cast<std::size_t>(align) * static_cast<std::size_t>(align))) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) { return operator new(size, align); }
// The nothrow forms too: every allocation function is replaced, so every delete may free().
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  note_allocation();
  return std::malloc(size ? size : 1);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void* operator new(std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  note_allocation();
  const auto a = static_cast<std::size_t>(align);
  return std::aligned_alloc(a, (size + a - 1) / a * a);
}
void* operator new[](std::size_t size, std::align_val_t align, const std::nothrow_t& tag) noexcept {
  return operator new(size, align, tag);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

#if !defined(__SANITIZE_ADDRESS__) && defined(__GLIBC__)
// Eigen and C code allocate with malloc directly: count those too, through glibc's own entry
// points (sanitizer builds intercept malloc themselves, so there only operator new is counted).
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* malloc(std::size_t size) {
  note_allocation();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  note_allocation();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  note_allocation();
  return __libc_realloc(p, size);
}
}
#endif

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

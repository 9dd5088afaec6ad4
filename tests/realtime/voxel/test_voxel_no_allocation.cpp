// The realtime contract (../shared/DESIGN.md): `step` allocates nothing. This program replaces
// the global operator new/delete and (outside sanitizer builds) glibc's malloc family with
// counting versions (the technique of tests/realtime/fracture/test_no_allocation.cpp), then
// steps the voxel model through contact, plunge, a cut with grid re-centring, pressing,
// retreat and re-entry into the cut, and requires zero allocations during the steps.

#include "tests/realtime/voxel/voxel_test_setup.hpp"

#include <gtest/gtest.h>

#include <atomic>
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

TEST(RealtimeContract, VoxelModelStepAllocatesNothing) {
  constexpr double mm = 1e-3;
  VoxelSurfaceCuttingModel model(test::cube_surface(1 * mm, 20), test::sponge_setup());

  // Sanity check that the counter works at all (direct calls: a new-expression may be elided).
  counting = true;
  ::operator delete(::operator new(16));
  counting = false;
  ASSERT_GE(allocations.load(), 1);
  allocations = 0;

  long modes_seen = 0;
  const auto note = [&](const ToolState&, const ForceSample& f) { modes_seen |= 1L << static_cast<int>(f.mode); };
  counting = true;
  for (int pass = 0; pass < 2; ++pass) { // the second pass re-enters the cut
    test::move(model, {0.1 * mm, 0, 1.1 * mm}, {0.1 * mm, 0, 0.6 * mm}, 1e-3, note);
    test::move(model, {0.1 * mm, 0, 0.6 * mm}, {0.9 * mm, 0.05 * mm, 0.5 * mm}, 1e-3, note);
    test::move(model, {0.9 * mm, 0.05 * mm, 0.5 * mm}, {0.9 * mm, 0.05 * mm, 0.5 * mm}, 1e-3, note); // press
    test::move(model, {0.9 * mm, 0.05 * mm, 0.5 * mm}, {0.9 * mm, 0.05 * mm, 1.1 * mm}, 1e-3, note);
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_GT(model.cut_advances(), 0);
  // no-contact, deformation-1, cutting, deformation-2 were all exercised while counting.
  const long expected = (1L << static_cast<int>(InteractionMode::no_contact)) |
                        (1L << static_cast<int>(InteractionMode::deformation_1)) |
                        (1L << static_cast<int>(InteractionMode::cutting)) |
                        (1L << static_cast<int>(InteractionMode::deformation_2));
  EXPECT_EQ(modes_seen, expected);
}

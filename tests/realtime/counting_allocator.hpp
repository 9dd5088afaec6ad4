#pragma once
// The realtime contract's "allocates nothing", made checkable: counting_allocator.cpp replaces
// every global operator new/delete form with versions that count calls while counting is on for
// the calling thread, and counts the malloc family too: outside sanitizer builds by replacing
// malloc/calloc/realloc (through glibc's own entry points), under AddressSanitizer through its
// allocation hook (ASan intercepts malloc itself). Link it into a test program of its own: it
// replaces allocation for the whole program.
//
// The per-thread switch lives only inside counting_allocator.cpp, behind set_counting: GCC 12 at
// -O2 with UBSan null-checks the address of an extern thread_local with the flags of an
// `add x@gottpoff(%rip), %rax` that GNU ld then relaxes into a `lea` (which sets no flags), so the
// check fires on a valid address in every test that writes the flag directly (objdump of
// test_realtime_no_allocation under the sanitizer build).

#include <atomic>

namespace kerf::test {

extern std::atomic<long> allocations; ///< allocation calls counted so far

/// Counts (on) or stops counting (off) the allocations made by the calling thread.
void set_counting(bool on) noexcept;

} // namespace kerf::test

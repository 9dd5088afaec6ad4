#pragma once
// The realtime contract's "allocates nothing", made checkable: counting_allocator.cpp replaces
// every global operator new/delete form and (outside sanitizer builds, through glibc's own entry
// points) malloc/calloc/realloc with versions that count calls while `counting` is true on the
// calling thread. Link it into a test program of its own: it replaces allocation for the whole
// program.

#include <atomic>

namespace kerf::test {

extern std::atomic<long> allocations; ///< allocation calls counted so far
extern thread_local bool counting;    ///< count allocations made by this thread

} // namespace kerf::test

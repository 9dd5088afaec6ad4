#pragma once
// KERF_VECTOR_CLONES: marks a hot loop function of the spring network to be compiled three times —
// for AVX-512 (x86-64-v4), AVX2 + FMA (x86-64-v3) and baseline x86-64 — with the loader picking
// the widest the processor has (GCC function multi-versioning, an ifunc). The build stays
// portable; elsewhere (other compilers, architectures, sanitizer builds) it is empty.

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define KERF_VECTOR_CLONES [[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]]
#else
#define KERF_VECTOR_CLONES
#endif

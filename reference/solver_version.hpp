#pragma once
// The version of the reference's numbers. A study's reference cache keys every cached profile by
// it (experiments/study/reference_cache.hpp), so a profile computed by another version is
// recomputed, never read back as if current.
//
// Bump it (+1) in the commit that changes what the reference computes for unchanged inputs: a
// material law, the element or quadrature, assembly, contact or the cohesive interface, the
// load path, the Newton or linear-solver defaults, a mesh or refinement rule. A change that only
// makes the same answer faster (converging to the same tolerance) needs no bump.
// tests/reference/test_solver_version.cpp solves a small fixed problem and fails when its numbers
// move by more than 1e-7 (relative) from the values recorded for this version: when it fails,
// bump solver_version and re-record the values there.

namespace kerf::reference {

// 2: a grasped disc's elastic layer tapers to zero at its rim (ElasticFoundation::tapered_disc).
inline constexpr int solver_version = 2;

} // namespace kerf::reference

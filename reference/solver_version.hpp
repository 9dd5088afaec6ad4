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

// 2: the cohesive interface's Newton tangent (secant only while the iteration is unsettled)
//    changes the load path of cohesive problems.
// 3: a grasped disc's elastic layer tapers to zero at its rim (ElasticFoundation::tapered_disc).
// 4: quadratic tetrahedra integrate their stresses and tangent with Witherden and Vincent's
//    8-point rule (degree 3) instead of the 14-point one (degree 5); Newton accepts a stall of
//    |R| within ten times its tolerance.
// 5: the load path follows the trajectory: every vertex of the motion is a load, and the loads
//    between two targets (cut-backs) lie on the trajectory, not on the chord.
inline constexpr int solver_version = 5;

} // namespace kerf::reference

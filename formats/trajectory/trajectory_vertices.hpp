#pragma once
// The vertices of a sampled motion: the samples a load path must pass through so that, between two
// of them, the motion is a straight line in time (within a tolerance). A quasi-static reference
// solves equilibria at a sequence of loads; between two loads its tool moves along the chord
// p(t) = p_a + (t − t_a)/(t_b − t_a) (p_b − p_a). When the motion between the two samples is not
// that chord — a cut that goes down and comes back up, a dwell that ends, a recorded hand that
// turns — the solved load path is another trajectory than the one the models follow. Its corners,
// found here, are loads the reference must solve (docs/reference.md, "The load path").
//
// The vertices of one motion are those of the Ramer–Douglas–Peucker simplification of its
// time-parametrised polyline (Douglas & Peucker 1973, Cartographica 10(2), 112–122) with the
// distance of a sample from a chord measured at the sample's own time: for samples a < k < b,
//
//   d_k = | p_k − p_a − (t_k − t_a)/(t_b − t_a) (p_b − p_a) |,
//
// and the chord a–b is kept when max_k d_k <= tolerance, else split at the farthest sample. So a
// dwell (p constant, then moving) is a corner although its path in space is a straight line, and
// the kept polyline is within `tolerance` of the sampled motion at every sample: the path a load
// path interpolating in time between consecutive vertices follows is the motion to `tolerance`.

#include "formats/trajectory/trajectory.hpp"

#include <cstddef>
#include <vector>

namespace kerf {

/// The vertex samples of `trajectory` (see file comment), ascending, the first and last sample
/// included; `tolerance` [m] > 0. Throws std::invalid_argument on a non-positive tolerance.
std::vector<std::size_t> trajectory_vertices(const SampledTrajectory& trajectory, double tolerance);

/// The vertices of several tools moving on one time line (sample k of each at the same time): the
/// union of each one's vertices (a sample past a shorter trajectory's end is that tool at rest).
std::vector<std::size_t> trajectory_vertices(const std::vector<SampledTrajectory>& trajectories, double tolerance);

} // namespace kerf

#pragma once
// What a model returns for one tool at one sample: the force and the interaction mode in paper
// 001's terms (§4.2–4.3, Fig. 5).

#include "meshes/interaction_mode.hpp"

#include <Eigen/Core>

namespace kerf {

/// One tool's output for one sample.
struct ForceSample {
  Eigen::Vector3d force = Eigen::Vector3d::Zero(); ///< force the body exerts on the tool [N]
  InteractionMode mode = InteractionMode::no_contact;
  double crack_extent = 0.0;  ///< crack depth along the cutting axis, c of paper 001 Fig. 3 [m]
  bool over_budget = false;   ///< the model could not finish within its time budget
};

// The guard at both ends of a fast model's step: a broken input or a non-finite force never
// becomes a force on the device (DESIGN.md: a model never returns NaN). Each guard that trips
// counts once in `non_finite`, which the models report as non_finite_count() (should stay 0).

/// True when the tool's position is usable; otherwise counts it and leaves `out` as it is (the
/// caller returns it: zero force, no contact).
inline bool finite_input(const Eigen::Vector3d& position, long& non_finite) noexcept {
  if (position.allFinite()) return true;
  ++non_finite;
  return false;
}

/// Writes the step's result into `out`, the force replaced by zero (and counted) when it is not
/// finite.
inline void write_sample(ForceSample& out, const Eigen::Vector3d& force, InteractionMode mode, double crack_extent,
                         long& non_finite) noexcept {
  if (force.allFinite()) {
    out.force = force;
  } else {
    ++non_finite;
    out.force.setZero();
  }
  out.mode = mode;
  out.crack_extent = crack_extent;
}

} // namespace kerf

#pragma once

#include <Eigen/Core>

namespace kerf {

/// The state of one tool at one servo sample, as a device or a trajectory gives it.
/// Position of the tool's reference point (a blade's edge midpoint, a sphere's centre) [m],
/// its velocity [m/s], and the sample time [s].
struct ToolState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  double time = 0.0;
};

} // namespace kerf

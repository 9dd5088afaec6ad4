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

} // namespace kerf

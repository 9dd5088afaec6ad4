#pragma once
// What a model returns for one tool at one sample: the force and the interaction mode in paper
// 001's terms (§4.2–4.3, Fig. 5).

#include <Eigen/Core>

#include <optional>
#include <string_view>

namespace kerf {

/// Interaction modes of paper 001 §4.2: deformation in state 1 (uncut material) or state 2
/// (inside a crack), rupture (the instant the stored energy opens a crack), cutting (the crack
/// front advances with the tool), and no contact.
enum class InteractionMode { no_contact, deformation_1, rupture, cutting, deformation_2 };

/// Profile spelling: "no-contact", "deformation-1", "rupture", "cutting", "deformation-2".
std::string_view to_string(InteractionMode mode);
std::optional<InteractionMode> interaction_mode_from_string(std::string_view name);

/// One tool's output for one sample.
struct ForceSample {
  Eigen::Vector3d force = Eigen::Vector3d::Zero(); ///< force the body exerts on the tool [N]
  InteractionMode mode = InteractionMode::no_contact;
  double crack_extent = 0.0;  ///< crack depth along the cutting axis, c of paper 001 Fig. 3 [m]
  bool over_budget = false;   ///< the model could not finish within its time budget
};

} // namespace kerf

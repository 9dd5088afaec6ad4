#pragma once
// The interaction modes of paper 001 §4.2 (Fig. 5): the vocabulary every model and the reference
// label their samples with, and the force profile's spelling of them.

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

} // namespace kerf

#include "meshes/interaction_mode.hpp"

#include <array>
#include <utility>

namespace kerf {

namespace {
constexpr std::array<std::pair<InteractionMode, std::string_view>, 5> mode_names{{
    {InteractionMode::no_contact, "no-contact"},
    {InteractionMode::deformation_1, "deformation-1"},
    {InteractionMode::rupture, "rupture"},
    {InteractionMode::cutting, "cutting"},
    {InteractionMode::deformation_2, "deformation-2"},
}};
} // namespace

std::string_view to_string(InteractionMode mode) {
  for (const auto& [m, name] : mode_names)
    if (m == mode) return name;
  return "?";
}

std::optional<InteractionMode> interaction_mode_from_string(std::string_view name) {
  for (const auto& [m, n] : mode_names)
    if (n == name) return m;
  return std::nullopt;
}

} // namespace kerf

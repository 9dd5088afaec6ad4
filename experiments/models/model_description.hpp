#pragma once
// What each model kerf can run is: its name, what it covers and where it comes from (`kerf
// models`). Data only: the study reader checks a study's `models` against it without linking the
// model builders (model_catalogue.hpp builds them; the fuzz build links this alone).

#include "realtime/phenomena.hpp"

#include <span>
#include <string_view>

namespace kerf {

/// One entry of `kerf models`.
struct ModelDescription {
  std::string_view name;     ///< command-line name
  std::string_view summary;  ///< one line
  std::string_view source;   ///< paper and section
  PhenomenonSet covers;      ///< phenomena it can represent
  std::string_view tools;    ///< which tools it takes
};

/// Every model that exists in this build, in the order `kerf models` lists them.
std::span<const ModelDescription> model_catalogue();
/// The model named `name`, or null.
const ModelDescription* find_model(std::string_view name);

} // namespace kerf

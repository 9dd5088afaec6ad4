// The fuzz build's model catalogue lookup (fuzz/CMakeLists.txt only; the normal build links
// experiments/models/model_catalogue.cpp): find_model and model_catalogue answer from the catalogue's
// names (catalogue_model_names.hpp), which is all the study reader asks of them. The descriptions
// carry the name only.

#include "experiments/models/model_catalogue.hpp"
#include "fuzz/catalogue_model_names.hpp"

#include <vector>

namespace kerf {

namespace {

const std::vector<ModelDescription> descriptions = [] {
  std::vector<ModelDescription> d;
  for (std::string_view name : fuzz::catalogue_model_names) d.push_back(ModelDescription{name, {}, {}, {}, {}});
  return d;
}();

} // namespace

std::span<const ModelDescription> model_catalogue() { return descriptions; }

const ModelDescription* find_model(std::string_view name) {
  for (const ModelDescription& d : descriptions)
    if (d.name == name) return &d;
  return nullptr;
}

} // namespace kerf

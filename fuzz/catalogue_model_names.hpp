#pragma once
// The model names of kerf's catalogue (experiments/models/model_catalogue.cpp), for the fuzz build.
// The study reader checks `models = [...]` against the catalogue (find_model), but the catalogue
// links every model builder and, through them, the meshing (gmsh) that the fuzz build leaves
// out; the fuzz build's find_model (catalogue_lookup.cpp) answers from this list instead.
// tests/faults/test_fuzz_regressions.cpp checks that it equals the real catalogue's names.

#include <array>
#include <string_view>

namespace kerf::fuzz {

/// The `name` of every entry of model_catalogue(), in its order.
inline constexpr std::array<std::string_view, 4> catalogue_model_names{"fracture", "edge", "voxel", "springs"};

} // namespace kerf::fuzz

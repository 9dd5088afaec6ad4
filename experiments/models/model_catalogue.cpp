#include "experiments/models/model_catalogue.hpp"

#include "experiments/models/model_builders.hpp"

namespace kerf {

namespace {

/// How a model (model_description.cpp: what it is) is checked against a scene and built.
struct CatalogueEntry {
  std::string_view name;
  void (*require_inputs)(const Scene&);
  BuiltModel (*build)(const Scene&, const TetMesh&);
  /// For a model that takes options (then `build` may be null).
  BuiltModel (*build_with_options)(const Scene&, const TetMesh&, const ModelOptions&) = nullptr;
  /// What it reproduces of a scene when less than the scene's phenomena it covers; null: those.
  PhenomenonSet (*represents)(const Scene&) = nullptr;
};

/// The phenomena in both `a` and `b`.
PhenomenonSet common(PhenomenonSet a, PhenomenonSet b) { return a.missing_from(a.missing_from(b)); }

/// The spring network with a blade: the edge presses the network (deformation), nothing is cut and
/// nothing slides (springs_builder.cpp); with styluses, what it covers (deformation, tearing).
PhenomenonSet springs_represent(const Scene& scene) {
  const bool blade = !scene.tools.empty() && scene.tools.front().kind == Tool::Kind::blade;
  return common(scene.phenomena, blade ? PhenomenonSet{Phenomenon::deformation}
                                       : PhenomenonSet{Phenomenon::deformation, Phenomenon::tearing});
}

const CatalogueEntry catalogue[] = {
    {"fracture", &require_fracture_inputs, &build_fracture_model},
    {"edge", &require_edge_inputs, &build_edge_model},
    {"voxel", &require_voxel_inputs, &build_voxel_model},
    {"springs", &require_springs_inputs, nullptr, &build_springs_model, &springs_represent},
};

const CatalogueEntry* find_entry(std::string_view name) {
  for (const CatalogueEntry& e : catalogue)
    if (e.name == name) return &e;
  return nullptr;
}

} // namespace

ToughnessRegions toughness_regions(const Scene& scene) {
  ToughnessRegions r;
  if (scene.phenomena.contains(Phenomenon::layers)) {
    for (const Material& layer : scene.layers) {
      r.regions.push_back(layer.region);
      r.fracture_toughness.push_back(layer.fracture_toughness);
    }
  } else {
    r.fracture_toughness.push_back(scene.material.fracture_toughness);
  }
  return r;
}

const ModelDescription& require_model_for_scene(std::string_view name, const Scene& scene) {
  const CatalogueEntry* entry = find_entry(name);
  const ModelDescription* description = find_model(name);
  if (!entry || !description) {
    std::string known;
    for (const ModelDescription& m : model_catalogue()) known += (known.empty() ? "" : ", ") + std::string(m.name);
    throw std::invalid_argument("unknown model \"" + std::string(name) + "\" (known: " + known + ")");
  }
  const ModelDescription& d = *description;
  const PhenomenonSet missing = scene.phenomena.missing_from(d.covers);
  if (!missing.empty())
    throw ModelMismatch("model " + std::string(name) + " cannot represent " + missing.to_string() + ", which scene " +
                        scene.name + " declares (it covers " + d.covers.to_string() + ")");
  entry->require_inputs(scene);
  return d;
}

PhenomenonSet represented_phenomena(std::string_view name, const Scene& scene) {
  const ModelDescription& d = require_model_for_scene(name, scene);
  const CatalogueEntry* entry = find_entry(name);
  return entry->represents ? entry->represents(scene) : common(scene.phenomena, d.covers);
}

BuiltModel make_model(std::string_view name, const Scene& scene, const TetMesh& mesh, const ModelOptions& options) {
  require_model_for_scene(name, scene);
  const CatalogueEntry* entry = find_entry(name);
  if (entry->build_with_options) return entry->build_with_options(scene, mesh, options);
  if (!options.empty())
    throw std::invalid_argument("model " + std::string(name) + " takes no options (got \"" + options.begin()->first + "\")");
  return entry->build(scene, mesh);
}

} // namespace kerf

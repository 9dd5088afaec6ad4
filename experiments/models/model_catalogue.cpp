#include "experiments/models/model_catalogue.hpp"

#include "experiments/models/model_builders.hpp"

namespace kerf {

namespace {

/// One model: what `kerf models` prints, how a scene is checked for it, how it is built.
struct CatalogueEntry {
  ModelDescription description;
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
    {{"fracture", "energy-based sharp cutting: deformation, rupture, cutting (f = J_c l), layers, pre-sliding friction",
      "paper 001 §4, §6, Fig. 11",
      PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction, Phenomenon::layers},
      "one blade"},
     &require_fracture_inputs, &build_fracture_model},
    {{"edge", "discretised blade edge: stiffness x disparity per point, shear-limited cutting resistance, friction, drag; voxel collision; geometric cut off the servo thread; with a stylus, the cut piece pulled by the spring network",
      "paper 000 §3.1-3.3 (with a stylus §4 and §2.1)",
      PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction, Phenomenon::layers},
      "one blade, or one blade then one sphere (stylus)"},
     &require_edge_inputs, &build_edge_model},
    {{"voxel", "polygon surface + local voxel grid: surface points advanced past critical forces, DCS, clip friction (Eq. 1)",
      "paper 002 §2.3-2.4, Table 1",
      PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction},
      "one sphere (cutting stick)"},
     &require_voxel_inputs, &build_voxel_model},
    {{"springs", "cubic 28-spring network around the stylus(es), E and ν identified, embedding, tearing; --integrator explicit|implicit|static; "
                 "on a one-blade cutting scene the deformation phase only (the edge presses the network: no cut, no friction)",
      "paper 000 §2.1, §2.2", PhenomenonSet{Phenomenon::deformation, Phenomenon::tearing, Phenomenon::cutting, Phenomenon::friction},
      "one or two spheres (styluses), or one blade (deformation phase)"},
     &require_springs_inputs, nullptr, &build_springs_model, &springs_represent},
};

const std::vector<ModelDescription> descriptions = [] {
  std::vector<ModelDescription> d;
  for (const CatalogueEntry& e : catalogue) d.push_back(e.description);
  return d;
}();

const CatalogueEntry* find_entry(std::string_view name) {
  for (const CatalogueEntry& e : catalogue)
    if (e.description.name == name) return &e;
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

std::span<const ModelDescription> model_catalogue() { return descriptions; }

const ModelDescription* find_model(std::string_view name) {
  const CatalogueEntry* e = find_entry(name);
  return e ? &e->description : nullptr;
}

const ModelDescription& require_model_for_scene(std::string_view name, const Scene& scene) {
  const CatalogueEntry* entry = find_entry(name);
  if (!entry) {
    std::string known;
    for (const CatalogueEntry& e : catalogue) known += (known.empty() ? "" : ", ") + std::string(e.description.name);
    throw std::invalid_argument("unknown model \"" + std::string(name) + "\" (known: " + known + ")");
  }
  const ModelDescription& d = entry->description;
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

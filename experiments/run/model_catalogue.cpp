#include "experiments/run/model_catalogue.hpp"

#include "realtime/fracture/fracture_cutting_model.hpp"

#include <array>

namespace kerf {

namespace {

const std::array<ModelDescription, 1> catalogue{{
    {"fracture", "energy-based sharp cutting: deformation, rupture, cutting (f = J_c l), layers, pre-sliding friction",
     "paper 001 §4, §6, Fig. 11",
     PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction, Phenomenon::layers},
     "one blade"},
}};

nlohmann::json vector_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

void require_fracture_inputs(const Scene& scene) {
  if (scene.tools.size() != 1 || scene.tools.front().kind != Tool::Kind::blade)
    throw ModelMismatch("model fracture needs exactly one blade tool; scene " + scene.name + " has " +
                        std::to_string(scene.tools.size()) + " tool(s)" +
                        (scene.tools.empty() || scene.tools.front().kind == Tool::Kind::blade ? "" : ", not a blade"));
  if (!scene.fracture)
    throw ModelMismatch("model fracture needs the [models.fracture] section (paper 001 §6 responses f_r, δ_r, i, "
                        "δ_c, j) in " + scene.file.string());
}

BuiltModel make_fracture_model(const Scene& scene, const TetMesh& mesh) {
  const BladeShape& blade = scene.tools.front().blade;
  FractureCuttingSetup setup;
  setup.edge_direction = blade.edge_direction;
  setup.cutting_direction = blade.cutting_direction;
  setup.edge_length = blade.edge_length;
  setup.response = *scene.fracture;
  // Only the machinery the scene needs: per-layer lengths for a layered body, friction only if
  // the scene declares it.
  ToughnessRegions regions = toughness_regions(scene);
  setup.regions = std::move(regions.regions);
  setup.fracture_toughness = std::move(regions.fracture_toughness);
  setup.friction = scene.phenomena.contains(Phenomenon::friction);
  setup.friction_coefficient = setup.friction ? scene.material.friction_coefficient : 0.0;
  setup.crack_capture_width = std::max(blade.thickness, 1e-6);

  nlohmann::json p;
  p["edge_direction"] = vector_json(setup.edge_direction);
  p["cutting_direction"] = vector_json(setup.cutting_direction);
  p["edge_length_m"] = setup.edge_length;
  p["regions"] = setup.regions;
  p["fracture_toughness_J_per_m2"] = setup.fracture_toughness;
  p["rupture_force_per_length_N_per_m"] = setup.response.rupture_force_per_length;
  p["rupture_deflection_m"] = setup.response.rupture_deflection;
  p["deformation_1_exponent"] = setup.response.deformation_1_exponent;
  p["crack_deflection_m"] = setup.response.crack_deflection;
  p["deformation_2_exponent"] = setup.response.deformation_2_exponent;
  p["lateral_stiffness_N_per_m"] = setup.response.lateral_stiffness;
  p["friction"] = setup.friction;
  if (setup.friction) {
    p["friction_coefficient"] = setup.friction_coefficient;
    p["presliding_stiffness_N_per_m"] = setup.response.presliding_stiffness;
    p["presliding_stick_ratio"] = setup.response.presliding_stick_ratio;
  }
  p["crack_capture_width_m"] = setup.crack_capture_width;
  return {std::make_unique<FractureCuttingModel>(mesh, std::move(setup)), std::move(p)};
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

std::span<const ModelDescription> model_catalogue() { return catalogue; }

const ModelDescription* find_model(std::string_view name) {
  for (const ModelDescription& m : catalogue)
    if (m.name == name) return &m;
  return nullptr;
}

const ModelDescription& require_model_for_scene(std::string_view name, const Scene& scene) {
  const ModelDescription* description = find_model(name);
  if (!description) {
    std::string known;
    for (const ModelDescription& m : catalogue) known += (known.empty() ? "" : ", ") + std::string(m.name);
    throw std::invalid_argument("unknown model \"" + std::string(name) + "\" (known: " + known + ")");
  }
  const PhenomenonSet missing = scene.phenomena.missing_from(description->covers);
  if (!missing.empty())
    throw ModelMismatch("model " + std::string(name) + " cannot represent " + missing.to_string() + ", which scene " +
                        scene.name + " declares (it covers " + description->covers.to_string() + ")");
  if (name == "fracture") require_fracture_inputs(scene);
  return *description;
}

BuiltModel make_model(std::string_view name, const Scene& scene, const TetMesh& mesh) {
  require_model_for_scene(name, scene);
  if (name == "fracture") return make_fracture_model(scene, mesh);
  throw std::logic_error("model " + std::string(name) + " is catalogued but has no builder");
}

} // namespace kerf

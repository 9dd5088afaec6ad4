// The fracture model (paper 001) built from a scene: one blade, the [models.fracture] responses,
// per-layer toughness, friction only if the scene declares it.

#include "experiments/models/model_builders.hpp"
#include "realtime/fracture/fracture_cutting_model.hpp"

namespace kerf {

namespace {
nlohmann::json vector_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

} // namespace

void require_fracture_inputs(const Scene& scene) {
  if (scene.tools.size() != 1 || scene.tools.front().kind != Tool::Kind::blade)
    throw ModelMismatch("model fracture needs exactly one blade tool; scene " + scene.name + " has " +
                        std::to_string(scene.tools.size()) + " tool(s)" +
                        (scene.tools.empty() || scene.tools.front().kind == Tool::Kind::blade ? "" : ", not a blade"));
  if (!scene.fracture)
    throw ModelMismatch("model fracture needs the [models.fracture] section (paper 001 §6 responses f_r, δ_r, i, "
                        "δ_c, j) in " + scene.file.string());
}

BuiltModel build_fracture_model(const Scene& scene, const TetMesh& mesh) {
  const BladeShape& blade = scene.tools.front().blade;
  FractureCuttingSetup setup;
  setup.blade = blade;
  setup.response = *scene.fracture;
  // Only the machinery the scene needs: per-layer lengths for a layered body, friction only if
  // the scene declares it.
  ToughnessRegions regions = toughness_regions(scene);
  setup.regions = std::move(regions.regions);
  setup.fracture_toughness = std::move(regions.fracture_toughness);
  setup.friction = scene.phenomena.contains(Phenomenon::friction);
  setup.friction_coefficient = setup.friction ? scene.material.friction_coefficient : 0.0;
  setup.crack_capture_width = std::max(blade.thickness, 1e-6);
  // The scene's blade starts on its cutting axis: l(x) along it is tabulated once (a trajectory
  // or a hand that leaves the axis is measured on the mesh as before).
  setup.cutting_axis_point = scene.tools.front().trajectory.start;

  nlohmann::json p;
  p["edge_direction"] = vector_json(setup.blade.edge_direction);
  p["cutting_direction"] = vector_json(setup.blade.cutting_direction);
  p["edge_length_m"] = setup.blade.edge_length;
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

} // namespace kerf

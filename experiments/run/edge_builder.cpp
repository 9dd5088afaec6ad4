// The discrete-edge model (paper 000 §3.1, §3.3) built from a scene: one blade, its parameters
// derived from the material (no extra scene section), per-layer materials, friction only if the
// scene declares it.

#include "experiments/run/model_builders.hpp"
#include "realtime/edge/discrete_edge_cutting_model.hpp"

#include <algorithm>
#include <cmath>

namespace kerf {

namespace {

nlohmann::json vector_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

/// The material as the discrete edge sees it, per unit edge length:
/// - stiffness k' = E / (1 - ν²): a piece ΔL of edge pressed into the body as a rigid circular
///   flat punch of diameter ΔL on an elastic half-space has k = 2 a E / (1 - ν²) with a = ΔL/2
///   (Sneddon 1965, Int. J. Eng. Sci. 3:47), so k = k' ΔL;
/// - shear limit F_s' = J_c: at the cap the edge advances at force F_s' per unit length, doing
///   work F_s' per unit area of cut, which the energy balance of a cut sets equal to the fracture
///   toughness (paper 001 Eq. 10, f = J_c l);
/// - drag b' = η / (1 - ν²): the Kelvin–Voigt viscosity η through the same punch geometry (the
///   elastic–viscoelastic correspondence principle, E -> η).
EdgeMaterial edge_material(const Material& m) {
  const double plane = 1.0 - m.poisson_ratio * m.poisson_ratio;
  return {m.youngs_modulus / plane, m.fracture_toughness, m.damping / plane};
}

} // namespace

void require_edge_inputs(const Scene& scene) {
  if (scene.tools.size() != 1 || scene.tools.front().kind != Tool::Kind::blade)
    throw ModelMismatch("model edge needs exactly one blade tool; scene " + scene.name + " has " +
                        std::to_string(scene.tools.size()) + " tool(s)" +
                        (scene.tools.empty() || scene.tools.front().kind == Tool::Kind::blade ? "" : ", not a blade"));
  if (!scene.phenomena.contains(Phenomenon::cutting))
    throw ModelMismatch("model edge renders cutting with a blade; scene " + scene.name + " declares no cutting");
}

BuiltModel build_edge_model(const Scene& scene, const TetMesh& mesh) {
  const BladeShape& blade = scene.tools.front().blade;
  // Resolution (numerical choices, not material): voxels of a quarter element, one discrete edge
  // point per voxel width along the edge (paper 000 gives neither).
  const double voxel_size = scene.geometry.element_size / 4.0;
  DiscreteEdgeSetup setup;
  setup.edge_direction = blade.edge_direction;
  setup.cutting_direction = blade.cutting_direction;
  setup.edge_length = blade.edge_length;
  setup.point_count = std::max(1, static_cast<int>(std::ceil(blade.edge_length / voxel_size)));
  setup.friction_coefficient = scene.phenomena.contains(Phenomenon::friction) ? scene.material.friction_coefficient : 0.0;
  setup.channel_capture_width = std::max(blade.thickness, voxel_size);

  std::vector<std::string> regions;
  if (scene.phenomena.contains(Phenomenon::layers)) {
    for (const Material& layer : scene.layers) {
      regions.push_back(layer.region);
      setup.materials.push_back(edge_material(layer));
    }
  } else {
    setup.materials.push_back(edge_material(scene.material));
  }

  nlohmann::json p;
  p["edge_direction"] = vector_json(setup.edge_direction);
  p["cutting_direction"] = vector_json(setup.cutting_direction);
  p["edge_length_m"] = setup.edge_length;
  p["point_count"] = setup.point_count;
  p["voxel_size_m"] = voxel_size;
  p["regions"] = regions;
  nlohmann::json materials = nlohmann::json::array();
  for (const EdgeMaterial& m : setup.materials)
    materials.push_back({{"stiffness_per_length_Pa", m.stiffness_per_length},
                         {"shear_limit_per_length_N_per_m", m.shear_limit_per_length},
                         {"drag_per_length_N_s_per_m2", m.drag_per_length}});
  p["materials"] = materials;
  p["friction_coefficient"] = setup.friction_coefficient;
  p["channel_capture_width_m"] = setup.channel_capture_width;
  CollisionVoxels voxels(mesh, voxel_size, regions);
  p["marked_voxels"] = voxels.marked_count();
  return {std::make_unique<DiscreteEdgeCuttingModel>(std::move(voxels), std::move(setup)), std::move(p)};
}

} // namespace kerf

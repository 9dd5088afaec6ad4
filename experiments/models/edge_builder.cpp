// The discrete-edge model (paper 000 §3.1, §3.3) built from a scene: one blade, its parameters
// derived from the material (no extra scene section), per-layer materials, friction only if the
// scene declares it; the geometric cut of §3.2 runs off the stepping thread on the scene's mesh,
// and a run writes the cut mesh (cut_mesh.vtu) and its fragments into the manifest.

#include "experiments/models/model_builders.hpp"
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
  const bool one_blade = scene.tools.size() == 1 && scene.tools[0].kind == Tool::Kind::blade;
  const bool blade_then_stylus = scene.tools.size() == 2 && scene.tools[0].kind == Tool::Kind::blade &&
                                 scene.tools[1].kind == Tool::Kind::sphere;
  if (!one_blade && !blade_then_stylus)
    throw ModelMismatch("model edge needs one blade tool, or a blade and then a sphere stylus (paper 000 §4: cut, then "
                        "pull a piece); scene " + scene.name + " has " + std::to_string(scene.tools.size()) +
                        " tool(s) in another arrangement");
  if (!scene.phenomena.contains(Phenomenon::cutting))
    throw ModelMismatch("model edge renders cutting with a blade; scene " + scene.name + " declares no cutting");
}

EdgeSceneSetup edge_setup_for_scene(const Scene& scene, const Tool& tool) {
  const BladeShape& blade = tool.blade;
  // Resolution (numerical choices, not material): voxels of a quarter element, one discrete edge
  // point per voxel width along the edge (paper 000 gives neither).
  EdgeSceneSetup e;
  e.voxel_size = scene.geometry.element_size / 4.0;
  DiscreteEdgeSetup& setup = e.setup;
  setup.blade = blade;
  setup.point_count = std::max(1, static_cast<int>(std::ceil(blade.edge_length / e.voxel_size)));
  setup.friction_coefficient = scene.phenomena.contains(Phenomenon::friction) ? scene.material.friction_coefficient : 0.0;
  setup.channel_capture_width = std::max(blade.thickness, e.voxel_size);

  if (scene.phenomena.contains(Phenomenon::layers)) {
    for (const Material& layer : scene.layers) {
      e.regions.push_back(layer.region);
      setup.materials.push_back(edge_material(layer));
    }
  } else {
    setup.materials.push_back(edge_material(scene.material));
  }

  nlohmann::json& p = e.parameters;
  p["edge_direction"] = vector_json(setup.blade.edge_direction);
  p["cutting_direction"] = vector_json(setup.blade.cutting_direction);
  p["edge_length_m"] = setup.blade.edge_length;
  p["point_count"] = setup.point_count;
  p["voxel_size_m"] = e.voxel_size;
  p["regions"] = e.regions;
  nlohmann::json materials = nlohmann::json::array();
  for (const EdgeMaterial& m : setup.materials)
    materials.push_back({{"stiffness_per_length_Pa", m.stiffness_per_length},
                         {"shear_limit_per_length_N_per_m", m.shear_limit_per_length},
                         {"drag_per_length_N_s_per_m2", m.drag_per_length}});
  p["materials"] = materials;
  p["friction_coefficient"] = setup.friction_coefficient;
  p["channel_capture_width_m"] = setup.channel_capture_width;
  // The cut's trajectory is recorded every voxel width (the resolution of the collision model).
  e.record_spacing = e.voxel_size;
  p["geometric_cut"] = {{"record_spacing_m", e.record_spacing},
                        {"snap_tolerance", e.cut.snap_tolerance},
                        {"reach", e.cut.reach}};
  return e;
}

BuiltModel build_edge_model(const Scene& scene, const TetMesh& mesh) {
  if (scene.tools.size() == 2) return build_shape_forming_model(scene, mesh); // blade, then stylus
  EdgeSceneSetup e = edge_setup_for_scene(scene, scene.tools.front());
  CollisionVoxels voxels(mesh, e.voxel_size, e.regions);
  e.parameters["marked_voxels"] = voxels.marked_count();
  const BladeShape blade = e.setup.blade;
  auto model = std::make_unique<DiscreteEdgeCuttingModel>(std::move(voxels), std::move(e.setup));
  model->attach_geometric_cut(std::make_unique<BackgroundCut>(mesh, blade, e.cut), e.record_spacing);
  BuiltModel built{std::move(model), std::move(e.parameters)};
  built.write_outputs = [edge_model = static_cast<DiscreteEdgeCuttingModel*>(built.model.get())](const std::filesystem::path& dir, VtuWriter write) {
    return write_geometric_cut(*edge_model, dir, write);
  };
  return built;
}

nlohmann::json write_geometric_cut(DiscreteEdgeCuttingModel& model, const std::filesystem::path& dir, VtuWriter write) {
  model.finish_geometric_cut();
  const BackgroundCut& cut = *model.geometric_cut();
  const CuttableBody& body = cut.body();
  Eigen::MatrixXd fragment(body.mesh().tets.rows(), 1);
  for (Eigen::Index t = 0; t < fragment.rows(); ++t) fragment(t, 0) = body.fragment_of_tet()[static_cast<std::size_t>(t)];
  write(body.mesh(), dir / "cut_mesh.vtu", {}, {{"fragment", fragment}});
  int cut_tets = 0;
  for (const GeometricCutReport& r : cut.reports()) cut_tets += r.cut_tets;
  nlohmann::json j;
  j["mesh"] = "cut_mesh.vtu";
  j["passes"] = cut.cuts_done();
  j["cut_tetrahedra"] = cut_tets;
  j["tetrahedra"] = body.mesh().tets.rows();
  j["nodes"] = body.mesh().nodes.rows();
  j["fragments"] = body.fragment_count();
  j["fragment_volumes_m3"] = body.fragment_volumes();
  j["dropped_positions"] = cut.dropped();
  if (!cut.error().empty()) j["error"] = cut.error();
  return {{"geometric_cut", j}};
}

} // namespace kerf

// The voxel/polygon model (paper 002) built from a scene: one tool (a sphere: the cutting stick;
// a blade: a knife, whose point the stick renders), the body's boundary surface as its polygon,
// and Table 1 of [models.voxel] read as documented in docs/models.md (section voxel).

#include "experiments/models/model_builders.hpp"
#include "meshes/surface_mesh.hpp"
#include "realtime/voxel/cutting_resistance.hpp"
#include "realtime/voxel/voxel_surface_cutting_model.hpp"

namespace kerf {

namespace {

/// Paper 002 models a 1 mm cube with a 0.04 mm stick and gives Table 1's advance length in mm:
/// its model's length unit is the millimetre. Table 1's "N/m^2" and "N s/m^2" are read in that
/// unit (docs/models.md, voxel: only then do Table 1's critical forces lie within reach of the
/// stick in the 1 mm cube) [m].
constexpr double paper_002_length_unit = 1e-3;

/// Paper 002 renders a knife cut with the tip of a cutting stick (§2.2–2.3) and accounts for the
/// buried knife edge by the depth cutting stiffness and the clip friction force (§2.4), with Cw
/// "half of cutting edge width". A blade becomes that stick: radius Cw = t/2 (the blade's thickness
/// t), placed at the knife's point — the lower end of the edge (z up in every scene; the edge's
/// midpoint when the edge is level) — one radius behind it along the cutting direction d, so that
/// the stick's leading point is the knife's point and its depth the edge's depth. Returns the
/// stick's centre relative to the blade's reference point (its edge midpoint) [m].
Eigen::Vector3d knife_point_stick_offset(const BladeShape& b) {
  const Eigen::Vector3d& e = b.edge_direction;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  if (e.z() > 1e-12) point = -0.5 * b.edge_length * e;
  else if (e.z() < -1e-12) point = 0.5 * b.edge_length * e;
  return point - 0.5 * b.thickness * b.cutting_direction;
}

} // namespace

void require_voxel_inputs(const Scene& scene) {
  if (scene.tools.size() != 1)
    throw ModelMismatch("model voxel renders one cutting stick (paper 002 §2.2: a sphere tool, or a blade whose point the "
                        "stick renders, §2.4); scene " + scene.name + " has " + std::to_string(scene.tools.size()) +
                        " tools");
  if (!scene.voxel)
    throw ModelMismatch("model voxel needs the [models.voxel] section (paper 002 Table 1: elastic, friction and "
                        "damping coefficients, critical forces, advance length) in " + scene.file.string());
}

BuiltModel build_voxel_model(const Scene& scene, const TetMesh& mesh) {
  const VoxelModelSettings& t1 = *scene.voxel;
  // Table 1 in the paper's millimetre unit: E = 20 N/mm^2 as a modulus (Eq. 1's E, with the
  // deformed area Cw dz), the stick's contact stiffness k_e = E x 1 mm = 20 N/mm (the paper's
  // "material stiffness" E of the DCS), and the damping per unit penetration λ = 0.5 N s/mm^2
  // (Table 1's own unit: F = λ δ dδ/dt, VoxelCuttingSetup::damping).
  const double modulus = t1.elastic_coefficient / (paper_002_length_unit * paper_002_length_unit);
  const Tool& tool = scene.tools.front();
  VoxelCuttingSetup setup;
  if (tool.kind == Tool::Kind::sphere) {
    setup.tool_radius = tool.radius;
  } else {
    setup.tool_radius = 0.5 * tool.blade.thickness; // Cw of Eq. (1)
    setup.centre_offset = knife_point_stick_offset(tool.blade);
  }
  setup.contact_stiffness = modulus * paper_002_length_unit;
  setup.damping = t1.damping_coefficient / (paper_002_length_unit * paper_002_length_unit);
  setup.friction_coefficient = t1.friction_coefficient;
  setup.critical_force_depth = t1.critical_force_depth;
  setup.critical_force_cutting = t1.critical_force_cutting;
  setup.advance_length = t1.advance_length;
  setup.grid = t1.grid;
  setup.friction = scene.phenomena.contains(Phenomenon::friction);
  setup.depth_cutting_stiffness = t1.depth_cutting_stiffness;
  setup.clip_friction = t1.clip_friction;
  setup.clip_modulus = modulus;

  nlohmann::json p;
  p["table_1_length_unit_m"] = paper_002_length_unit;
  p["tool"] = tool.kind == Tool::Kind::sphere ? "sphere: the cutting stick" : "blade: the stick at the knife's point";
  p["tool_radius_m"] = setup.tool_radius;
  p["stick_centre_offset_m"] = {setup.centre_offset.x(), setup.centre_offset.y(), setup.centre_offset.z()};
  p["contact_stiffness_N_per_m"] = setup.contact_stiffness;
  p["damping_N_s_per_m2"] = setup.damping;
  p["friction"] = setup.friction;
  p["friction_coefficient"] = setup.friction_coefficient;
  p["critical_force_depth_N"] = setup.critical_force_depth;
  p["critical_force_cutting_N"] = setup.critical_force_cutting;
  p["advance_length_m"] = setup.advance_length;
  p["grid_cells"] = setup.grid;
  p["depth_cutting_stiffness"] = setup.depth_cutting_stiffness;
  p["depth_cutting_stiffness_per_mm"] = depth_cutting_stiffness_per_mm;
  p["clip_friction"] = setup.clip_friction;
  p["clip_modulus_Pa"] = setup.clip_modulus;
  p["regularisation_speed_m_per_s"] = setup.regularisation_speed;
  p["triangle_capacity"] = setup.triangle_capacity;
  auto model = std::make_unique<VoxelSurfaceCuttingModel>(boundary_surface(mesh), setup);
  p["voxel_memory_bytes"] = model->voxel_memory_bytes();
  return {std::move(model), std::move(p)};
}

} // namespace kerf

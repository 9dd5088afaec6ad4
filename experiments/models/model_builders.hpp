#pragma once
// How each model is checked against a scene and built from it. One pair of functions per model,
// each pair in its own file (`*_builder.cpp`); the catalogue (model_catalogue.cpp) lists them.

#include "experiments/models/model_catalogue.hpp"
#include "realtime/edge/discrete_edge_cutting_model.hpp"

namespace kerf {

/// Paper 001, realtime/fracture (fracture_builder.cpp).
void require_fracture_inputs(const Scene& scene);
BuiltModel build_fracture_model(const Scene& scene, const TetMesh& mesh);

/// Paper 000 §2, realtime/springs (springs_builder.cpp); option "integrator".
void require_springs_inputs(const Scene& scene);
BuiltModel build_springs_model(const Scene& scene, const TetMesh& mesh, const ModelOptions& options);

/// Paper 000 §3.1/§3.3, realtime/edge (edge_builder.cpp), with the geometric cut of §3.2 off
/// the stepping thread; a scene with a blade and then a sphere stylus gets paper 000 §4's shape
/// forming (build_shape_forming_model). write_geometric_cut finishes the cut, writes
/// DIR/cut_mesh.vtu (cell data `fragment`) through `write` and returns the manifest's
/// "geometric_cut" entry (passes, cut tetrahedra, fragments, fragment volumes [m^3]).
void require_edge_inputs(const Scene& scene);
BuiltModel build_edge_model(const Scene& scene, const TetMesh& mesh);
nlohmann::json write_geometric_cut(DiscreteEdgeCuttingModel& model, const std::filesystem::path& dir, VtuWriter write);
/// The edge model's setup for blade `tool` of `scene` (materials per region, resolution, the
/// geometric cut's recording) with its manifest parameters (edge_builder.cpp).
struct EdgeSceneSetup {
  DiscreteEdgeSetup setup;
  double voxel_size = 0.0;              ///< [m]
  std::vector<std::string> regions;
  GeometricCutOptions cut;
  double record_spacing = 0.0;          ///< [m]
  nlohmann::json parameters;
};
EdgeSceneSetup edge_setup_for_scene(const Scene& scene, const Tool& tool);

/// Paper 000 §4, cutting then deforming on one TetMesh: the edge model's blade and cut, then the
/// spring network on the fragment under the stylus (shape_forming_builder.cpp); model "edge" on
/// a scene whose tools are a blade and then a sphere (clay_form).
BuiltModel build_shape_forming_model(const Scene& scene, const TetMesh& mesh);

/// Paper 002, realtime/voxel (voxel_builder.cpp).
void require_voxel_inputs(const Scene& scene);
BuiltModel build_voxel_model(const Scene& scene, const TetMesh& mesh);

} // namespace kerf

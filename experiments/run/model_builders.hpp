#pragma once
// How each model is checked against a scene and built from it. One pair of functions per model,
// each pair in its own file (`*_builder.cpp`); the catalogue (model_catalogue.cpp) lists them.

#include "experiments/run/model_catalogue.hpp"

namespace kerf {

/// Paper 001, realtime/fracture (fracture_builder.cpp).
void require_fracture_inputs(const Scene& scene);
BuiltModel build_fracture_model(const Scene& scene, const TetMesh& mesh);

/// Paper 000 §2, realtime/springs (springs_builder.cpp); option "integrator".
void require_springs_inputs(const Scene& scene);
BuiltModel build_springs_model(const Scene& scene, const TetMesh& mesh, const ModelOptions& options);

/// Paper 000 §3.1/§3.3, realtime/edge (edge_builder.cpp).
void require_edge_inputs(const Scene& scene);
BuiltModel build_edge_model(const Scene& scene, const TetMesh& mesh);

/// Paper 002, realtime/voxel (voxel_builder.cpp).
void require_voxel_inputs(const Scene& scene);
BuiltModel build_voxel_model(const Scene& scene, const TetMesh& mesh);

} // namespace kerf

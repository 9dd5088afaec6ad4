// Paper 000 §4 (shape forming) built from a scene whose tools are a blade and then a sphere stylus
// (`kerf run clay_form --model edge`): tool 0 the blade cutting with the edge model and
// its geometric cut (edge_builder.cpp's setup), tool 1 a sphere stylus deforming the fragment it
// touches with the spring network (realtime/springs, built through SpringNetworkModel's public
// setup: the material's E, ν, ρ and damping, the scene's supports, the explicit integrator).
// A run writes the formed mesh (formed_mesh.vtu: the cut mesh with the pulled fragment's nodes
// moved) beside the cut mesh, and the fragments into the manifest.

#include "experiments/models/model_builders.hpp"
#include "realtime/edge/shape_forming_model.hpp"

namespace kerf {

BuiltModel build_shape_forming_model(const Scene& scene, const TetMesh& mesh) {
  EdgeSceneSetup e = edge_setup_for_scene(scene, scene.tools[0]);
  ShapeFormingSetup setup;
  setup.edge = e.setup;
  setup.voxel_size = e.voxel_size;
  setup.regions = e.regions;
  setup.cut = e.cut;
  setup.record_spacing = e.record_spacing;
  const Material& m = scene.material;
  SpringNetworkSetup& springs = setup.springs;
  springs.youngs_modulus = m.youngs_modulus;
  springs.poisson_ratio = m.poisson_ratio;
  springs.density = m.density;
  springs.damping = m.damping;
  springs.integrator = SpringIntegrator::symplectic_euler;
  for (const Support& s : scene.supports) springs.supports.push_back({s.surface, s.kind == Support::Kind::sliding});
  springs.styluses.push_back({scene.tools[1].trajectory.start, scene.tools[1].radius});
  // `kerf run` replays the trajectory faster than real time: the stylus phase waits for the cut
  // (ShapeFormingSetup::wait_for_cut), so the profile does not depend on the worker's speed.
  setup.wait_for_cut = true;

  nlohmann::json p;
  p["edge"] = e.parameters;
  p["springs"] = {{"integrator", std::string(to_string(springs.integrator))},
                  {"cells_per_side", springs.cells},
                  {"stylus_start_m", nlohmann::json::array({springs.styluses[0].start.x(), springs.styluses[0].start.y(),
                                                            springs.styluses[0].start.z()})},
                  {"stylus_radius_m", springs.styluses[0].radius}};
  p["wait_for_cut"] = setup.wait_for_cut;
  auto model = std::make_unique<ShapeFormingModel>(mesh, std::move(setup));
  BuiltModel built{std::move(model), std::move(p)};
  built.write_outputs = [forming = static_cast<ShapeFormingModel*>(built.model.get())](const std::filesystem::path& dir, VtuWriter write) {
    nlohmann::json j = write_geometric_cut(forming->edge(), dir, write);
    const TetMesh formed = forming->formed_mesh();
    write(formed, dir / "formed_mesh.vtu", {}, {});
    nlohmann::json stage = nlohmann::json::object();
    if (const FormingStage* s = forming->active_stage()) {
      stage["fragment"] = s->fragment;
      stage["fragment_tetrahedra"] = s->mesh.tets.rows();
      stage["network_cells"] = s->springs->network().cell_count();
      stage["attached_nodes"] = s->springs->attached_nodes(0);
      stage["mesh"] = "formed_mesh.vtu";
    }
    j["geometric_cut"]["forming"] = stage;
    return j;
  };
  return built;
}

} // namespace kerf

// The spring-network model (paper 000 §2) built from a scene: one or two sphere styluses, the
// material's E, ν, ρ and damping, the scene's supports, tearing (at the material's cohesive
// strength, or [models.springs] tensile_limit) only if the scene declares it; the network's
// settings from [models.springs] (docs/scenes.md). Model option "integrator": explicit, implicit
// or static (overrides the scene's).

#include "experiments/run/model_builders.hpp"
#include "realtime/springs/spring_network_model.hpp"

namespace kerf {

void require_springs_inputs(const Scene& scene) {
  if (scene.tools.empty() || scene.tools.size() > 2)
    throw ModelMismatch("model springs needs one or two sphere (stylus) tools; scene " + scene.name + " has " +
                        std::to_string(scene.tools.size()));
  for (const Tool& t : scene.tools)
    if (t.kind != Tool::Kind::sphere)
      throw ModelMismatch("model springs takes sphere (stylus) tools only (paper 000 §2: the stylus tip grasps the "
                          "body); tool \"" + t.name + "\" of scene " + scene.name + " is a blade");
  if (scene.phenomena.contains(Phenomenon::tearing) && !(scene.material.cohesive_strength > 0.0) &&
      !(scene.springs && scene.springs->tensile_limit))
    throw ModelMismatch("model springs tears at [models.springs] tensile_limit or the material's cohesive_strength, neither of "
                        "which scene " + scene.name + " gives");
}

BuiltModel build_springs_model(const Scene& scene, const TetMesh& mesh, const ModelOptions& options) {
  SpringNetworkSetup setup;
  const SpringsModelSettings settings = scene.springs.value_or(SpringsModelSettings{});
  if (settings.integrator) setup.integrator = *spring_integrator_from_string(*settings.integrator);
  for (const auto& [key, value] : options) {
    if (key != "integrator")
      throw std::invalid_argument("model springs: unknown option \"" + key + "\" (known: integrator)");
    const auto integrator = spring_integrator_from_string(value);
    if (!integrator)
      throw std::invalid_argument("model springs: integrator \"" + value + "\" is not one of explicit, implicit, static");
    setup.integrator = *integrator;
  }
  const Material& m = scene.material;
  // A calibrated scene scales the modulus the spring constants are identified from ([models.springs]).
  setup.youngs_modulus = m.youngs_modulus * (scene.springs ? scene.springs->stiffness_scale : 1.0);
  setup.poisson_ratio = m.poisson_ratio;
  setup.density = m.density;
  setup.damping = settings.damping.value_or(m.damping);
  setup.volume_term = settings.volume_term.value_or(true);
  setup.cells = settings.cells.value_or(setup.cells);
  setup.cell_size = settings.cell_size.value_or(0.0);
  setup.grasp_radius = settings.grasp_radius.value_or(0.0);
  setup.tearing = scene.phenomena.contains(Phenomenon::tearing);
  setup.tensile_limit = setup.tearing ? settings.tensile_limit.value_or(m.cohesive_strength) : 0.0;
  for (const Support& s : scene.supports) setup.supports.push_back({s.surface, s.kind == Support::Kind::sliding});
  for (const Tool& t : scene.tools) setup.styluses.push_back({t.trajectory.start, t.radius});

  auto model = std::make_unique<SpringNetworkModel>(mesh, setup);
  const SpringNetwork& net = model->network();
  const CellIdentification& id = model->identification();
  nlohmann::json p;
  p["integrator"] = std::string(to_string(setup.integrator));
  p["cells_per_side"] = setup.cells;
  p["cell_size_m"] = net.block.cell_size;
  p["block_origin_m"] = nlohmann::json::array({net.block.origin.x(), net.block.origin.y(), net.block.origin.z()});
  p["kept_cells"] = net.cell_count();
  p["nodes"] = net.node_count;
  p["spring_constants_N_per_m"] = {{"edge", id.stiffness.edge}, {"face_diagonal", id.stiffness.face_diagonal},
                                   {"body_diagonal", id.stiffness.body_diagonal}};
  p["stiffness_scale"] = scene.springs ? scene.springs->stiffness_scale : 1.0;
  p["volume_modulus_Pa"] = id.stiffness.volume_modulus;
  p["network_poisson_ratio"] = id.poisson_ratio;
  p["bulk_modulus_error"] = id.bulk_modulus_error;
  p["damping_time_s"] = net.damping_time;
  p["volume_term"] = id.stiffness.volume_modulus > 0.0;
  p["grasp_radius_m"] = setup.grasp_radius > 0.0 ? nlohmann::json(setup.grasp_radius) : nlohmann::json("tip radius + h/2");
  p["explicit_stability_limit_s"] = model->stability_limit();
  std::vector<int> attached;
  for (int t = 0; t < model->tool_count(); ++t) attached.push_back(model->attached_nodes(t));
  p["attached_nodes"] = attached;
  p["tearing"] = setup.tearing;
  if (setup.tearing) p["tensile_limit_Pa"] = setup.tensile_limit;
  return {std::move(model), std::move(p)};
}

} // namespace kerf

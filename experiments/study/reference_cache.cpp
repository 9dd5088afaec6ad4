#include "experiments/study/reference_cache.hpp"

#include "formats/profile/force_profile.hpp"
#include "experiments/models/run_model.hpp"
#include "experiments/records/content_hash.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "reference/load_path.hpp"
#include "reference/mpi_processes.hpp"


#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace kerf {

ReferenceRunSettings study_reference_settings(const StudyReferenceSpec& spec, const Scene& scene, int level,
                                              const std::vector<std::size_t>& sample_indices, LoadIncrement increment) {
  ReferenceRunSettings settings;
  settings.degree = spec.degree_of(scene.file.stem().string(), scene.geometry.element_degree);
  // Every level of a scene with a geometry is meshed anew (study_reference_scene); a ready .msh
  // can only be refined: level k >= 0 refines it k times.
  settings.refinements = scene.geometry.kind == SceneGeometry::Kind::msh ? std::max(level, 0) : 0;
  settings.sample_indices = sample_indices;
  settings.write_fields = false;
  settings.linear_solver = spec.linear_solver;
  settings.fracture = spec.fracture;
  settings.distribute = false; // one process per solve: the study spreads whole solves over its ranks
  // Adaptive sampling down to a travel tied to the scene's own element size h0 (the level's h
  // times 2^level for a scene meshed anew, a .msh scene's own), so every level of a scene has
  // the same least travel; half the increment halves it.
  const double h0 = scene.geometry.kind == SceneGeometry::Kind::msh ? scene.geometry.element_size
                                                                   : std::ldexp(scene.geometry.element_size, level);
  settings.adaptive_force_change = spec.adaptive;
  settings.adaptive_min_travel = study_min_travel_per_element * h0 * (increment == LoadIncrement::half ? 0.5 : 1.0);
  return settings;
}

Scene study_reference_scene(const Scene& scene, int level) {
  if (level < minimum_study_mesh_level)
    throw std::invalid_argument("scene " + scene.name + ": mesh level " + std::to_string(level) + " is below " +
                                std::to_string(minimum_study_mesh_level));
  Scene s = scene;
  // h_k = h 2^-k: level k is the geometry meshed anew at 2^-k h, every graded size (crack path,
  // grasp rim) scaled with it (SceneGeometry::nominal_element_size), so the levels are the same
  // graded mesh systematically refined. A scene whose mesh is a file has no geometry to mesh: its
  // levels k >= 0 refine that mesh k times (study_reference_settings), and k < 0 is refused.
  if (scene.geometry.kind == SceneGeometry::Kind::msh) {
    if (level < 0)
      throw std::invalid_argument("scene " + scene.name + ": mesh level " + std::to_string(level) +
                                  " needs its geometry meshed anew, and its mesh is the file " +
                                  scene.geometry.source.string() + "; use levels >= 0 (global refinements)");
    return s;
  }
  s.geometry.element_size = std::ldexp(scene.geometry.element_size, -level);
  return s;
}

double study_reference_element_size(const Scene& scene, int level) { return std::ldexp(scene.geometry.element_size, -level); }

namespace {

/// A number written so that any change of its value changes the text (17 significant digits).
std::string exact(double v) {
  char s[40];
  std::snprintf(s, sizeof s, "%.17g", v);
  return s;
}

std::string material_line(const Material& m) {
  return m.region + ": law " + material_law_name(m.law) + ", E " +
         exact(m.youngs_modulus) + ", nu " + exact(m.poisson_ratio) + ", rho " + exact(m.density) + ", J_c " +
         exact(m.fracture_toughness) + ", sigma_c " + exact(m.cohesive_strength) + ", mu " + exact(m.friction_coefficient) +
         ", eta " + exact(m.damping);
}

const char* solver_name(reference::LinearSolverChoice c) {
  switch (c) {
  case reference::LinearSolverChoice::automatic: return "automatic";
  case reference::LinearSolverChoice::direct: return "direct";
  case reference::LinearSolverChoice::iterative: return "iterative";
  }
  return "?";
}

const char* fracture_name(ReferenceFracture f) {
  switch (f) {
  case ReferenceFracture::automatic: return "automatic";
  case ReferenceFracture::off: return "off";
  case ReferenceFracture::on: return "on";
  }
  return "?";
}

} // namespace

ReferenceCacheKey reference_cache_key(const Scene& scene, const ReferenceRunSettings& settings, int solver_version) {
  // The scene: its file, the geometry file it meshes, and what a caller may have changed in
  // memory since reading it (materials, mesh size, the trajectory).
  const std::string scene_sha = file_sha256(scene.file);
  std::string text = "scene_file_sha256 = " + scene_sha + "\n";
  text += "geometry_file_sha256 = " + file_sha256(scene.geometry.source) + "\n";
  std::string parameters;
  for (const auto& [name, value] : scene.geometry.parameters) parameters += " " + name + "=" + exact(value);
  text += "geometry_parameters =" + parameters + "\n";
  text += "element_size = " + exact(scene.geometry.element_size) + "\n";
  // The parameters kerf derives for the reference's mesh from the scene (grasp discs, gradings):
  // a change of the rules that derive them changes the mesh.
  std::string derived;
  for (const auto& [name, value] : scene_mesh_parameters(scene, MeshPurpose::reference)) derived += " " + name + "=" + exact(value);
  text += "reference_mesh_parameters =" + derived + "\n";
  text += "material = " + material_line(scene.material) + "\n";
  for (const Material& layer : scene.layers) text += "layer = " + material_line(layer) + "\n";

  // The sampled trajectory at the solved samples (all of them when none are chosen): time and
  // position of every tool.
  const std::vector<SampledTrajectory> trajectories = sample_scene_trajectories(scene);
  std::string motion;
  std::size_t n = 0;
  for (const SampledTrajectory& t : trajectories) n = std::max(n, t.samples.size());
  std::vector<std::size_t> indices = settings.sample_indices;
  if (indices.empty())
    for (std::size_t k = 0; k < n; ++k) indices.push_back(k);
  for (std::size_t t = 0; t < trajectories.size(); ++t)
    for (std::size_t k : indices) {
      const auto& samples = trajectories[t].samples;
      const ToolState& s = samples[std::min(k, samples.size() - 1)];
      motion += std::to_string(t) + " " + exact(s.time) + " " + exact(s.position.x()) + " " + exact(s.position.y()) + " " +
                exact(s.position.z()) + "\n";
    }
  text += "trajectory_samples = " + std::to_string(indices.size()) + " of " + std::to_string(n) + "\n";
  text += "trajectory_sha256 = " + text_sha256(motion) + "\n";

  // The solver: what the settings choose, and the defaults run_reference keeps.
  const reference::SolverSettings defaults;
  text += "solver_version = " + std::to_string(solver_version) + "\n";
  text += "degree = " + std::to_string(settings.degree) + "\n";
  text += "adaptive_sampling = " + exact(settings.adaptive_force_change) + " " + exact(settings.adaptive_min_travel) + "\n";
  // The load path: the trajectory, through every vertex of the motion (reference_run.hpp).
  text += "load_path = trajectory vertices, tolerance " + exact(settings.vertex_tolerance) + "\n";
  text += "refinements = " + std::to_string(settings.refinements) + "\n";
  text += "linear_solver = " + std::string(solver_name(settings.linear_solver)) + "\n";
  text += "direct_dof_limit = " + std::to_string(defaults.direct_dof_limit) + "\n";
  text += "direct_factor_limit = " + exact(defaults.direct_factor_limit) + "\n";
  text += "iterative_tolerance = " + exact(defaults.iterative_tolerance) + "\n";
  text += "newton_relative_tolerance = " + exact(defaults.relative_tolerance) + "\n";
  text += "newton_absolute_tolerance = " + exact(defaults.absolute_tolerance) + "\n";
  text += "max_newton_iterations = " + std::to_string(defaults.max_newton_iterations) + "\n";
  text += "contact_penalty = " + (defaults.contact_penalty == 0.0 ? std::string("automatic") : exact(defaults.contact_penalty)) + "\n";
  text += "max_cutbacks = " + std::to_string(reference::LoadPathSettings{}.max_cutbacks) + "\n";
  text += "fracture = " + std::string(fracture_name(settings.fracture)) + "\n";
  // Distributed over N processes the solve sums in another order (round-off) and the linear solver
  // is MUMPS or a parallel GAMG: N is part of the key; not distributed, it is one process.
  const int processes = settings.distribute ? std::max(1, reference::mpirun_process_count()) : 1;
  text += "processes = " + std::to_string(processes) + "\n";

  ReferenceCacheKey key;
  key.text = text;
  key.directory = scene_sha.substr(0, 16) + "-p" + std::to_string(settings.degree) + "-L" +
                  std::to_string(settings.refinements) + "-n" + std::to_string(indices.size()) + "-" +
                  text_sha256(text).substr(0, 16);
  return key;
}

} // namespace kerf

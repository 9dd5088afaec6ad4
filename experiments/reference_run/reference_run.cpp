#include "experiments/reference_run/reference_run.hpp"

#include "experiments/reference_run/reference_checkpoint.hpp"
#include "experiments/records/content_hash.hpp"
#include "experiments/scene/scene_mesh.hpp"
#include "experiments/trajectory/trajectory.hpp"
#include "meshes/atomic_file.hpp"
#include "meshes/surface_mesh.hpp"
#include "reference/load_path.hpp"
#include "reference/mpi_processes.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <set>
#include <stdexcept>

namespace kerf {

namespace {

using reference::DisplacementBoundary;
using reference::FiniteStrainProblem;
using reference::LoadState;

reference::MaterialRegion region_of(const Material& m) {
  reference::MaterialRegion r;
  r.volume_group = m.region.empty() ? "body" : m.region;
  r.law = m.law; // the one MaterialLaw (meshes/material_law.hpp)
  r.youngs_modulus = m.youngs_modulus;
  r.poisson_ratio = m.poisson_ratio;
  r.density = m.density;
  r.damping = m.damping;
  return r;
}

/// Position on the sampled path at time t [s], linear between samples (uniform rate).
Eigen::Vector3d position_at(const std::vector<Eigen::Vector3d>& p, const std::vector<double>& times, double t) {
  if (p.size() == 1 || t <= times.front()) return p.front();
  if (t >= times.back()) return p.back();
  const auto hi = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const std::size_t lo = hi - 1;
  const double f = (t - times[lo]) / (times[hi] - times[lo]);
  return p[lo] + f * (p[hi] - p[lo]);
}

} // namespace

namespace {

/// Ties the sphere `tool` (sampled at `positions`) to the disc it grasps (paper 000 §2.1: the stylus
/// grasps the surface), the physical surface `grasp_surface` of the mesh (scene_mesh: a region of
/// the geometry, the same whatever the mesh): adds the tie group `tie_name` of its triangles and
/// the prescribed displacement u = p(λ T) − p(0) (the tool displacement since its start, λ the load
/// factor) to `p` — or, with a grasp stiffness k, the elastic foundation t = k (d − u) towards that
/// displacement d — and returns the coupling. A grasping stylus must start touching the body.
ReferenceToolCoupling tie_stylus(const Scene& scene, const TetMesh& mesh, const Tool& tool,
                                 const std::vector<Eigen::Vector3d>& positions, const std::vector<double>& times,
                                 const std::string& grasp_surface, const std::string& tie_name, FiniteStrainProblem& p) {
  const SurfaceQuery surface(boundary_surface(mesh));
  const SurfaceQuery::Closest first = surface.closest_point(positions.front());
  if (std::abs(first.signed_distance - tool.radius) > 0.05 * tool.radius)
    throw std::invalid_argument("reference: scene '" + scene.name + "' (" + scene.file.string() + "): stylus '" + tool.name +
                                "' grasps the surface (grasp_radius) but does not start touching it: its tip centre is " +
                                std::to_string(first.signed_distance * 1e3) + " mm from the surface, expected its radius " +
                                std::to_string(tool.radius * 1e3) + " mm");
  ReferenceToolCoupling c;
  c.kind = ReferenceToolCoupling::Kind::tied;
  c.contact_point = first.point;
  const SurfaceGroup* grasp = mesh.find_surface_group(grasp_surface);
  if (grasp == nullptr)
    throw std::invalid_argument("reference: scene '" + scene.name + "': the mesh has no surface '" + grasp_surface +
                                "' for the disc stylus '" + tool.name + "' grasps (mesh the scene with scene_mesh)");
  for (Eigen::Index f = 0; f < grasp->triangles.rows(); ++f) c.tied_triangles.push_back(static_cast<int>(f));
  SurfaceGroup tie = *grasp;
  tie.name = tie_name;
  std::set<int> nodes;
  for (Eigen::Index f = 0; f < tie.triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) nodes.insert(tie.triangles(f, k));
  c.tied_nodes = nodes.size();
  p.mesh.surface_groups.push_back(std::move(tie));

  // u = p(λ T) − p(0): the tool displacement since contact, λ the load factor.
  auto path = std::make_shared<const std::vector<Eigen::Vector3d>>(positions);
  auto at = std::make_shared<const std::vector<double>>(times);
  const double T = times.back();
  auto tool_displacement = [path, at, T](const Eigen::Vector3d&, double load) -> Eigen::Vector3d {
    return position_at(*path, *at, load * T) - path->front();
  };
  if (tool.grasp_stiffness) {
    // A compliant grasp: the disc is held to the tool by an elastic layer, t = k (d − u).
    c.grasp_stiffness = *tool.grasp_stiffness;
    c.foundation = static_cast<int>(p.foundations.size());
    // The layer is stiffest under the tip's centre and ends at the rim: k(r) = k (1 − r²/R²), r the
    // distance from the grasp centre, R the grasp radius, so the traction on the body falls
    // continuously to zero at the rim (a uniform layer's traction step there concentrates the stress
    // into a fold of the free surface beside the rim that no mesh resolves).
    p.foundations.push_back({tie_name, *tool.grasp_stiffness, tool_displacement,
                             reference::ElasticFoundation::tapered_disc(c.contact_point, *tool.grasp_radius)});
    return c;
  }
  c.boundary = static_cast<int>(p.displacement_boundaries.size());
  p.displacement_boundaries.push_back({tie_name, DisplacementBoundary::Kind::prescribed, tool_displacement, {true, true, true}});
  return c;
}

} // namespace

ReferenceProblem reference_problem(const Scene& scene, const TetMesh& mesh) {
  if (scene.tools.empty()) throw std::invalid_argument("reference: scene '" + scene.name + "' has no tool");
  ReferenceProblem out;
  FiniteStrainProblem& p = out.problem;
  p.mesh = mesh;
  // Layers first: the solver takes the first region that holds a tetrahedron.
  for (const Material& layer : scene.layers) p.materials.push_back(region_of(layer));
  Material body = scene.material;
  body.region = "body";
  p.materials.push_back(region_of(body));
  for (const Support& s : scene.supports)
    p.displacement_boundaries.push_back({s.surface,
                                         s.kind == Support::Kind::bonded ? DisplacementBoundary::Kind::bonded
                                                                         : DisplacementBoundary::Kind::sliding,
                                         {},
                                         {true, true, true}});

  // Every tool on one time line (the load factor of sample k is t_k / T for all of them).
  for (const Tool& tool : scene.tools) {
    const SampledTrajectory path = sample(tool.trajectory);
    if (path.samples.empty()) throw std::invalid_argument("reference: tool '" + tool.name + "' has an empty trajectory");
    ReferenceTool rt;
    rt.name = tool.name;
    std::vector<double> times;
    for (const ToolState& s : path.samples) {
      rt.positions.push_back(s.position);
      times.push_back(s.time);
    }
    if (out.tools.empty()) {
      out.times = times;
    } else {
      bool same = times.size() == out.times.size();
      for (std::size_t k = 0; same && k < times.size(); ++k) same = std::abs(times[k] - out.times[k]) <= 1e-9;
      if (!same)
        throw std::invalid_argument("reference: scene '" + scene.name + "': tool '" + tool.name +
                                    "' is sampled at other times than tool '" + out.tools.front().name +
                                    "'; the reference needs one time line (same rate and duration)");
    }
    out.tools.push_back(std::move(rt));
  }

  const bool several = scene.tools.size() > 1;
  int grasping = 0; // the grasping styluses so far: the k-th grasps the surface "grasp<k>" (scene_mesh.hpp)
  for (std::size_t j = 0; j < scene.tools.size(); ++j) {
    const Tool& tool = scene.tools[j];
    ReferenceTool& rt = out.tools[j];
    if (tool.kind == Tool::Kind::blade) {
      if (several)
        throw std::invalid_argument("reference: scene '" + scene.name + "' has " + std::to_string(scene.tools.size()) +
                                    " tools and '" + tool.name + "' is a blade: several tools are coupled only as "
                                    "styluses that grasp the surface (tied)");
      reference::RigidToolShape shape;
      shape.kind = reference::RigidToolShape::Kind::wedge;
      shape.blade = tool.blade;
      p.tool = shape;
      continue;
    }
    const std::string tie_name = several ? "stylus_tie_" + tool.name : "stylus_tie";
    if (tool.grasp_radius) {
      rt.coupling = tie_stylus(scene, mesh, tool, rt.positions, out.times, grasp_surface_name(++grasping), tie_name, p);
      continue;
    }
    if (several)
      throw std::invalid_argument("reference: scene '" + scene.name + "': stylus '" + tool.name +
                                  "' does not grasp the surface (no grasp_radius); several tools are coupled only "
                                  "as styluses that grasp it");
    // A sphere that presses: penalty contact.
    reference::RigidToolShape shape;
    shape.kind = reference::RigidToolShape::Kind::sphere;
    shape.radius = tool.radius;
    p.tool = shape;
  }
  return out;
}

namespace {

// ---------------------------------------------------------------------------------- fields
/// fields/step_NNNN.vtu, or the .pvtu record of the pieces of a distributed run.
std::string step_name(std::size_t k, bool pieces) {
  char buf[32];
  std::snprintf(buf, sizeof buf, pieces ? "step_%04zu.pvtu" : "step_%04zu.vtu", k);
  return buf;
}

/// dir/fields.pvd: the ParaView collection of the .vtu (serial) or .pvtu (distributed: `pieces`)
/// of the first `count` solved samples.
void write_pvd(const std::filesystem::path& dir, const std::vector<double>& times, std::size_t count, bool pieces) {
  write_atomically(dir / "fields.pvd", [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("reference: cannot write " + tmp.string());
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "  <Collection>\n";
    out.precision(17);
    for (std::size_t k = 0; k < count; ++k)
      out << "    <DataSet timestep=\"" << times[k] << "\" group=\"\" part=\"0\" file=\"fields/" << step_name(k, pieces)
          << "\"/>\n";
    out << "  </Collection>\n</VTKFile>\n";
    out.flush();
    if (!out) throw std::runtime_error("reference: writing " + tmp.string() + " failed");
  });
}

nlohmann::json vec_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

} // namespace

ForceProfile run_reference(const Scene& scene, const TetMesh& mesh, const ReferenceRunSettings& settings,
                           const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  using Clock = std::chrono::steady_clock;
  const auto wall_begin = Clock::now();
  if (settings.checkpoint_every < 1)
    throw std::invalid_argument("reference: checkpoint_every must be >= 1, got " + std::to_string(settings.checkpoint_every));

  ReferenceProblem rp = reference_problem(scene, mesh);
  const CrackPathInfo crack = add_crack_path(scene, rp.problem, settings.fracture, settings.refinements,
                                              settings.cohesive_viscous_time);
  // Kelvin–Voigt damping: the dynamic step's, when asked for (the quasi-static solve has no rate).
  bool damped = false;
  for (reference::MaterialRegion& region : rp.problem.materials) {
    if (!(settings.dynamic && settings.damping)) region.damping = 0.0;
    damped = damped || region.damping > 0.0;
  }
  if (!(settings.interface_error_relative >= 0.0) || !(settings.interface_error_floor >= 0.0) ||
      !std::isfinite(settings.interface_error_relative) || !std::isfinite(settings.interface_error_floor))
    throw std::invalid_argument("reference: the interface energy tolerances must be finite and >= 0, got " +
                                std::to_string(settings.interface_error_relative) + " and " +
                                std::to_string(settings.interface_error_floor));
  if (!crack.warning.empty()) std::fprintf(stderr, "reference %s: warning: %s\n", scene.name.c_str(), crack.warning.c_str());
  // The crack extent is measured along the blade's cutting direction (c of paper 001 Fig. 3), or
  // downwards from the grasped top for a tear.
  const Eigen::Vector3d crack_direction =
      scene.tools.front().kind == Tool::Kind::blade ? scene.tools.front().blade.cutting_direction : Eigen::Vector3d(0, 0, -1);
  const std::size_t n = rp.times.size();
  std::vector<std::size_t> indices = settings.sample_indices;
  if (indices.empty())
    for (std::size_t k = 0; k < n; ++k) indices.push_back(k);
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= n || (i > 0 && indices[i] <= indices[i - 1]))
      throw std::invalid_argument("reference: sample indices must be ascending and below " + std::to_string(n) +
                                  " (the trajectory's sample count); entry " + std::to_string(i) + " is " +
                                  std::to_string(indices[i]));
  const double T = rp.times.back();
  // The penalty tool, if any, is the scene's only tool (reference_problem).
  auto load_of = [&](std::size_t k) {
    return LoadState{T > 0.0 ? rp.times[k] / T : 0.0, rp.tools.front().positions[k], rp.times[k]};
  };
  auto is_tied = [](const ReferenceTool& t) { return t.coupling.kind == ReferenceToolCoupling::Kind::tied; };

  reference::SolverSettings solver_settings;
  solver_settings.degree = settings.degree;
  solver_settings.refinements = settings.refinements;
  solver_settings.linear_solver = settings.linear_solver;
  solver_settings.distribute = settings.distribute;
  solver_settings.residual_fault = settings.residual_fault;
  solver_settings.dynamic = settings.dynamic;
  reference::FiniteStrainSolver solver(rp.problem, solver_settings);
  // Under mpirun every process runs this function; rank 0 writes the files and the progress. A
  // solver that is not distributed (settings.distribute false: e.g. one of the solves `mpirun kerf
  // study` spreads over its ranks) is its own process's run, and that process writes.
  const bool writer = solver.process_count() == 1 || reference::mpi_processes().rank == 0;
  const bool pieces = solver.process_count() > 1;

  const std::string sha = file_sha256(scene.file);
  const fs::path checkpoint_file = dir / "checkpoint.bin";
  ReferenceCheckpoint cp;
  cp.scene_sha256 = sha;
  cp.degree = settings.degree;
  cp.refinements = settings.refinements;
  cp.processes = solver.process_count();
  cp.dynamic = settings.dynamic;
  cp.damped = damped;
  cp.indices = indices;
  cp.last = load_of(0);
  std::optional<std::size_t> resumed_from;
  if (settings.resume && fs::exists(checkpoint_file)) {
    ReferenceCheckpoint saved = read_reference_checkpoint(checkpoint_file);
    // An adaptive run's list grows by the samples it inserted: every requested one must be in it.
    const bool same_samples = settings.adaptive_force_change > 0.0
                                  ? std::includes(saved.indices.begin(), saved.indices.end(), indices.begin(), indices.end())
                                  : saved.indices == indices;
    if (saved.scene_sha256 != sha || saved.degree != settings.degree || saved.refinements != settings.refinements ||
        !same_samples || saved.processes != cp.processes)
      throw std::runtime_error("reference: " + checkpoint_file.string() +
                               " is from a different run (scene file, degree, refinements, samples or MPI process "
                               "count differ; it was written by " +
                               std::to_string(saved.processes) + " process(es), this run has " +
                               std::to_string(cp.processes) + ")");
    if (saved.dynamic != cp.dynamic)
      throw std::runtime_error("reference: " + checkpoint_file.string() + " is from a " +
                               (saved.dynamic ? "dynamic" : "quasi-static") + " run and this run is " +
                               (cp.dynamic ? "dynamic (--dynamic)" : "quasi-static") +
                               ": resume with the same time integration");
    if (saved.damped != cp.damped)
      throw std::runtime_error("reference: " + checkpoint_file.string() + " is from a run " +
                               (saved.damped ? "with" : "without") + " the scene's Kelvin-Voigt damping and this run is " +
                               (cp.damped ? "damped" : "undamped (--no-damping, or a checkpoint from before the damping)") +
                               ": resume with the same damping");
    solver.set_state(saved.state);
    cp = std::move(saved);
    indices = cp.indices; // an adaptive run continues with the samples it had inserted
    cp.last.time = cp.last.load_factor * T; // the load factor is t/T (load_of), also between samples
    resumed_from = cp.solved;
    if (writer)
      std::fprintf(stderr, "reference %s: resuming after sample %zu/%zu from %s\n", scene.name.c_str(), cp.solved,
                   indices.size(), checkpoint_file.c_str());
  } else if (settings.resume && writer) {
    std::fprintf(stderr, "reference %s: no checkpoint in %s, starting from the beginning\n", scene.name.c_str(),
                 dir.c_str());
  }
  if (settings.write_fields) fs::create_directories(dir / "fields");

  reference::LoadPathSettings path_settings;
  if (settings.dynamic && crack.active) {
    // The interface energy control (reference/load_path.hpp): |e| <= rel ΔD + floor J_c A per step.
    path_settings.interface_error_relative = settings.interface_error_relative;
    path_settings.interface_error_absolute =
        settings.interface_error_floor * scene.material.fracture_toughness * crack.interface_area;
  }
  // In an optional: adaptive sampling rebuilds it at an earlier converged state (it holds the solver).
  std::optional<reference::LoadPath> load_path;
  load_path.emplace(solver, cp.last, path_settings);
  load_path->set_interface_step(cp.interface_step);
  std::vector<double> solved_times;
  for (std::size_t k : indices) solved_times.push_back(rp.times[k]);
  std::string stop;
  const auto run_begin = Clock::now();
  const std::size_t first = cp.solved;
  int newton_total = 0;
  for (const auto& s : cp.samples) newton_total += s.at("newton_iterations").get<int>();
  // Energy bookkeeping and the interface state of the previous sample (for the modes), restored
  // from the last sample record on resume.
  EnergyBookkeeping energy;
  reference::CohesiveSampleState previous_interface;
  if (!cp.samples.empty() && cp.samples.back().contains("energy")) {
    energy = EnergyBookkeeping::from_json(cp.samples.back().at("energy"));
    previous_interface = {cp.samples.back().at("contact_points").get<int>() > 0, cp.samples.back().at("energy").at("failed_area_m2").get<double>()};
  }
  // Adaptive sampling: the state before each sample, to undo it when an intermediate sample is due.
  const bool adaptive = settings.adaptive_force_change > 0.0;
  if (adaptive && !(settings.adaptive_min_travel > 0.0 && std::isfinite(settings.adaptive_force_change)))
    throw std::invalid_argument("reference: adaptive sampling needs a force change fraction and a minimum travel > 0");
  double peak_force = 0.0;
  for (const ProfileRow& r : cp.profile.rows) peak_force = std::max(peak_force, r.force.norm());
  auto travel_between = [&](std::size_t a, std::size_t b) {
    double d = 0.0;
    for (const ReferenceTool& tool : rp.tools) d = std::max(d, (tool.positions[b] - tool.positions[a]).norm());
    return d;
  };
  std::size_t inserted = 0;
  for (std::size_t i = cp.solved; i < indices.size(); ++i) {
    const std::size_t k = indices[i];
    reference::LoadStepReport step;
    const LoadState load = load_of(k);
    std::vector<double> state_before;
    LoadState load_before{};
    double interface_step_before = 0.0;
    if (adaptive && i > 0) {
      state_before = load_path->last_converged_state();
      load_before = load_path->last_converged_load();
      interface_step_before = load_path->interface_step();
    }
    try {
      step = load_path->advance({load, k, rp.times[k]});
    } catch (const reference::LoadPathError& e) {
      stop = e.what();
      if (writer) std::fprintf(stderr, "reference %s: stopped: %s\n", scene.name.c_str(), e.what());
      break;
    }
    const double cost = step.seconds;
    nlohmann::json reactions = nlohmann::json::object();
    for (const reference::BoundaryReaction& b : step.equilibrium.boundary_reactions)
      reactions[b.surface] = vec_json(b.force + Eigen::Vector3d::Zero());
    // The force on each tool: a tied stylus's is the reaction of its tie (the force of the body on
    // the tied nodes); a pressing tool's is the contact resultant. The supports carry the rest.
    std::vector<Eigen::Vector3d> tool_forces, tool_positions, forces_on_body;
    Eigen::Vector3d support = step.support_reaction;
    bool touching = false;
    nlohmann::json forces_json = nlohmann::json::object();
    for (const ReferenceTool& tool : rp.tools) {
      Eigen::Vector3d f = step.tool_force;
      bool touches = step.equilibrium.contact_points + step.equilibrium.edge_contact_points > 0;
      if (is_tied(tool) && tool.coupling.foundation >= 0) {
        // A compliant grasp: the force of the body on its layer, −∫ k (d − u) dA (not a support).
        f = step.equilibrium.foundation_forces.at(static_cast<std::size_t>(tool.coupling.foundation));
        touches = f.norm() > 0.0;
      } else if (is_tied(tool)) {
        f = step.equilibrium.boundary_reactions.at(static_cast<std::size_t>(tool.coupling.boundary)).force;
        support -= f;
        touches = f.norm() > 0.0;
      }
      f += Eigen::Vector3d::Zero(); // −0 → 0 in the CSV
      touching = touching || touches;
      tool_forces.push_back(f);
      tool_positions.push_back(tool.positions[k]);
      forces_on_body.push_back(-f);
      forces_json[tool.name] = vec_json(f);
    }
    const reference::CohesiveSampleState interface{touching, step.equilibrium.cohesive.failed_area};
    InteractionMode mode = touching ? InteractionMode::deformation_1 : InteractionMode::no_contact;
    double crack_extent = 0.0;
    if (crack.active) {
      mode = reference::reference_mode(previous_interface, interface);
      crack_extent = solver.crack_extent(crack_direction);
    }
    if (adaptive && i > 0) {
      // An event or a fast change between the previous sample and this one: undo this sample and
      // solve the one half way first (while the tool travels more than the minimum between them).
      const std::size_t previous = indices[i - 1];
      const std::size_t n_tools = rp.tools.size();
      const std::size_t last = cp.profile.rows.size() - n_tools; // the previous sample's first row
      const ProfileRow& before = cp.profile.rows[last];
      // A fast change is a curve that leaves the straight line through the two samples before:
      // |F_k − (F_{k−1} + (F_{k−1} − F_{k−2}) (t_k − t_{k−1}) / (t_{k−1} − t_{k−2}))| beyond the
      // fraction of the largest force (a ramp from zero is straight: it inserts nothing).
      double deviation = 0.0;
      if (i > 1) {
        const std::size_t older = last - n_tools;
        const double t0 = cp.profile.rows[older].t, t1 = before.t, t2 = rp.times[k];
        const double slope = t1 > t0 ? (t2 - t1) / (t1 - t0) : 0.0;
        for (std::size_t j = 0; j < n_tools; ++j) {
          const Eigen::Vector3d& f0 = cp.profile.rows[older + j].force;
          const Eigen::Vector3d& f1 = cp.profile.rows[last + j].force;
          deviation = std::max(deviation, (tool_forces[j] - (f1 + (f1 - f0) * slope)).norm());
        }
      }
      const double scale = std::max({peak_force, tool_forces.front().norm(), before.force.norm()});
      const bool event = mode != before.mode;
      const bool fast = deviation > settings.adaptive_force_change * scale;
      if ((event || fast) && k > previous + 1 && travel_between(previous, k) > settings.adaptive_min_travel) {
        cp.solve_seconds += step.seconds; // the undone solve's cost is spent all the same
        newton_total += step.newton_iterations;
        solver.set_state(state_before);
        load_path.emplace(solver, load_before, path_settings);
        load_path->set_interface_step(interface_step_before);
        indices.insert(indices.begin() + static_cast<std::ptrdiff_t>(i), previous + (k - previous) / 2);
        solved_times.insert(solved_times.begin() + static_cast<std::ptrdiff_t>(i), rp.times[indices[i]]);
        cp.indices = indices;
        ++inserted;
        --i; // the loop's ++i comes back to position i: the inserted sample
        continue;
      }
    }
    for (const Eigen::Vector3d& f : tool_forces) peak_force = std::max(peak_force, f.norm());
    previous_interface = interface;
    energy.add_sample(tool_positions, forces_on_body, solver.strain_energy(), step.equilibrium.cohesive,
                      step.equilibrium.contact_energy + step.equilibrium.foundation_energy, solver.kinetic_energy(), solver.damping_dissipation());
    for (std::size_t j = 0; j < rp.tools.size(); ++j) {
      ProfileRow row;
      row.t = rp.times[k];
      row.tool = rp.tools[j].name;
      row.position = tool_positions[j];
      row.force = tool_forces[j];
      row.mode = mode;
      row.crack_extent = crack_extent;
      row.cost_s = cost; // one solve for all the tools
      cp.profile.rows.push_back(row);
    }
    const Eigen::Vector3d& tool_force = tool_forces.front();
    cp.samples.push_back({{"index", k},
                          {"t_s", rp.times[k]},
                          {"newton_iterations", step.newton_iterations},
                          {"cutbacks", step.cutbacks},
                          {"increments", step.increments},
                          {"interface_rejections", step.interface_rejections},
                          {"interface_tolerance_exceeded", step.interface_tolerance_exceeded},
                          {"residual_N", step.final_residual},
                          {"seconds", cost},
                          {"tool_force_N", vec_json(tool_force)},
                          {"tool_forces_N", forces_json},
                          {"support_reaction_N", vec_json(support)},
                          {"boundary_reactions_N", reactions},
                          {"force_imbalance_N", vec_json(step.equilibrium.force_imbalance)},
                          {"contact_points", step.equilibrium.contact_points},
                          {"edge_contact_points", step.equilibrium.edge_contact_points},
                          {"edge_contact_length_m", step.equilibrium.edge_contact_length},
                          {"energy", energy.to_json()}});
    cp.solve_seconds += cost;
    newton_total += step.newton_iterations;
    cp.solved = i + 1;
    cp.last = load_path->last_converged_load();
    cp.interface_step = load_path->interface_step();
    if (settings.write_fields) {
      if (pieces)
        solver.write_fields(dir / "fields" / step_name(i, true), load); // collective; atomic inside
      else if (writer)
        write_atomically(dir / "fields" / step_name(i, false), [&](const fs::path& tmp) { solver.write_fields(tmp, load); });
      if (writer) write_pvd(dir, solved_times, cp.solved, pieces);
    }
    if (cp.solved % static_cast<std::size_t>(settings.checkpoint_every) == 0) {
      cp.state = load_path->last_converged_state();
      if (writer) write_reference_checkpoint(cp, checkpoint_file);
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - run_begin).count();
    const double eta = elapsed / static_cast<double>(cp.solved - first) * static_cast<double>(indices.size() - cp.solved);
    if (writer)
      std::fprintf(stderr,
                   "reference %s: sample %zu/%zu (#%zu, t = %.4f s) tool (%.3f, %.3f, %.3f) mm, %d Newton its, "
                   "%d cut-backs, |R| %.2e N, |F| %.4g N, elapsed %.1f s, ETA %.1f s\n",
                   scene.name.c_str(), cp.solved, indices.size(), k, rp.times[k], tool_positions.front().x() * 1e3,
                   tool_positions.front().y() * 1e3, tool_positions.front().z() * 1e3, step.newton_iterations, step.cutbacks,
                   step.final_residual, tool_force.norm(), elapsed, eta);
  }
  if (!stop.empty()) {
    cp.state = load_path->last_converged_state();
    if (writer) write_reference_checkpoint(cp, checkpoint_file); // the last converged state, saved
  }

  nlohmann::json m;
  m["kerf_version"] = KERF_VERSION;
  m["git_commit"] = KERF_GIT_COMMIT;
  m["scene"] = {{"name", scene.name},
                {"file", fs::absolute(scene.file).string()},
                {"sha256", sha},
                {"phenomena", scene.phenomena.to_string()}};
  m["model"] = {{"name", "reference"},
                {"parameters",
                 {{"degree", settings.degree},
                  {"refinements", settings.refinements},
                  {"samples_requested", indices.size()},
                  {"checkpoint_every", settings.checkpoint_every},
                  {"time_integration", settings.dynamic ? "dynamic: Newmark average acceleration (beta = 1/4, gamma = 1/2), consistent mass"
                                                        : "quasi-static"},
                  {"kelvin_voigt_damping", damped},
                  {"interface_error_relative", path_settings.interface_error_relative},
                  {"interface_error_absolute_J", path_settings.interface_error_absolute},
                  {"write_fields", settings.write_fields}}}};
  m["mesh"] = {{"nodes", mesh.nodes.rows()},
               {"tetrahedra", mesh.tets.rows()},
               {"element_size_m", scene.geometry.element_size},
               {"source", scene.geometry.source.string()}};
  nlohmann::json solver_json = {{"dofs", solver.dof_count()},
                                {"cells", solver.cell_count()},
                                {"linear_solver", solver.linear_solver_name()},
                                {"mpi_processes", solver.process_count()},
                                {"relative_tolerance", solver_settings.relative_tolerance},
                                {"max_newton_iterations", solver_settings.max_newton_iterations},
                                {"max_cutbacks", reference::LoadPathSettings{}.max_cutbacks},
                                {"tool_coupling", is_tied(rp.tools.front()) ? "tied" : "penalty"}};
  nlohmann::json tools_json = nlohmann::json::array();
  for (const ReferenceTool& tool : rp.tools) {
    nlohmann::json t = {{"name", tool.name}, {"coupling", is_tied(tool) ? "tied" : "penalty"}};
    if (is_tied(tool)) {
      t["tied_nodes"] = tool.coupling.tied_nodes;
      t["tied_triangles"] = tool.coupling.tied_triangles.size();
      if (tool.coupling.foundation >= 0) t["grasp_stiffness_N_per_m3"] = tool.coupling.grasp_stiffness;
      t["contact_point_m"] = vec_json(tool.coupling.contact_point);
    }
    tools_json.push_back(t);
  }
  solver_json["tools"] = tools_json;
  if (adaptive)
    solver_json["adaptive_sampling"] = {{"force_change", settings.adaptive_force_change},
                                        {"min_travel_m", settings.adaptive_min_travel},
                                        {"requested_samples", settings.sample_indices.size()},
                                        {"solved_samples", indices.size()},
                                        {"inserted_this_run", inserted}};
  if (is_tied(rp.tools.front())) { // the first tool's, as before several tools were coupled
    solver_json["tied_nodes"] = rp.tools.front().coupling.tied_nodes;
    solver_json["tied_triangles"] = rp.tools.front().coupling.tied_triangles.size();
    solver_json["contact_point_m"] = vec_json(rp.tools.front().coupling.contact_point);
  } else {
    solver_json["contact_penalty_Pa_per_m"] = solver.contact_penalty();
  }
  m["solver"] = solver_json;
  m["timings"] = {{"wall_s", std::chrono::duration<double>(Clock::now() - wall_begin).count()},
                  {"solve_total_s", cp.solve_seconds},
                  {"samples_solved", cp.solved}};
  m["newton_iterations_total"] = newton_total;
  m["energy"] = energy.to_json();
  m["fracture"] = crack.active ? nlohmann::json{{"cohesive_law", "bilinear (Camacho-Ortiz effective opening), reference/cohesive/cohesive_law.hpp"},
                                                {"cohesive_strength_Pa", scene.material.cohesive_strength},
                                                {"fracture_toughness_J_per_m2", scene.material.fracture_toughness},
                                                {"interface_triangles", crack.interface_triangles},
                                                {"cohesive_zone_length_m", crack.zone_length},
                                                {"elements_in_zone", crack.elements_in_zone},
                                                {"viscous_time_s", settings.cohesive_viscous_time},
                                                {"viscosity_Pa_s_per_m", crack.viscosity},
                                                {"interface_area_m2", crack.interface_area},
                                                {"warning", crack.warning}}
                               : nlohmann::json(nullptr);
  m["samples"] = cp.samples;
  m["stopped"] = stop.empty() ? nlohmann::json(nullptr) : nlohmann::json(stop);
  m["resumed_after_sample"] = resumed_from ? nlohmann::json(*resumed_from) : nlohmann::json(nullptr);
  if (writer) {
    write_profile_csv(cp.profile, dir / "profile.csv");
    write_manifest(m, dir / "manifest.json");
  }
  reference::wait_for_processes(); // the files are in place when any process returns
  return cp.profile;
}

} // namespace kerf

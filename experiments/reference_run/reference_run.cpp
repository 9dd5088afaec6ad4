#include "experiments/reference_run/reference_run.hpp"

#include "experiments/reference_run/reference_checkpoint.hpp"
#include "experiments/records/content_hash.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "formats/trajectory/trajectory_vertices.hpp"
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
#include <iterator>
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

namespace {

// ------------------------------------------------------------------------- the load path's targets
/// Why a trajectory sample is a load of the run (the manifest's `load` of each sample).
enum class LoadReason { requested, vertex, inserted };

const char* load_reason_name(LoadReason r) {
  switch (r) {
  case LoadReason::requested: return "requested";
  case LoadReason::vertex: return "vertex";
  case LoadReason::inserted: return "inserted";
  }
  return "?";
}

/// The vertices of the tools' common motion (formats/trajectory/trajectory_vertices.hpp).
std::vector<std::size_t> motion_vertices(const ReferenceProblem& rp, double tolerance) {
  std::vector<SampledTrajectory> motions;
  for (const ReferenceTool& tool : rp.tools) {
    SampledTrajectory m;
    for (std::size_t k = 0; k < rp.times.size(); ++k) {
      ToolState s;
      s.time = rp.times[k];
      s.position = tool.positions[k];
      m.samples.push_back(s);
    }
    motions.push_back(std::move(m));
  }
  return trajectory_vertices(motions, tolerance);
}

/// The loads of a run: the requested output samples and every vertex of the motion up to the last
/// of them (a run asked to stop early, `kerf reference --until`, ends there), ascending.
std::vector<std::size_t> planned_loads(const std::vector<std::size_t>& requested, const std::vector<std::size_t>& vertices) {
  std::vector<std::size_t> out;
  const auto end = requested.empty() ? vertices.begin() : std::upper_bound(vertices.begin(), vertices.end(), requested.back());
  std::set_union(requested.begin(), requested.end(), vertices.begin(), end, std::back_inserter(out));
  return out;
}

/// A portable path for a manifest: relative to the working directory when the file lies under it
/// (a study run from the repository root writes `experiments/scenes/…`), else as it is.
std::string portable_path(const std::filesystem::path& p) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path base = fs::current_path(error);
  if (error) return p.string();
  const fs::path relative = fs::absolute(p, error).lexically_relative(base);
  if (error || relative.empty() || *relative.begin() == "..") return p.string();
  return relative.string();
}

/// The forces and state of one solved sample, as the profile and the manifest record them.
struct SolvedSample {
  std::vector<Eigen::Vector3d> tool_forces, tool_positions;
  Eigen::Vector3d support = Eigen::Vector3d::Zero();
  nlohmann::json forces_json = nlohmann::json::object();
  nlohmann::json reactions = nlohmann::json::object();
  reference::CohesiveSampleState interface;
  InteractionMode mode = InteractionMode::no_contact;
  double crack_extent = 0.0;
};

/// run_reference's steps (reference_run.hpp) over the state they share: the problem, the solver,
/// the load path along the trajectory, the checkpoint that holds what is solved so far, and the
/// bookkeeping the manifest reports. run() is the driver; each step below is one idea of it.
class TrajectorySolve {
public:
  TrajectorySolve(const Scene& scene, const TetMesh& mesh, const ReferenceRunSettings& settings, std::filesystem::path dir);
  ReferenceResult run();

private:
  void plan();
  void resume_from_checkpoint();
  reference::LoadPathSettings load_path_settings() const;
  void start_load_path(const LoadState& from, double interface_step);
  /// The load at time t on the trajectory: load factor t/T, the pressing tool where it is at t.
  LoadState load_at(double t) const;
  SolvedSample forces_of(const reference::LoadStepReport& step, std::size_t k) const;
  /// Adaptive sampling: whether sample `i` (just solved as `sample`) leaves too fast a change behind
  /// it, so that the sample half way back must be solved first.
  bool needs_sample_before(std::size_t i, const SolvedSample& sample) const;
  void undo_and_insert_before(std::size_t i, const reference::LoadStepReport& step);
  void record(std::size_t i, const reference::LoadStepReport& step, const SolvedSample& sample);
  void write_fields_and_checkpoint(std::size_t i, const LoadState& load);
  void print_progress(std::size_t k, const reference::LoadStepReport& step, const SolvedSample& sample) const;
  LoadReason reason_of(std::size_t k) const;
  nlohmann::json manifest(double wall_seconds) const;
  nlohmann::json solver_record() const;    ///< the manifest's "solver": size, linear solver, tools, load path
  nlohmann::json load_path_record() const; ///< "solver" / "load_path": the loads planned and solved, by reason
  nlohmann::json fracture_record() const;  ///< "fracture": the cohesive interface, or null
  [[nodiscard]] bool is_tied(const ReferenceTool& t) const { return t.coupling.kind == ReferenceToolCoupling::Kind::tied; }

  const Scene& m_scene;
  const TetMesh& m_mesh;
  const ReferenceRunSettings& m_settings;
  const std::filesystem::path m_dir;
  ReferenceProblem m_problem;
  CrackPathInfo m_crack;
  bool m_damped = false;
  Eigen::Vector3d m_crack_direction = -Eigen::Vector3d::UnitZ();
  double m_duration = 0.0; ///< T [s], the trajectory's duration
  std::vector<std::size_t> m_requested, m_vertices;
  std::vector<std::size_t> m_indices; ///< the loads to solve: requested ∪ vertices (∪ inserted as they come)
  reference::SolverSettings m_solver_settings;
  std::unique_ptr<reference::FiniteStrainSolver> m_solver;
  bool m_writer = true, m_pieces = false;
  std::string m_sha;
  std::filesystem::path m_checkpoint_file;
  ReferenceCheckpoint m_cp;
  std::optional<std::size_t> m_resumed_from;
  std::optional<reference::LoadPath> m_load_path;
  std::vector<double> m_solved_times;
  std::string m_stop;
  std::size_t m_first = 0; ///< samples solved when this run started (after a resume)
  int m_newton_total = 0;
  EnergyBookkeeping m_energy;
  reference::CohesiveSampleState m_previous_interface;
  double m_peak_force = 0.0;
  std::size_t m_inserted = 0;
  std::vector<double> m_state_before; ///< adaptive sampling: the solver state before the sample being solved
  LoadState m_load_before{};
  double m_interface_step_before = 0.0;
  std::chrono::steady_clock::time_point m_begin;
};

TrajectorySolve::TrajectorySolve(const Scene& scene, const TetMesh& mesh, const ReferenceRunSettings& settings,
                                 std::filesystem::path dir)
    : m_scene(scene), m_mesh(mesh), m_settings(settings), m_dir(std::move(dir)), m_begin(std::chrono::steady_clock::now()) {
  if (settings.checkpoint_every < 1)
    throw std::invalid_argument("reference: checkpoint_every must be >= 1, got " + std::to_string(settings.checkpoint_every));
  if (!(settings.interface_error_relative >= 0.0) || !(settings.interface_error_floor >= 0.0) ||
      !std::isfinite(settings.interface_error_relative) || !std::isfinite(settings.interface_error_floor))
    throw std::invalid_argument("reference: the interface energy tolerances must be finite and >= 0, got " +
                                std::to_string(settings.interface_error_relative) + " and " +
                                std::to_string(settings.interface_error_floor));
  if (settings.adaptive_force_change > 0.0 && !(settings.adaptive_min_travel > 0.0 && std::isfinite(settings.adaptive_force_change)))
    throw std::invalid_argument("reference: adaptive sampling needs a force change fraction and a minimum travel > 0");
  m_problem = reference_problem(scene, mesh);
  m_crack = add_crack_path(scene, m_problem.problem, settings.fracture, settings.refinements, settings.cohesive_viscous_time);
  // Kelvin–Voigt damping: the dynamic step's, when asked for (the quasi-static solve has no rate).
  for (reference::MaterialRegion& region : m_problem.problem.materials) {
    if (!(settings.dynamic && settings.damping)) region.damping = 0.0;
    m_damped = m_damped || region.damping > 0.0;
  }
  if (!m_crack.warning.empty()) std::fprintf(stderr, "reference %s: warning: %s\n", scene.name.c_str(), m_crack.warning.c_str());
  // The crack extent is measured along the blade's cutting direction (c of paper 001 Fig. 3), or
  // downwards from the grasped top for a tear.
  if (scene.tools.front().kind == Tool::Kind::blade) m_crack_direction = scene.tools.front().blade.cutting_direction;
  plan();
  m_solver_settings.degree = settings.degree;
  m_solver_settings.refinements = settings.refinements;
  m_solver_settings.linear_solver = settings.linear_solver;
  m_solver_settings.distribute = settings.distribute;
  m_solver_settings.residual_fault = settings.residual_fault;
  m_solver_settings.dynamic = settings.dynamic;
  m_solver = std::make_unique<reference::FiniteStrainSolver>(m_problem.problem, m_solver_settings);
  // Under mpirun every process runs this; rank 0 writes the files and the progress. A solver that
  // is not distributed (settings.distribute false: one of the solves `mpirun kerf study` spreads
  // over its ranks) is its own process's run, and that process writes.
  m_writer = m_solver->process_count() == 1 || reference::mpi_processes().rank == 0;
  m_pieces = m_solver->process_count() > 1;
  m_sha = file_sha256(scene.file);
  m_checkpoint_file = m_dir / "checkpoint.bin";
}

/// The loads: the requested output samples (all when none are named), and the vertices of the
/// motion, so that between two consecutive loads the tools move along a straight line in time.
void TrajectorySolve::plan() {
  const std::size_t n = m_problem.times.size();
  m_requested = m_settings.sample_indices;
  if (m_requested.empty())
    for (std::size_t k = 0; k < n; ++k) m_requested.push_back(k);
  for (std::size_t i = 0; i < m_requested.size(); ++i)
    if (m_requested[i] >= n || (i > 0 && m_requested[i] <= m_requested[i - 1]))
      throw std::invalid_argument("reference: sample indices must be ascending and below " + std::to_string(n) +
                                  " (the trajectory's sample count); entry " + std::to_string(i) + " is " +
                                  std::to_string(m_requested[i]));
  if (!(m_settings.vertex_tolerance > 0.0) || !std::isfinite(m_settings.vertex_tolerance))
    throw std::invalid_argument("reference: the vertex tolerance must be a positive length, got " +
                                std::to_string(m_settings.vertex_tolerance) + " m");
  m_vertices = motion_vertices(m_problem, m_settings.vertex_tolerance);
  m_indices = planned_loads(m_requested, m_vertices);
  m_duration = m_problem.times.back();
}

LoadState TrajectorySolve::load_at(double t) const {
  // The pressing tool, if any, is the scene's only tool (reference_problem); a tied tool's
  // displacement follows the load factor along its own sampled path (tie_stylus).
  return LoadState{m_duration > 0.0 ? t / m_duration : 0.0, position_at(m_problem.tools.front().positions, m_problem.times, t), t};
}

LoadReason TrajectorySolve::reason_of(std::size_t k) const {
  if (std::binary_search(m_requested.begin(), m_requested.end(), k)) return LoadReason::requested;
  if (std::binary_search(m_vertices.begin(), m_vertices.end(), k)) return LoadReason::vertex;
  return LoadReason::inserted;
}

void TrajectorySolve::resume_from_checkpoint() {
  namespace fs = std::filesystem;
  m_cp.scene_sha256 = m_sha;
  m_cp.degree = m_settings.degree;
  m_cp.refinements = m_settings.refinements;
  m_cp.processes = m_solver->process_count();
  m_cp.dynamic = m_settings.dynamic;
  m_cp.damped = m_damped;
  m_cp.indices = m_indices;
  m_cp.last = load_at(0.0);
  if (!m_settings.resume) return;
  if (!fs::exists(m_checkpoint_file)) {
    if (m_writer)
      std::fprintf(stderr, "reference %s: no checkpoint in %s, starting from the beginning\n", m_scene.name.c_str(), m_dir.c_str());
    return;
  }
  ReferenceCheckpoint saved = read_reference_checkpoint(m_checkpoint_file);
  // An adaptive run's list grows by the samples it inserted: every planned one must be in it.
  const bool same_samples = m_settings.adaptive_force_change > 0.0
                                ? std::includes(saved.indices.begin(), saved.indices.end(), m_indices.begin(), m_indices.end())
                                : saved.indices == m_indices;
  if (saved.scene_sha256 != m_sha || saved.degree != m_settings.degree || saved.refinements != m_settings.refinements ||
      !same_samples || saved.processes != m_cp.processes)
    throw std::runtime_error("reference: " + m_checkpoint_file.string() +
                             " is from a different run (scene file, degree, refinements, loads or MPI process "
                             "count differ; it was written by " +
                             std::to_string(saved.processes) + " process(es), this run has " +
                             std::to_string(m_cp.processes) + ")");
  if (saved.dynamic != m_cp.dynamic)
    throw std::runtime_error("reference: " + m_checkpoint_file.string() + " is from a " +
                             (saved.dynamic ? "dynamic" : "quasi-static") + " run and this run is " +
                             (m_cp.dynamic ? "dynamic (--dynamic)" : "quasi-static") + ": resume with the same time integration");
  if (saved.damped != m_cp.damped)
    throw std::runtime_error("reference: " + m_checkpoint_file.string() + " is from a run " +
                             (saved.damped ? "with" : "without") + " the scene's Kelvin-Voigt damping and this run is " +
                             (m_cp.damped ? "damped" : "undamped (--no-damping, or a checkpoint from before the damping)") +
                             ": resume with the same damping");
  m_solver->set_state(saved.state);
  m_cp = std::move(saved);
  m_indices = m_cp.indices; // an adaptive run continues with the samples it had inserted
  m_cp.last.time = m_cp.last.load_factor * m_duration; // the load factor is t/T (load_at), also between samples
  m_resumed_from = m_cp.solved;
  if (m_writer)
    std::fprintf(stderr, "reference %s: resuming after sample %zu/%zu from %s\n", m_scene.name.c_str(), m_cp.solved,
                 m_indices.size(), m_checkpoint_file.c_str());
}

reference::LoadPathSettings TrajectorySolve::load_path_settings() const {
  reference::LoadPathSettings s;
  if (m_settings.dynamic && m_crack.active) {
    // The interface energy control (reference/load_path.hpp): |e| <= rel ΔD + floor J_c A per step.
    s.interface_error_relative = m_settings.interface_error_relative;
    s.interface_error_absolute = m_settings.interface_error_floor * m_scene.material.fracture_toughness * m_crack.interface_area;
  }
  return s;
}

void TrajectorySolve::start_load_path(const LoadState& from, double interface_step) {
  m_load_path.emplace(*m_solver, from, load_path_settings(), [this](double t) { return load_at(t); });
  m_load_path->set_interface_step(interface_step);
}

SolvedSample TrajectorySolve::forces_of(const reference::LoadStepReport& step, std::size_t k) const {
  SolvedSample out;
  for (const reference::BoundaryReaction& b : step.equilibrium.boundary_reactions)
    out.reactions[b.surface] = vec_json(b.force + Eigen::Vector3d::Zero());
  // The force on each tool: a tied stylus's is the reaction of its tie (the force of the body on
  // the tied nodes); a pressing tool's is the contact resultant. The supports carry the rest.
  out.support = step.support_reaction;
  bool touching = false;
  for (const ReferenceTool& tool : m_problem.tools) {
    Eigen::Vector3d f = step.tool_force;
    bool touches = step.equilibrium.contact_points + step.equilibrium.edge_contact_points > 0;
    if (is_tied(tool) && tool.coupling.foundation >= 0) {
      // A compliant grasp: the force of the body on its layer, −∫ k (d − u) dA (not a support).
      f = step.equilibrium.foundation_forces.at(static_cast<std::size_t>(tool.coupling.foundation));
      touches = f.norm() > 0.0;
    } else if (is_tied(tool)) {
      f = step.equilibrium.boundary_reactions.at(static_cast<std::size_t>(tool.coupling.boundary)).force;
      out.support -= f;
      touches = f.norm() > 0.0;
    }
    f += Eigen::Vector3d::Zero(); // −0 → 0 in the CSV
    touching = touching || touches;
    out.tool_forces.push_back(f);
    out.tool_positions.push_back(tool.positions[k]);
    out.forces_json[tool.name] = vec_json(f);
  }
  out.interface = {touching, step.equilibrium.cohesive.failed_area};
  out.mode = touching ? InteractionMode::deformation_1 : InteractionMode::no_contact;
  if (m_crack.active) {
    out.mode = reference::reference_mode(m_previous_interface, out.interface);
    out.crack_extent = m_solver->crack_extent(m_crack_direction);
  }
  return out;
}

bool TrajectorySolve::needs_sample_before(std::size_t i, const SolvedSample& sample) const {
  if (!(m_settings.adaptive_force_change > 0.0) || i == 0) return false;
  const std::size_t k = m_indices[i], previous = m_indices[i - 1];
  double travel = 0.0;
  for (const ReferenceTool& tool : m_problem.tools) travel = std::max(travel, (tool.positions[k] - tool.positions[previous]).norm());
  if (k <= previous + 1 || travel <= m_settings.adaptive_min_travel) return false;
  const std::size_t n_tools = m_problem.tools.size();
  const std::vector<ProfileRow>& rows = m_cp.profile.rows;
  const std::size_t last = rows.size() - n_tools; // the previous sample's first row
  const ProfileRow& before = rows[last];
  if (sample.mode != before.mode) return true; // an event: first contact, rupture, cutting, release
  // A fast change is a curve that leaves the straight line through the two samples before:
  // |F_k − (F_{k−1} + (F_{k−1} − F_{k−2}) (t_k − t_{k−1}) / (t_{k−1} − t_{k−2}))| beyond the
  // fraction of the largest force (a ramp from zero is straight: it inserts nothing).
  if (i < 2) return false;
  const std::size_t older = last - n_tools;
  const double t0 = rows[older].t, t1 = before.t, t2 = m_problem.times[k];
  const double slope = t1 > t0 ? (t2 - t1) / (t1 - t0) : 0.0;
  double deviation = 0.0;
  for (std::size_t j = 0; j < n_tools; ++j) {
    const Eigen::Vector3d& f0 = rows[older + j].force;
    const Eigen::Vector3d& f1 = rows[last + j].force;
    deviation = std::max(deviation, (sample.tool_forces[j] - (f1 + (f1 - f0) * slope)).norm());
  }
  const double scale = std::max({m_peak_force, sample.tool_forces.front().norm(), before.force.norm()});
  return deviation > m_settings.adaptive_force_change * scale;
}

void TrajectorySolve::undo_and_insert_before(std::size_t i, const reference::LoadStepReport& step) {
  m_cp.solve_seconds += step.seconds; // the undone solve's cost is spent all the same
  m_newton_total += step.newton_iterations;
  // Back to the previous sample's state (the one the load path held before this sample).
  m_solver->set_state(m_state_before);
  start_load_path(m_load_before, m_interface_step_before);
  const std::size_t previous = m_indices[i - 1], k = m_indices[i];
  m_indices.insert(m_indices.begin() + static_cast<std::ptrdiff_t>(i), previous + (k - previous) / 2);
  m_solved_times.insert(m_solved_times.begin() + static_cast<std::ptrdiff_t>(i), m_problem.times[m_indices[i]]);
  m_cp.indices = m_indices;
  ++m_inserted;
}

void TrajectorySolve::record(std::size_t i, const reference::LoadStepReport& step, const SolvedSample& sample) {
  const std::size_t k = m_indices[i];
  for (const Eigen::Vector3d& f : sample.tool_forces) m_peak_force = std::max(m_peak_force, f.norm());
  m_previous_interface = sample.interface;
  std::vector<Eigen::Vector3d> forces_on_body;
  for (const Eigen::Vector3d& f : sample.tool_forces) forces_on_body.push_back(-f);
  m_energy.add_sample(sample.tool_positions, forces_on_body, m_solver->strain_energy(), step.equilibrium.cohesive,
                      step.equilibrium.contact_energy + step.equilibrium.foundation_energy, m_solver->kinetic_energy(),
                      m_solver->damping_dissipation());
  for (std::size_t j = 0; j < m_problem.tools.size(); ++j) {
    ProfileRow row;
    row.t = m_problem.times[k];
    row.tool = m_problem.tools[j].name;
    row.position = sample.tool_positions[j];
    row.force = sample.tool_forces[j];
    row.mode = sample.mode;
    row.crack_extent = sample.crack_extent;
    row.cost_s = step.seconds; // one solve for all the tools
    m_cp.profile.rows.push_back(row);
  }
  m_cp.samples.push_back({{"index", k},
                          {"t_s", m_problem.times[k]},
                          {"load", load_reason_name(reason_of(k))},
                          {"newton_iterations", step.newton_iterations},
                          {"cutbacks", step.cutbacks},
                          {"increments", step.increments},
                          {"interface_rejections", step.interface_rejections},
                          {"interface_tolerance_exceeded", step.interface_tolerance_exceeded},
                          {"residual_N", step.final_residual},
                          {"seconds", step.seconds},
                          {"tool_force_N", vec_json(sample.tool_forces.front())},
                          {"tool_forces_N", sample.forces_json},
                          {"support_reaction_N", vec_json(sample.support)},
                          {"boundary_reactions_N", sample.reactions},
                          {"force_imbalance_N", vec_json(step.equilibrium.force_imbalance)},
                          {"contact_points", step.equilibrium.contact_points},
                          {"edge_contact_points", step.equilibrium.edge_contact_points},
                          {"edge_contact_length_m", step.equilibrium.edge_contact_length},
                          {"energy", m_energy.to_json()}});
  m_cp.solve_seconds += step.seconds;
  m_newton_total += step.newton_iterations;
  m_cp.solved = i + 1;
  m_cp.last = m_load_path->last_converged_load();
  m_cp.interface_step = m_load_path->interface_step();
}

void TrajectorySolve::write_fields_and_checkpoint(std::size_t i, const LoadState& load) {
  namespace fs = std::filesystem;
  if (m_settings.write_fields) {
    if (m_pieces)
      m_solver->write_fields(m_dir / "fields" / step_name(i, true), load); // collective; atomic inside
    else if (m_writer)
      write_atomically(m_dir / "fields" / step_name(i, false), [&](const fs::path& tmp) { m_solver->write_fields(tmp, load); });
    if (m_writer) write_pvd(m_dir, m_solved_times, m_cp.solved, m_pieces);
  }
  if (m_cp.solved % static_cast<std::size_t>(m_settings.checkpoint_every) == 0) {
    m_cp.state = m_load_path->last_converged_state();
    if (m_writer) write_reference_checkpoint(m_cp, m_checkpoint_file);
  }
}

void TrajectorySolve::print_progress(std::size_t k, const reference::LoadStepReport& step, const SolvedSample& sample) const {
  if (!m_writer) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_begin).count();
  const double eta = elapsed / static_cast<double>(m_cp.solved - m_first) * static_cast<double>(m_indices.size() - m_cp.solved);
  const Eigen::Vector3d& x = sample.tool_positions.front();
  std::fprintf(stderr,
               "reference %s: sample %zu/%zu (#%zu, t = %.4f s, %s) tool (%.3f, %.3f, %.3f) mm, %d Newton its, "
               "%d cut-backs, |R| %.2e N, |F| %.4g N, elapsed %.1f s, ETA %.1f s\n",
               m_scene.name.c_str(), m_cp.solved, m_indices.size(), k, m_problem.times[k], load_reason_name(reason_of(k)),
               x.x() * 1e3, x.y() * 1e3, x.z() * 1e3, step.newton_iterations, step.cutbacks, step.final_residual,
               sample.tool_forces.front().norm(), elapsed, eta);
}

ReferenceResult TrajectorySolve::run() {
  namespace fs = std::filesystem;
  resume_from_checkpoint();
  if (m_settings.write_fields) fs::create_directories(m_dir / "fields");
  start_load_path(m_cp.last, m_cp.interface_step);
  for (std::size_t k : m_indices) m_solved_times.push_back(m_problem.times[k]);
  m_first = m_cp.solved;
  for (const auto& s : m_cp.samples) m_newton_total += s.at("newton_iterations").get<int>();
  // Energy bookkeeping and the interface state of the previous sample (for the modes), restored
  // from the last sample record on resume.
  if (!m_cp.samples.empty() && m_cp.samples.back().contains("energy")) {
    m_energy = EnergyBookkeeping::from_json(m_cp.samples.back().at("energy"));
    m_previous_interface = {m_cp.samples.back().at("contact_points").get<int>() > 0,
                            m_cp.samples.back().at("energy").at("failed_area_m2").get<double>()};
  }
  for (const ProfileRow& r : m_cp.profile.rows) m_peak_force = std::max(m_peak_force, r.force.norm());

  for (std::size_t i = m_cp.solved; i < m_indices.size(); ++i) {
    const std::size_t k = m_indices[i];
    const LoadState load = load_at(m_problem.times[k]);
    if (m_settings.adaptive_force_change > 0.0) {
      // The state before this sample: adaptive sampling returns to it to solve a sample before this one.
      m_state_before = m_load_path->last_converged_state();
      m_load_before = m_load_path->last_converged_load();
      m_interface_step_before = m_load_path->interface_step();
    }
    reference::LoadStepReport step;
    try {
      step = m_load_path->advance({load, k, m_problem.times[k]});
    } catch (const reference::LoadPathError& e) {
      m_stop = e.what();
      if (m_writer) std::fprintf(stderr, "reference %s: stopped: %s\n", m_scene.name.c_str(), e.what());
      break;
    }
    const SolvedSample sample = forces_of(step, k);
    if (needs_sample_before(i, sample)) {
      undo_and_insert_before(i, step);
      --i; // the loop's ++i comes back to position i: the inserted sample
      continue;
    }
    record(i, step, sample);
    write_fields_and_checkpoint(i, load);
    print_progress(k, step, sample);
  }
  if (!m_stop.empty()) {
    m_cp.state = m_load_path->last_converged_state();
    if (m_writer) write_reference_checkpoint(m_cp, m_checkpoint_file); // the last converged state, saved
  }
  const nlohmann::json m = manifest(std::chrono::duration<double>(std::chrono::steady_clock::now() - m_begin).count());
  if (m_writer) {
    write_profile_csv(m_cp.profile, m_dir / "profile.csv");
    write_manifest(m, m_dir / "manifest.json");
  }
  reference::wait_for_processes(); // the files are in place when any process returns
  return {m_cp.profile, m_stop};
}

nlohmann::json TrajectorySolve::manifest(double wall_seconds) const {
  nlohmann::json m;
  m["kerf_version"] = KERF_VERSION;
  m["git_commit"] = KERF_GIT_COMMIT;
  m["scene"] = {{"name", m_scene.name},
                {"file", portable_path(m_scene.file)},
                {"sha256", m_sha},
                {"phenomena", m_scene.phenomena.to_string()}};
  m["model"] = {{"name", "reference"},
                {"parameters",
                 {{"degree", m_settings.degree},
                  {"refinements", m_settings.refinements},
                  {"samples_requested", m_requested.size()},
                  {"checkpoint_every", m_settings.checkpoint_every},
                  {"time_integration", m_settings.dynamic ? "dynamic: Newmark average acceleration (beta = 1/4, gamma = 1/2), consistent mass"
                                                          : "quasi-static"},
                  {"kelvin_voigt_damping", m_damped},
                  {"interface_error_relative", load_path_settings().interface_error_relative},
                  {"interface_error_absolute_J", load_path_settings().interface_error_absolute},
                  {"write_fields", m_settings.write_fields}}}};
  m["mesh"] = {{"nodes", m_mesh.nodes.rows()},
               {"tetrahedra", m_mesh.tets.rows()},
               {"element_size_m", m_scene.geometry.element_size},
               {"source", portable_path(m_scene.geometry.source)}};
  m["solver"] = solver_record();
  const reference::SolverTimings parts = m_solver->timings(); // rank 0's when distributed
  m["timings"] = {{"wall_s", wall_seconds},
                  {"solve_total_s", m_cp.solve_seconds},
                  {"samples_solved", m_cp.solved},
                  {"solver_parts_s", {{"assembly", parts.assembly_seconds},
                                      {"factorization", parts.factorization_seconds},
                                      {"solve", parts.solve_seconds},
                                      {"communication", parts.communication_seconds}}}};
  m["newton_iterations_total"] = m_newton_total;
  m["energy"] = m_energy.to_json();
  m["fracture"] = fracture_record();
  m["samples"] = m_cp.samples;
  m["stopped"] = m_stop.empty() ? nlohmann::json(nullptr) : nlohmann::json(m_stop);
  m["partial"] = !m_stop.empty();
  m["resumed_after_sample"] = m_resumed_from ? nlohmann::json(*m_resumed_from) : nlohmann::json(nullptr);
  return m;
}

nlohmann::json TrajectorySolve::solver_record() const {
  nlohmann::json solver = {{"dofs", m_solver->dof_count()},
                           {"cells", m_solver->cell_count()},
                           {"linear_solver", m_solver->linear_solver_name()},
                           {"linear_solver_reason", m_solver->linear_solver_reason()},
                           {"mpi_processes", m_solver->process_count()},
                           {"relative_tolerance", m_solver_settings.relative_tolerance},
                           {"max_newton_iterations", m_solver_settings.max_newton_iterations},
                           {"max_cutbacks", reference::LoadPathSettings{}.max_cutbacks},
                           {"tool_coupling", is_tied(m_problem.tools.front()) ? "tied" : "penalty"}};
  nlohmann::json tools = nlohmann::json::array();
  for (const ReferenceTool& tool : m_problem.tools) {
    nlohmann::json t = {{"name", tool.name}, {"coupling", is_tied(tool) ? "tied" : "penalty"}};
    if (is_tied(tool)) {
      t["tied_nodes"] = tool.coupling.tied_nodes;
      t["tied_triangles"] = tool.coupling.tied_triangles.size();
      if (tool.coupling.foundation >= 0) t["grasp_stiffness_N_per_m3"] = tool.coupling.grasp_stiffness;
      t["contact_point_m"] = vec_json(tool.coupling.contact_point);
    }
    tools.push_back(t);
  }
  solver["tools"] = tools;
  solver["load_path"] = load_path_record();
  if (m_settings.adaptive_force_change > 0.0)
    solver["adaptive_sampling"] = {{"force_change", m_settings.adaptive_force_change},
                                   {"min_travel_m", m_settings.adaptive_min_travel},
                                   {"requested_samples", m_settings.sample_indices.size()},
                                   {"solved_samples", m_indices.size()},
                                   {"inserted_this_run", m_inserted}};
  if (is_tied(m_problem.tools.front())) { // the first tool's, as before several tools were coupled
    solver["tied_nodes"] = m_problem.tools.front().coupling.tied_nodes;
    solver["tied_triangles"] = m_problem.tools.front().coupling.tied_triangles.size();
    solver["contact_point_m"] = vec_json(m_problem.tools.front().coupling.contact_point);
  } else {
    solver["contact_penalty_Pa_per_m"] = m_solver->contact_penalty();
  }
  return solver;
}

nlohmann::json TrajectorySolve::load_path_record() const {
  // The load path: every vertex of the motion, the requested samples, the ones adaptive sampling
  // inserted; between two loads the tools move along the trajectory (LoadPath's motion).
  std::size_t vertices_solved = 0, inserted_solved = 0;
  for (std::size_t i = 0; i < m_cp.solved; ++i) {
    const LoadReason r = reason_of(m_indices[i]);
    vertices_solved += r == LoadReason::vertex;
    inserted_solved += r == LoadReason::inserted;
  }
  return {{"motion", "the trajectory: between two loads the tools move along it (reference/load_path.hpp)"},
          {"vertex_tolerance_m", m_settings.vertex_tolerance},
          {"requested_samples", m_requested.size()},
          {"vertices", m_vertices.size()},
          {"loads_planned", m_indices.size()},
          {"loads_solved", m_cp.solved},
          {"vertices_not_requested", vertices_solved},
          {"inserted", inserted_solved}};
}

nlohmann::json TrajectorySolve::fracture_record() const {
  return m_crack.active ? nlohmann::json{{"cohesive_law", "bilinear (Camacho-Ortiz effective opening), reference/cohesive/cohesive_law.hpp"},
                                         {"cohesive_strength_Pa", m_scene.material.cohesive_strength},
                                         {"fracture_toughness_J_per_m2", m_scene.material.fracture_toughness},
                                         {"interface_triangles", m_crack.interface_triangles},
                                         {"cohesive_zone_length_m", m_crack.zone_length},
                                         {"elements_in_zone", m_crack.elements_in_zone},
                                         {"viscous_time_s", m_settings.cohesive_viscous_time},
                                         {"viscosity_Pa_s_per_m", m_crack.viscosity},
                                         {"interface_area_m2", m_crack.interface_area},
                                         {"warning", m_crack.warning}}
                        : nlohmann::json(nullptr);
}

} // namespace

ReferenceResult run_reference(const Scene& scene, const TetMesh& mesh, const ReferenceRunSettings& settings,
                              const std::filesystem::path& dir) {
  return TrajectorySolve(scene, mesh, settings, dir).run();
}

} // namespace kerf

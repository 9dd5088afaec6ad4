#include "experiments/run/reference_run.hpp"

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
using reference::LawKind;
using reference::LoadState;

reference::MaterialRegion region_of(const Material& m) {
  reference::MaterialRegion r;
  r.volume_group = m.region.empty() ? "body" : m.region;
  r.law = m.law == MaterialLaw::neo_hookean ? LawKind::neo_hookean : LawKind::st_venant_kirchhoff;
  r.youngs_modulus = m.youngs_modulus;
  r.poisson_ratio = m.poisson_ratio;
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

ReferenceProblem reference_problem(const Scene& scene, const TetMesh& mesh) {
  if (scene.tools.size() != 1)
    throw std::invalid_argument("reference: scene '" + scene.name + "' has " + std::to_string(scene.tools.size()) +
                                " tools; the reference couples exactly one rigid tool");
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

  const Tool& tool = scene.tools.front();
  const SampledTrajectory path = sample(tool.trajectory);
  if (path.samples.empty()) throw std::invalid_argument("reference: tool '" + tool.name + "' has an empty trajectory");
  for (const ToolState& s : path.samples) {
    out.positions.push_back(s.position);
    out.times.push_back(s.time);
  }

  reference::RigidToolShape shape;
  if (tool.kind == Tool::Kind::blade) {
    shape.kind = reference::RigidToolShape::Kind::wedge;
    shape.edge_direction = tool.blade.edge_direction;
    shape.cutting_direction = tool.blade.cutting_direction;
    shape.wedge_angle = tool.blade.wedge_angle;
    shape.thickness = tool.blade.thickness;
    p.tool = shape;
    return out;
  }
  shape.kind = reference::RigidToolShape::Kind::sphere;
  shape.radius = tool.radius;

  // A sphere that starts touching the body (centre one radius from the surface, within 5% of R)
  // and never moves towards it grasps the surface (paper 000 §2.1): tied. Otherwise it presses.
  const SurfaceQuery surface(boundary_surface(mesh));
  const SurfaceQuery::Closest first = surface.closest_point(out.positions.front());
  const Eigen::Vector3d away = first.normal;
  const bool touching = std::abs(first.signed_distance - tool.radius) <= 0.05 * tool.radius;
  double outward = 0.0, inward = 0.0;
  for (const Eigen::Vector3d& x : out.positions) {
    const double s = (x - out.positions.front()).dot(away);
    outward = std::max(outward, s);
    inward = std::max(inward, -s);
  }
  if (!(touching && outward > 0.0 && inward <= 1e-9 * outward)) {
    p.tool = shape;
    return out;
  }

  ReferenceToolCoupling& c = out.coupling;
  c.kind = ReferenceToolCoupling::Kind::tied;
  c.contact_point = first.point;
  const SurfaceGroup* top = mesh.find_surface_group("top");
  if (top == nullptr)
    throw std::invalid_argument("reference: scene '" + scene.name + "': the tied stylus needs a surface group 'top'");
  auto within = [&](int node) { return (Eigen::Vector3d(mesh.nodes.row(node)) - c.contact_point).norm() <= tool.radius; };
  for (int pass = 0; pass < 2 && c.tied_triangles.empty(); ++pass)
    for (Eigen::Index f = 0; f < top->triangles.rows(); ++f) {
      int inside = 0;
      for (int k = 0; k < 3; ++k) inside += within(top->triangles(f, k)) ? 1 : 0;
      if (pass == 0 ? inside == 3 : inside > 0) c.tied_triangles.push_back(static_cast<int>(f));
    }
  if (c.tied_triangles.empty())
    throw std::invalid_argument("reference: scene '" + scene.name + "': no node of 'top' lies within the stylus radius of " +
                                "its first contact point");
  SurfaceGroup tie;
  tie.name = "stylus_tie";
  tie.triangles.resize(static_cast<Eigen::Index>(c.tied_triangles.size()), 3);
  std::set<int> nodes;
  for (std::size_t i = 0; i < c.tied_triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      tie.triangles(static_cast<Eigen::Index>(i), k) = top->triangles(c.tied_triangles[i], k);
      nodes.insert(top->triangles(c.tied_triangles[i], k));
    }
  c.tied_nodes = nodes.size();
  p.mesh.surface_groups.push_back(std::move(tie));

  // u = p(λ T) − p(0): the tool displacement since contact, λ the load factor.
  auto positions = std::make_shared<const std::vector<Eigen::Vector3d>>(out.positions);
  auto times = std::make_shared<const std::vector<double>>(out.times);
  const double T = out.times.back();
  p.displacement_boundaries.push_back(
      {"stylus_tie", DisplacementBoundary::Kind::prescribed,
       [positions, times, T](const Eigen::Vector3d&, double load) -> Eigen::Vector3d {
         return position_at(*positions, *times, load * T) - positions->front();
       },
       {true, true, true}});
  return out;
}

namespace {

// ---------------------------------------------------------------------------------- checkpoint
// Binary, native byte order (a checkpoint is resumed on the machine that wrote it):
// "KERFREF2", scene sha256, degree, refinements, process count, sample indices, targets solved,
// the last converged load, the solver state (global DOF order, which depends on the process
// count), the profile rows, the per-sample manifest records.

constexpr char checkpoint_magic[8] = {'K', 'E', 'R', 'F', 'R', 'E', 'F', '2'};

struct Checkpoint {
  std::string scene_sha256;
  int degree = 0, refinements = 0;
  int processes = 1; ///< MPI processes the mesh was distributed over
  std::vector<std::size_t> indices;
  std::size_t solved = 0;
  LoadState last;
  std::vector<double> state;
  ForceProfile profile;
  nlohmann::json samples = nlohmann::json::array();
  double solve_seconds = 0.0;
};

class Writer {
public:
  explicit Writer(std::ofstream& out) : m_out(out) {}
  void u64(std::uint64_t v) { m_out.write(reinterpret_cast<const char*>(&v), sizeof v); }
  void i32(std::int32_t v) { m_out.write(reinterpret_cast<const char*>(&v), sizeof v); }
  void f64(double v) { m_out.write(reinterpret_cast<const char*>(&v), sizeof v); }
  void str(const std::string& s) {
    u64(s.size());
    m_out.write(s.data(), static_cast<std::streamsize>(s.size()));
  }
  void vec(const Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) f64(v[k]);
  }

private:
  std::ofstream& m_out;
};

class Reader {
public:
  Reader(std::ifstream& in, std::filesystem::path file) : m_in(in), m_file(std::move(file)) {}
  template <class T> T pod() {
    T v{};
    m_in.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!m_in) throw std::runtime_error("reference checkpoint " + m_file.string() + ": truncated");
    return v;
  }
  std::uint64_t u64() { return pod<std::uint64_t>(); }
  std::uint64_t count(std::uint64_t limit) {
    const std::uint64_t n = u64();
    if (n > limit) throw std::runtime_error("reference checkpoint " + m_file.string() + ": corrupt count");
    return n;
  }
  double f64() { return pod<double>(); }
  std::string str() {
    std::string s(count(std::uint64_t{1} << 32), '\0');
    m_in.read(s.data(), static_cast<std::streamsize>(s.size()));
    if (!m_in) throw std::runtime_error("reference checkpoint " + m_file.string() + ": truncated");
    return s;
  }
  Eigen::Vector3d vec() {
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) v[k] = f64();
    return v;
  }

private:
  std::ifstream& m_in;
  std::filesystem::path m_file;
};

void write_checkpoint(const Checkpoint& c, const std::filesystem::path& file) {
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error("reference: cannot write checkpoint " + tmp.string());
    Writer w(out);
    out.write(checkpoint_magic, sizeof checkpoint_magic);
    w.str(c.scene_sha256);
    w.i32(c.degree);
    w.i32(c.refinements);
    w.i32(c.processes);
    w.u64(c.indices.size());
    for (std::size_t i : c.indices) w.u64(i);
    w.u64(c.solved);
    w.f64(c.last.load_factor);
    w.vec(c.last.tool_position);
    w.u64(c.state.size());
    for (double v : c.state) w.f64(v);
    w.u64(c.profile.rows.size());
    for (const ProfileRow& r : c.profile.rows) {
      w.f64(r.t);
      w.str(r.tool);
      w.vec(r.position);
      w.vec(r.force);
      w.i32(static_cast<std::int32_t>(r.mode));
      w.f64(r.crack_extent);
      w.f64(r.cost_s);
    }
    w.str(c.samples.dump());
    w.f64(c.solve_seconds);
    out.flush();
    if (!out) throw std::runtime_error("reference: writing checkpoint " + tmp.string() + " failed");
  });
}

Checkpoint read_checkpoint(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("reference: cannot read checkpoint " + file.string());
  char magic[8];
  in.read(magic, sizeof magic);
  if (!in || !std::equal(magic, magic + 8, checkpoint_magic))
    throw std::runtime_error("reference checkpoint " + file.string() + ": not a kerf reference checkpoint");
  Reader r(in, file);
  Checkpoint c;
  c.scene_sha256 = r.str();
  c.degree = r.pod<std::int32_t>();
  c.refinements = r.pod<std::int32_t>();
  c.processes = r.pod<std::int32_t>();
  c.indices.resize(r.count(std::uint64_t{1} << 32));
  for (std::size_t& i : c.indices) i = r.u64();
  c.solved = r.u64();
  c.last.load_factor = r.f64();
  c.last.tool_position = r.vec();
  c.state.resize(r.count(std::uint64_t{1} << 34));
  for (double& v : c.state) v = r.f64();
  c.profile.rows.resize(r.count(std::uint64_t{1} << 32));
  for (ProfileRow& row : c.profile.rows) {
    row.t = r.f64();
    row.tool = r.str();
    row.position = r.vec();
    row.force = r.vec();
    const auto mode = r.pod<std::int32_t>();
    if (mode < 0 || mode > static_cast<std::int32_t>(InteractionMode::deformation_2))
      throw std::runtime_error("reference checkpoint " + file.string() + ": corrupt mode");
    row.mode = static_cast<InteractionMode>(mode);
    row.crack_extent = r.f64();
    row.cost_s = r.f64();
  }
  c.samples = nlohmann::json::parse(r.str());
  c.solve_seconds = r.f64();
  if (c.solved > c.indices.size())
    throw std::runtime_error("reference checkpoint " + file.string() + ": more samples solved than requested");
  return c;
}

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
  const CrackPathInfo crack = add_crack_path(scene, rp.problem, settings.fracture, settings.refinements);
  if (!crack.warning.empty()) std::fprintf(stderr, "reference %s: warning: %s\n", scene.name.c_str(), crack.warning.c_str());
  // The crack extent is measured along the blade's cutting direction (c of paper 001 Fig. 3), or
  // downwards from the grasped top for a tear.
  const Eigen::Vector3d crack_direction =
      scene.tools.front().kind == Tool::Kind::blade ? scene.tools.front().blade.cutting_direction : Eigen::Vector3d(0, 0, -1);
  const std::size_t n = rp.positions.size();
  std::vector<std::size_t> indices = settings.sample_indices;
  if (indices.empty())
    for (std::size_t k = 0; k < n; ++k) indices.push_back(k);
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= n || (i > 0 && indices[i] <= indices[i - 1]))
      throw std::invalid_argument("reference: sample indices must be ascending and below " + std::to_string(n) +
                                  " (the trajectory's sample count); entry " + std::to_string(i) + " is " +
                                  std::to_string(indices[i]));
  const double T = rp.times.back();
  auto load_of = [&](std::size_t k) { return LoadState{T > 0.0 ? rp.times[k] / T : 0.0, rp.positions[k], rp.times[k]}; };
  const bool tied = rp.coupling.kind == ReferenceToolCoupling::Kind::tied;
  const std::string tool_name = scene.tools.front().name;

  reference::SolverSettings solver_settings;
  solver_settings.degree = settings.degree;
  solver_settings.refinements = settings.refinements;
  solver_settings.linear_solver = settings.linear_solver;
  solver_settings.distribute = settings.distribute;
  reference::FiniteStrainSolver solver(rp.problem, solver_settings);
  // Under mpirun every process runs this function; rank 0 writes the files and the progress. A
  // solver that is not distributed (settings.distribute false: e.g. one of the solves `mpirun kerf
  // study` spreads over its ranks) is its own process's run, and that process writes.
  const bool writer = solver.process_count() == 1 || reference::mpi_processes().rank == 0;
  const bool pieces = solver.process_count() > 1;
  // The reaction on the tied nodes: a second solver on the same mesh whose only Dirichlet DOFs
  // are the tie, given the converged state and asked for equilibrium with no Newton step and an
  // unbounded tolerance. Its "support reaction" (−Σ of the residual over its Dirichlet DOFs) is then
  // the force of the body on the tied nodes, i.e. on the stylus.
  std::unique_ptr<reference::FiniteStrainSolver> tie_probe;
  if (tied) {
    FiniteStrainProblem probe = rp.problem;
    probe.displacement_boundaries.erase(probe.displacement_boundaries.begin(),
                                        probe.displacement_boundaries.end() - 1); // keep the tie (last)
    reference::SolverSettings probe_settings = solver_settings;
    probe_settings.max_newton_iterations = 0;
    probe_settings.relative_tolerance = 1e300;
    tie_probe = std::make_unique<reference::FiniteStrainSolver>(probe, probe_settings);
  }

  const std::string sha = file_sha256(scene.file);
  const fs::path checkpoint_file = dir / "checkpoint.bin";
  Checkpoint cp;
  cp.scene_sha256 = sha;
  cp.degree = settings.degree;
  cp.refinements = settings.refinements;
  cp.processes = solver.process_count();
  cp.indices = indices;
  cp.last = load_of(0);
  std::optional<std::size_t> resumed_from;
  if (settings.resume && fs::exists(checkpoint_file)) {
    Checkpoint saved = read_checkpoint(checkpoint_file);
    if (saved.scene_sha256 != sha || saved.degree != settings.degree || saved.refinements != settings.refinements ||
        saved.indices != indices || saved.processes != cp.processes)
      throw std::runtime_error("reference: " + checkpoint_file.string() +
                               " is from a different run (scene file, degree, refinements, samples or MPI process "
                               "count differ; it was written by " +
                               std::to_string(saved.processes) + " process(es), this run has " +
                               std::to_string(cp.processes) + ")");
    solver.set_state(saved.state);
    cp = std::move(saved);
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

  reference::LoadPath path(solver, cp.last);
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
  for (std::size_t i = cp.solved; i < indices.size(); ++i) {
    const std::size_t k = indices[i];
    reference::LoadStepReport step;
    const LoadState load = load_of(k);
    try {
      step = path.advance({load, k, rp.times[k]});
    } catch (const reference::LoadPathError& e) {
      stop = e.what();
      if (writer) std::fprintf(stderr, "reference %s: stopped: %s\n", scene.name.c_str(), e.what());
      break;
    }
    Eigen::Vector3d tool_force = step.tool_force + Eigen::Vector3d::Zero(); // −0 → 0
    Eigen::Vector3d support = step.support_reaction;
    double cost = step.seconds;
    if (tied) {
      const auto t0 = Clock::now();
      tie_probe->set_state(path.last_converged_state());
      const reference::EquilibriumReport r = tie_probe->solve(load);
      if (!r.converged) throw std::runtime_error("reference: evaluating the stylus reaction failed: " + r.failure);
      tool_force = r.support_reaction + Eigen::Vector3d::Zero(); // + 0 turns −0 into 0 in the CSV
      support = step.support_reaction - tool_force; // the main solver sums every Dirichlet DOF
      cost += std::chrono::duration<double>(Clock::now() - t0).count();
    }
    ProfileRow row;
    row.t = rp.times[k];
    row.tool = tool_name;
    row.position = rp.positions[k];
    row.force = tool_force;
    const bool touching = tied ? tool_force.norm() > 0.0 : step.equilibrium.contact_points > 0;
    row.mode = touching ? InteractionMode::deformation_1 : InteractionMode::no_contact;
    const reference::CohesiveSampleState interface{touching, step.equilibrium.cohesive.failed_area};
    if (crack.active) {
      row.mode = reference::reference_mode(previous_interface, interface);
      row.crack_extent = solver.crack_extent(crack_direction);
    }
    previous_interface = interface;
    energy.add_sample({rp.positions[k]}, {-tool_force}, solver.strain_energy(), step.equilibrium.cohesive);
    row.cost_s = cost;
    cp.profile.rows.push_back(row);
    cp.samples.push_back({{"index", k},
                          {"t_s", rp.times[k]},
                          {"newton_iterations", step.newton_iterations},
                          {"cutbacks", step.cutbacks},
                          {"increments", step.increments},
                          {"residual_N", step.final_residual},
                          {"seconds", cost},
                          {"tool_force_N", vec_json(tool_force)},
                          {"support_reaction_N", vec_json(support)},
                          {"contact_points", step.equilibrium.contact_points},
                          {"energy", energy.to_json()}});
    cp.solve_seconds += cost;
    newton_total += step.newton_iterations;
    cp.solved = i + 1;
    cp.last = path.last_converged_load();
    if (settings.write_fields) {
      if (pieces)
        solver.write_fields(dir / "fields" / step_name(i, true), load); // collective; atomic inside
      else if (writer)
        write_atomically(dir / "fields" / step_name(i, false), [&](const fs::path& tmp) { solver.write_fields(tmp, load); });
      if (writer) write_pvd(dir, solved_times, cp.solved, pieces);
    }
    if (cp.solved % static_cast<std::size_t>(settings.checkpoint_every) == 0) {
      cp.state = path.last_converged_state();
      if (writer) write_checkpoint(cp, checkpoint_file);
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - run_begin).count();
    const double eta = elapsed / static_cast<double>(cp.solved - first) * static_cast<double>(indices.size() - cp.solved);
    if (writer)
      std::fprintf(stderr,
                   "reference %s: sample %zu/%zu (#%zu, t = %.4f s) tool (%.3f, %.3f, %.3f) mm, %d Newton its, "
                   "%d cut-backs, |R| %.2e N, |F| %.4g N, elapsed %.1f s, ETA %.1f s\n",
                   scene.name.c_str(), cp.solved, indices.size(), k, rp.times[k], rp.positions[k].x() * 1e3,
                   rp.positions[k].y() * 1e3, rp.positions[k].z() * 1e3, step.newton_iterations, step.cutbacks,
                   step.final_residual, tool_force.norm(), elapsed, eta);
  }
  if (!stop.empty()) {
    cp.state = path.last_converged_state();
    if (writer) write_checkpoint(cp, checkpoint_file); // the last converged state, saved
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
                                {"tool_coupling", tied ? "tied" : "penalty"}};
  if (tied) {
    solver_json["tied_nodes"] = rp.coupling.tied_nodes;
    solver_json["tied_triangles"] = rp.coupling.tied_triangles.size();
    solver_json["contact_point_m"] = vec_json(rp.coupling.contact_point);
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

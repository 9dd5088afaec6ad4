// kerf reference SCENE [--degree 1|2] [--refine K] [--samples N] [--until T] [--levels L]
// [--element-size H] [-o DIR] [--resume] [--no-fields] [--solver auto|direct|iterative] [--np N]
// [--fracture auto|on|off] [--adaptive F] [--min-travel MM] [--cohesive-viscous-time TAU] [--dynamic] [--no-damping]
// [--interface-energy-tolerance REL]: the finite-strain reference along the
// scene's trajectory (docs/reference.md),
// written as profile.csv + manifest.json (+ fields.pvd), with a progress line per sample and
// checkpoints to resume from; with --levels, a mesh convergence study over L refinements. `--np N`
// re-launches the same command under `mpirun -np N` (as `mpirun -np N kerf reference …` does
// directly): the solver runs distributed.

#include "apps/command_line.hpp"
#include "apps/kerf/commands.hpp"
#include "experiments/reference_run/reference_convergence.hpp"
#include "experiments/reference_run/reference_run.hpp"
#include "experiments/models/session_replay.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/quantity.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/study_runner.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "reference/mpi_processes.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

namespace kerf::cli {

namespace {

/// `kerf reference`'s default sample count (--samples).
constexpr int default_reference_samples = 40;

struct ReferenceOptions {
  std::string scene;
  std::string out;
  int degree = 0; ///< 0: the scene's element_degree
  int refine = 0;
  /// Trajectory samples solved: N evenly spaced (first and last included), or "all". The default
  /// is one a user can wait for on a scene's mesh (a few minutes on two cores), fine enough to
  /// draw the force-travel curve.
  std::string samples = std::to_string(default_reference_samples);
  double until = -1.0; ///< < 0: the whole trajectory; else only samples with t <= until [s]
  int levels = 0;      ///< 0: one run; >= 3: a convergence study over that many refinements
  std::string element_size; ///< overrides the scene's element size ("5 mm"); empty = the scene's
  std::string grasp_element_size; ///< overrides the grasp rims' derived element size; empty = derived
  bool resume = false;
  std::string fracture = "auto";
  std::string mesh = "reference"; ///< "reference": the scene meshed for the reference (graded); "scene": its own mesh
  double adaptive = StudyReferenceSpec{}.adaptive; ///< adaptive sampling: the force change (fraction of the peak) that inserts a sample, a study's default; 0: off
  double min_travel_mm = 0.05; ///< adaptive sampling: the least tool travel between two samples [mm]
  double vertex_tolerance_mm = ReferenceRunSettings{}.vertex_tolerance * 1e3; ///< the load path's vertices [mm]
  double viscous_time = 0.0; ///< τ [s] of the cohesive law's viscous regularisation (0: none)
  bool dynamic = false;      ///< the dynamic (inertial) step instead of the quasi-static one
  bool no_damping = false;   ///< dynamic step: leave the scene's Kelvin–Voigt damping out
  double interface_tolerance = ReferenceRunSettings{}.interface_error_relative; ///< dynamic + fracture: kinks control
  bool no_fields = false;
  std::string trajectory; ///< a haptic session file whose tool positions replace the scene's trajectories
  reference::LinearSolverChoice solver = reference::LinearSolverChoice::automatic;
  int np = 0; ///< MPI processes; 0 = this process alone (or as many as mpirun started)
};

/// Replaces this process by `mpirun -np N <this program> reference …` with the same options
/// (--oversubscribe when N exceeds the cores; as root, Open MPI's OMPI_ALLOW_RUN_AS_ROOT[_CONFIRM]
/// set, without which it refuses to start). Returns only by throwing.
[[noreturn]] void relaunch_under_mpirun(const ReferenceOptions& o) {
  const std::string program = std::filesystem::read_symlink("/proc/self/exe").string();
  std::vector<std::string> args{"mpirun", "-np", std::to_string(o.np)};
  if (static_cast<unsigned>(o.np) > std::thread::hardware_concurrency()) args.emplace_back("--oversubscribe");
  args.insert(args.end(), {program, "reference", o.scene, "--refine", std::to_string(o.refine)});
  if (o.degree > 0) args.insert(args.end(), {"--degree", std::to_string(o.degree)});
  args.insert(args.end(), {"--samples", o.samples});
  if (o.until >= 0.0) args.insert(args.end(), {"--until", std::to_string(o.until)});
  if (o.levels > 0) args.insert(args.end(), {"--levels", std::to_string(o.levels)});
  if (!o.element_size.empty()) args.insert(args.end(), {"--element-size", o.element_size});
  if (!o.grasp_element_size.empty()) args.insert(args.end(), {"--grasp-element-size", o.grasp_element_size});
  args.insert(args.end(), {"--fracture", o.fracture, "--mesh", o.mesh});
  args.insert(args.end(), {"--adaptive", std::to_string(o.adaptive), "--min-travel", std::to_string(o.min_travel_mm)});
  char tolerance[32];
  std::snprintf(tolerance, sizeof tolerance, "%.17g", o.vertex_tolerance_mm);
  args.insert(args.end(), {"--vertex-tolerance", tolerance});
  if (o.viscous_time > 0.0) args.insert(args.end(), {"--cohesive-viscous-time", std::to_string(o.viscous_time)});
  if (o.dynamic) args.emplace_back("--dynamic");
  if (o.no_damping) args.emplace_back("--no-damping");
  args.insert(args.end(), {"--interface-energy-tolerance", std::to_string(o.interface_tolerance)});
  if (!o.out.empty()) args.insert(args.end(), {"-o", o.out});
  if (o.resume) args.emplace_back("--resume");
  if (o.no_fields) args.emplace_back("--no-fields");
  if (!o.trajectory.empty()) args.insert(args.end(), {"--trajectory", o.trajectory});
  const char* solver = o.solver == reference::LinearSolverChoice::direct      ? "direct"
                       : o.solver == reference::LinearSolverChoice::iterative ? "iterative"
                                                                               : "auto";
  args.insert(args.end(), {"--solver", solver});
  if (::geteuid() == 0) {
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  }
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  ::execvp("mpirun", argv.data());
  throw std::runtime_error(std::string("--np ") + std::to_string(o.np) + ": cannot run mpirun: " + std::strerror(errno));
}

void run_reference_command(const ReferenceOptions& o) {
  namespace fs = std::filesystem;
  const int launched = reference::mpirun_process_count();
  if (o.np > 1 && launched == 0) relaunch_under_mpirun(o);
  if (o.np > 0 && launched > 0 && o.np != launched)
    throw std::invalid_argument("--np " + std::to_string(o.np) + " but mpirun started " + std::to_string(launched) +
                                " processes");
  const Scene read = read_scene(resolve_scene(o.scene));
  const fs::path out = o.out.empty() ? fs::path("runs") / read.name / "reference" : fs::path(o.out);
  // A recorded session replays what the hand did at the rig through the ground truth.
  Scene scene = o.trajectory.empty() ? read : replay_session(read, o.trajectory, out);
  if (!o.element_size.empty()) scene.geometry.element_size = parse_quantity(o.element_size, Dimension::length);
  if (!o.grasp_element_size.empty()) {
    const double size = parse_quantity(o.grasp_element_size, Dimension::length);
    if (!(size > 0.0)) throw std::invalid_argument("--grasp-element-size " + o.grasp_element_size + ": expected a positive length");
    scene.geometry.grasp_element_size = size;
  }
  ReferenceRunSettings settings;
  settings.degree = o.degree > 0 ? o.degree : scene.geometry.element_degree;
  settings.refinements = o.refine;
  settings.write_fields = !o.no_fields;
  settings.resume = o.resume;
  settings.linear_solver = o.solver;
  settings.fracture = o.fracture == "on" ? ReferenceFracture::on : o.fracture == "off" ? ReferenceFracture::off : ReferenceFracture::automatic;
  settings.cohesive_viscous_time = o.viscous_time;
  settings.adaptive_force_change = o.samples == "all" ? 0.0 : o.adaptive; // every sample: nothing to insert
  settings.adaptive_min_travel = o.min_travel_mm * 1e-3;
  settings.vertex_tolerance = o.vertex_tolerance_mm * 1e-3;
  settings.dynamic = o.dynamic;
  settings.damping = !o.no_damping;
  settings.interface_error_relative = o.interface_tolerance;
  if (o.interface_tolerance == 0.0) settings.interface_error_floor = 0.0; // the control off
  int samples = 0; // 0: every sample
  if (o.samples != "all") {
    std::size_t used = 0;
    try {
      samples = std::stoi(o.samples, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != o.samples.size() || samples < 1)
      throw std::invalid_argument("--samples: expected a count >= 1 or \"all\", got \"" + o.samples + "\"");
  }
  {
    if (scene.tools.empty()) throw std::invalid_argument("scene '" + scene.name + "' has no tool");
    const SampledTrajectory path = sample(scene.tools.front().trajectory);
    // Samples are in time order: the first `count` have t <= until.
    std::size_t count = path.samples.size();
    if (o.until >= 0.0) {
      count = 0;
      while (count < path.samples.size() && path.samples[count].time <= o.until + 1e-12) ++count;
      if (count == 0) throw std::invalid_argument("--until " + std::to_string(o.until) + " s is before the first sample");
    }
    if (samples > 0 && static_cast<std::size_t>(samples) < count) {
      settings.sample_indices = reference_sample_indices(count, samples);
    } else {
      for (std::size_t k = 0; k < count; ++k) settings.sample_indices.push_back(k);
    }
  }
  const auto begin = std::chrono::steady_clock::now();
  const TetMesh mesh = scene_mesh(scene, o.mesh == "scene" ? MeshPurpose::scene : MeshPurpose::reference);
  if (o.levels > 0) {
    if (o.resume) throw std::invalid_argument("--resume does not apply to a convergence study (--levels)");
    const fs::path dir = o.out.empty() ? fs::path("runs") / read.name / "reference_convergence" : fs::path(o.out);
    const ConvergenceStudy study = run_reference_convergence(scene, mesh, settings, o.levels, dir);
    if (reference::mpi_processes().rank != 0) return; // rank 0 reports
    std::printf("%s", convergence_markdown(scene, study).c_str());
    std::printf("wrote %s, %s\n", (dir / "convergence.csv").c_str(), (dir / "convergence.md").c_str());
    return;
  }
  const ReferenceResult result = run_reference(scene, mesh, settings, out);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const bool reporter = reference::mpi_processes().rank == 0;
  double peak = 0.0;
  for (const ProfileRow& r : result.profile.rows) peak = std::max(peak, r.force.norm());
  if (reporter) {
    std::printf("%s / reference (P%d, %d refinements): %zu samples solved, peak |F| %.6g N, wall %.2f s\n",
                scene.name.c_str(), settings.degree, o.refine, result.profile.rows.size(), peak, wall);
    std::printf("wrote %s, %s%s\n", (out / "profile.csv").c_str(), (out / "manifest.json").c_str(),
                settings.write_fields ? (", " + (out / "fields.pvd").string()).c_str() : "");
  }
  // A load path that stopped is no finished reference: the program says so in its status
  // (apps/command_line.hpp), on every process, after the partial files are written.
  if (!result.complete())
    throw IncompleteRun(exit_reference_stopped, "the load path stopped before the trajectory's end (partial profile in " +
                                                    (out / "profile.csv").string() + "): " + result.stopped);
}

} // namespace

void add_reference_command(CLI::App& app) {
  auto options = std::make_shared<ReferenceOptions>();
  auto* cmd = app.add_subcommand("reference", "finite-strain reference run on a scene: profile.csv, manifest.json, fields.pvd");
  cmd->add_option("scene", options->scene, "scene file or name")->required();
  cmd->add_option("--degree", options->degree, "finite element degree (default: the scene's element_degree, else 1)")
      ->check(CLI::IsMember({1, 2}));
  cmd->add_option("--refine", options->refine, "global mesh refinements")->check(CLI::Range(0, 4));
  cmd->add_option("--samples", options->samples,
                  "solve N evenly spaced trajectory samples, first and last included, or \"all\" (default " +
                      std::to_string(default_reference_samples) + ")");
  cmd->add_option("--until", options->until, "solve only trajectory samples with t <= T seconds")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--levels", options->levels,
                  "mesh convergence: run at L successive refinements (from --refine) into DIR/refine_K and "
                  "report the observed order (DIR default runs/SCENE/reference_convergence)")
      ->check(CLI::Range(3, 5));
  cmd->add_option("--element-size", options->element_size,
                  "mesh the scene with this element size instead of its own (a length, e.g. \"5 mm\")");
  cmd->add_option("--grasp-element-size", options->grasp_element_size,
                  "the element size on each grasp rim instead of the one derived from the scene (a length; for a study of "
                  "the rim's resolution, docs/reference.md)");
  cmd->add_option("-o,--output", options->out, "output directory (default runs/SCENE/reference)");
  cmd->add_flag("--resume", options->resume, "continue from DIR/checkpoint.bin");
  cmd->add_flag("--no-fields", options->no_fields, "do not write fields.pvd and the .vtu files");
  const std::map<std::string, reference::LinearSolverChoice> solvers{
      {"auto", reference::LinearSolverChoice::automatic},
      {"direct", reference::LinearSolverChoice::direct},
      {"iterative", reference::LinearSolverChoice::iterative}};
  cmd->add_option("--solver", options->solver,
                  "linear solver: auto (direct up to 60000 DOFs, and above while CHOLMOD predicts a factor of at most 1e8 entries; iterative above either), direct (CHOLMOD Cholesky for a symmetric positive definite tangent, else UMFPACK LU; MUMPS under MPI) or iterative "
                  "(PETSc CG + GAMG)")
      ->transform(CLI::CheckedTransformer(solvers, CLI::ignore_case));
  cmd->add_option("--np", options->np,
                  "run distributed on N MPI processes: re-launches this command under mpirun -np N")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--fracture", options->fracture,
                  "cohesive fracture along the scene's cut_plane: auto (default: on for a scene that declares cutting or "
                  "tearing and gives cohesive_strength and fracture_toughness), on, off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cmd->add_option("--mesh", options->mesh,
                  "reference: the scene meshed for the reference, graded where the physics needs it (default); scene: "
                  "the scene's own mesh, as the fast models see it (docs/reference.md)")
      ->check(CLI::IsMember({"reference", "scene"}));
  cmd->add_option("--adaptive", options->adaptive,
                  "adaptive sampling: where the force changes by more than this fraction of its peak between two "
                  "samples, or the interaction mode changes (contact, rupture, cutting), solve the sample half way "
                  "first, down to --min-travel (default 0.2, as a study's; 0: only the --samples and the trajectory's vertices)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--min-travel", options->min_travel_mm,
                  "adaptive sampling: the least tool travel between two samples, in mm (default 0.05)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--vertex-tolerance", options->vertex_tolerance_mm,
                  "the load path: besides the --samples, every vertex of the tool's motion is solved (a segment's end, "
                  "a dwell's start and end, a recorded hand's turn): where the motion leaves the straight line in time "
                  "between its neighbouring vertices by more than this distance, in mm (default 0.001)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--cohesive-viscous-time", options->viscous_time,
                  "viscous regularisation of the cohesive law (Gao & Bower 2004): relaxation time TAU in seconds, "
                  "eta = sigma_c TAU / delta_f (default 0: none); its dissipation is in the manifest's energy")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--dynamic", options->dynamic,
                "dynamic (inertial) step: implicit Newmark average acceleration with the consistent mass of the "
                "scene's density; the kinetic energy joins the manifest's energy");
  cmd->add_flag("--no-damping", options->no_damping,
                "with --dynamic: leave out the scene's Kelvin-Voigt damping (its viscous stress (eta/E) C0 : dE/dt "
                "and the damping dissipation in the manifest's energy)");
  cmd->add_option("--interface-energy-tolerance", options->interface_tolerance,
                  "with --dynamic and fracture: reject and halve a step whose time-integration error at the cohesive "
                  "law's kinks exceeds REL x its cohesive dissipation + 1e-5 J_c A (default 0.005; 0: off)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--trajectory", options->trajectory,
                  "a haptic session file (kerf-rig haptic --record): its tool positions replace the scene's trajectories");
  cmd->callback([options] { run_reference_command(*options); });
}

} // namespace kerf::cli

// kerf calibrate SCENE --model M [--trajectory SESSION] [--target PROFILE.csv] [-o params.toml]:
// fit a fast model's free parameters to the reference (or to any target profile) on a calibration
// trajectory, validate on held-out trajectories, and write a parameter file a scene includes
// (docs/studies.md, "Calibration").

#include "experiments/calibration/calibration.hpp"
#include "apps/kerf/commands.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "experiments/models/session_replay.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/reference_cache.hpp"
#include "experiments/study/stability_sweep.hpp"
#include "experiments/study/study_runner.hpp"
#include "experiments/study/study_table.hpp"

#include "meshes/atomic_file.hpp"

#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

namespace kerf::cli {

namespace {

struct CalibrateOptions {
  std::string scene;
  std::string model;
  std::string trajectory;            ///< a haptic session replacing the scene's trajectory
  std::string target;                ///< a profile CSV to fit instead of the reference
  std::vector<std::string> validate; ///< held-out haptic sessions (scored against the reference)
  std::string out;
  std::string work;                  ///< reference runs (cached) and replayed trajectories
  int samples = 12;
  int refine = 0;
  int max_evaluations = 150;
  bool fixed_exponents = false;
};

/// The reference on `scene` at mesh level `refine` (a study's level: the scene meshed anew at
/// 2^-refine times its element size, study_reference_scene), `samples` solves, cached in `dir` under
/// the key of the scene, its trajectory and the solver settings (reference_cache.hpp), written as
/// dir/key.txt.
ForceProfile reference_profile(const Scene& scene_file, int refine, int samples, const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  const Scene scene = study_reference_scene(scene_file, refine);
  StudyReferenceSpec spec;
  spec.refinements = {refine};
  spec.samples = samples;
  std::size_t n = 0;
  for (const auto& t : sample_scene_trajectories(scene)) n = std::max(n, t.samples.size());
  const std::vector<std::size_t> indices = reference_sample_indices(n, samples);
  const ReferenceCacheKey key = reference_cache_key(scene, study_reference_settings(spec, scene, refine, indices));
  std::ostringstream cached;
  if (std::ifstream k(dir / "key.txt"); k) cached << k.rdbuf();
  if (cached.str() == key.text && fs::exists(dir / "profile.csv")) return read_profile_csv(dir / "profile.csv");
  const ReferenceResult r = finite_element_reference()(StudyReferenceSolve{scene, refine, indices, LoadIncrement::whole, dir, key.text}, spec);
  if (!r.complete())
    throw std::runtime_error("the reference on " + scene.name + " stopped before the trajectory's end, a fit to it would fit a partial "
                             "profile: " + r.stopped);
  if (!fs::exists(dir / "profile.csv")) write_profile_csv(r.profile, dir / "profile.csv");
  write_atomically(dir / "key.txt", [&](const fs::path& tmp) { std::ofstream(tmp) << key.text; });
  return r.profile;
}

std::string describe(const CalibratedParameters& p) {
  std::string out;
  const auto free = free_parameters(p.model);
  for (std::size_t k = 0; k < free.size(); ++k) {
    char item[128];
    std::snprintf(item, sizeof item, "%s%s = %.5g%s%s", out.empty() ? "" : ", ", std::string(free[k].symbol).c_str(),
                  p.values[k] / free[k].unit_value, free[k].unit.empty() ? "" : " ", std::string(free[k].unit).c_str());
    out += item;
  }
  if (p.deformation_1_exponent) out += ", i = " + std::to_string(*p.deformation_1_exponent);
  if (p.deformation_2_exponent) out += ", j = " + std::to_string(*p.deformation_2_exponent);
  return out;
}

void run_calibrate(const CalibrateOptions& o) {
  namespace fs = std::filesystem;
  const Scene read = read_scene(resolve_scene(o.scene));
  const fs::path work = o.work.empty() ? fs::path("runs") / read.name / o.model / "calibration" : fs::path(o.work);
  const fs::path out = o.out.empty() ? work / "parameters.toml" : fs::path(o.out);
  fs::create_directories(work);
  if (out.has_parent_path()) fs::create_directories(out.parent_path());
  require_model_for_scene(o.model, read);
  const Scene scene = o.trajectory.empty() ? read : replay_session(read, o.trajectory, work / "calibration_trajectory");
  const TetMesh mesh = scene_mesh(scene);

  CalibrationTarget target{o.target.empty() ? "reference L" + std::to_string(o.refine) : o.target, scene, {}};
  target.profile = o.target.empty() ? reference_profile(scene, o.refine, o.samples, work / "reference_calibration")
                                    : read_profile_csv(o.target);
  CalibrationSettings settings;
  settings.simplex.max_evaluations = o.max_evaluations;
  settings.fit_exponents = !o.fixed_exponents;
  std::printf("calibrating %s on %s against %s (%zu target rows): Nelder-Mead on ln(parameters)\n", o.model.c_str(),
              scene.name.c_str(), target.label.c_str(), target.profile.rows.size());
  const CalibrationResult r = calibrate(o.model, target, mesh, settings);

  // Held-out trajectories: the scripted trajectory at half and double speed, and recorded sessions.
  struct HeldOut {
    std::string label;
    Scene scene;
  };
  std::vector<HeldOut> held_out;
  bool scripted = true;
  for (const Tool& t : scene.tools) scripted = scripted && t.trajectory.recorded_file.empty();
  if (scripted)
    for (double f : {0.5, 2.0}) held_out.push_back({"speed x" + std::string(f < 1 ? "0.5" : "2"), scaled_scene(scene, "speed", f)});
  for (std::size_t k = 0; k < o.validate.size(); ++k)
    held_out.push_back({o.validate[k], replay_session(read, o.validate[k], work / ("held_out_" + std::to_string(k)))});

  StudyTable table({{"trajectory", "", 3, 1.0},
                    {"target", "", 3, 1.0},
                    {"RMS error before", "%", 3, 100.0},
                    {"RMS error after", "%", 3, 100.0},
                    {"note", "", 3, 1.0}});
  using O = std::optional<double>;
  table.add_row({std::string("calibration"), target.label, O(r.initial_error), O(r.fitted_error), std::string()});
  for (std::size_t k = 0; k < held_out.size(); ++k) {
    const HeldOut& h = held_out[k];
    try {
      const ForceProfile ref = reference_profile(h.scene, o.refine, o.samples, work / ("reference_held_out_" + std::to_string(k)));
      const TetMesh& m = mesh; // same body; only the trajectory differs
      table.add_row({h.label, "reference L" + std::to_string(o.refine),
                     O(profile_error(o.model, with_parameters(h.scene, r.initial), m, ref)),
                     O(profile_error(o.model, with_parameters(h.scene, r.fitted), m, ref)), std::string()});
    } catch (const std::exception& e) {
      table.add_row({h.label, std::string("reference L") + std::to_string(o.refine), O(), O(),
                     std::string("not validated: ") + e.what()});
    }
  }

  std::string comment = "Calibrated by: kerf calibrate " + o.scene + " --model " + o.model +
                        (o.trajectory.empty() ? "" : " --trajectory " + o.trajectory) +
                        (o.target.empty() ? "" : " --target " + o.target) + "\n";
  comment += "Scene " + scene.name + " (" + scene.file.string() + "), target: " + target.label + ", " +
             std::to_string(target.profile.rows.size()) + " rows.\n";
  comment += "Method: Nelder-Mead simplex on ln(parameter) minimising the normalised RMS force error" +
             std::string(o.model == "fracture" && settings.fit_exponents ? ", for each exponent pair (i, j) in {1,2,3}^2" : "") +
             "; " + std::to_string(r.evaluations) + " model runs" + (r.converged ? ", converged" : ", stopped at the evaluation limit") + ".\n";
  comment += "Before: " + describe(r.initial) + "\nAfter:  " + describe(r.fitted) + "\n\n" + table.markdown() +
             "\nInclude it from a scene with   include = \"" + out.filename().string() + "\"   (docs/scenes.md).";
  const std::string text = parameter_file_text(r.fitted, comment);
  write_atomically(out, [&](const fs::path& tmp) {
    std::ofstream f(tmp);
    f << text;
    if (!f.flush()) throw std::runtime_error(out.string() + ": write failed");
  });
  std::printf("%s\nbefore: %s\nafter:  %s\n%d model runs%s\nwrote %s\n", table.markdown().c_str(), describe(r.initial).c_str(),
              describe(r.fitted).c_str(), r.evaluations, r.converged ? "" : " (evaluation limit reached)", out.c_str());
}

} // namespace

void add_calibrate_command(CLI::App& app) {
  auto options = std::make_shared<CalibrateOptions>();
  auto* cmd = app.add_subcommand("calibrate", "fit a fast model's free parameters to the reference (or a target profile), "
                                              "validate on held-out trajectories, write a parameter file a scene includes");
  cmd->add_option("scene", options->scene, "scene file or name")->required();
  cmd->add_option("--model", options->model, "fracture (f_r, δ_r, δ_c, i, j), springs (stiffness scale) or voxel (E, critical forces)")->required();
  cmd->add_option("--trajectory", options->trajectory, "a recorded haptic session to calibrate on instead of the scene's trajectory");
  cmd->add_option("--target", options->target, "fit this force profile (CSV, docs/force-profile.md) instead of the reference");
  cmd->add_option("--validate", options->validate, "held-out haptic sessions, scored against the reference (besides the scene's trajectory at half and double speed)");
  cmd->add_option("--samples", options->samples, "reference equilibrium solves per trajectory (default 12)")->check(CLI::Range(2, 100000));
  cmd->add_option("--refine", options->refine, "reference mesh level K: the scene meshed at 2^-K times its element size, as a study's level (default 0)")->check(CLI::Range(0, 4));
  cmd->add_option("--max-evaluations", options->max_evaluations, "model runs per simplex search (default 150)")->check(CLI::Range(1, 100000));
  cmd->add_flag("--fixed-exponents", options->fixed_exponents, "fracture: keep the scene's exponents i, j (default: try all nine pairs)");
  cmd->add_option("-o,--output", options->out, "parameter file to write (default WORK/parameters.toml)");
  cmd->add_option("--work", options->work, "directory for the reference runs (cached) and replayed trajectories (default runs/SCENE/MODEL/calibration)");
  cmd->callback([options] { run_calibrate(*options); });
}

} // namespace kerf::cli

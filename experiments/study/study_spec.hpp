#pragma once
// A study file (experiments/studies/NAME.toml): scenes x models x resolutions (docs/studies.md).
//
//   [study]
//   name = "default"
//   description = "…"
//   scenes = ["potato_rect_cut", "clay_pull"]      # names in experiments/scenes, or paths
//   models = ["fracture", "springs", "edge", "voxel"]   # each runs on the scenes it can represent
//
//   [reference]                                    # optional: the finite-element ground truth
//   degree = 1                                     # every scene's element degree (default: each
//                                                  # scene's own, [geometry] element_degree)
//   refinements = [0, 1]                           # mesh levels, ascending; the last is the finest;
//                                                  # level k: the scene meshed anew at 2^-k times
//                                                  # its element size (a .msh scene: refined k times)
//   samples = 40                                   # trajectory samples the reference solves
//   linear_solver = "auto"                         # "auto", "direct" or "iterative"
//   fracture = "off"                               # cohesive fracture: "off", "auto" or "on"
//   scene_refinements = { potato_rect_cut = [-3, -2, -1] }   # a scene's own levels (optional)
//   scene_degree = { clay_pull = 2 }               # a scene's own element degree (optional)
//   scene_samples = { potato_rect_cut = 48 }       # a scene's own sample count (optional)
//
//   [models.springs]                               # optional: a model at several resolutions,
//   resolutions = [4, 8, 12]                       # one row "springs [N = 4]" … each (instead of the
//                                                  # plain row): the points of its speed/accuracy
//                                                  # curve (model_resolution.hpp: springs, voxel)
//
//   [calibration]                                  # optional: calibrated rows beside the others
//   clay_pull = ["calibration/clay_pull.springs.toml"]   # parameter files (kerf calibrate -o),
//                                                  # relative to the study file; every model a file
//                                                  # calibrates also runs as "MODEL (calibrated)"
//
//   [[calibrate]]                                  # optional: a calibration fitted by the study
//   scene = "clay_pull"                            # a scene of study.scenes
//   model = "springs"                              # a model of study.models with free parameters
//   speed = 2.0                                    # the calibration trajectory: the scene's played
//                                                  # this many times as fast (!= 1): moves faster,
//                                                  # holds shorter (study_runner.hpp)
//   max_evaluations = 30                           # model runs of the fit (default 40)
//   samples = 6                                    # reference solves on the calibration trajectory
//                                                  # (default: the scene's [reference] samples)
//   # fitted to the finest reference on the calibration trajectory, then run and scored, as
//   # "MODEL (calibrated)", on the scene's own trajectory: held out from the fit.
//
// Unknown keys and wrong types are errors naming file:line:column, as for scenes.

#include "experiments/reference_run/reference_fracture.hpp"
#include "reference/finite_strain_solver.hpp"

#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf {

/// The coarsest mesh level a study takes: the scene's element size ×8.
inline constexpr int minimum_study_mesh_level = -3;

/// The finite-element reference of a study ([reference]): its discretisation and solver settings.
/// Every one of them is in the reference cache's key (reference_cache.hpp).
struct StudyReferenceSpec {
  /// FE_SimplexP degree, 1 or 2, for every scene of the study; unset: each scene's own
  /// ([geometry] element_degree, SceneGeometry::element_degree).
  std::optional<int> degree;
  /// Per-scene degrees replacing the others for the scenes named ([reference] scene_degree =
  /// { NAME = 2 }).
  std::map<std::string, int> scene_degree;
  /// The element degree of the scene named `scene`, whose file gives `scene_element_degree`:
  /// scene_degree's, else the study's `degree`, else the scene's own.
  int degree_of(const std::string& scene, int scene_element_degree) const {
    const auto it = scene_degree.find(scene);
    return it != scene_degree.end() ? it->second : degree.value_or(scene_element_degree);
  }
  /// Mesh levels, ascending; the last is the finest. Level k: the scene meshed anew at element
  /// size 2^-k h, its graded sizes scaled alike (a .msh scene: refined k >= 0 times;
  /// reference_cache.hpp, study_reference_scene). In minimum_study_mesh_level..4.
  std::vector<int> refinements{0};
  /// Per-scene mesh levels replacing `refinements` for the scenes named ([reference]
  /// scene_refinements = { NAME = [levels] }): a scene whose finest level costs more than a study
  /// can spend is verified on coarser ones, and its row says so (it may fail its resolution check).
  std::map<std::string, std::vector<int>> scene_refinements;
  /// The mesh levels of the scene named `scene`: its own, else `refinements`.
  const std::vector<int>& levels_of(const std::string& scene) const {
    const auto it = scene_refinements.find(scene);
    return it == scene_refinements.end() ? refinements : it->second;
  }
  int samples = 40; ///< equilibrium solves along each trajectory (evenly spaced samples)
  /// Per-scene sample counts replacing `samples` for the scenes named ([reference] scene_samples =
  /// { NAME = N }): a scene whose force has finer structure (a cut's crack front advancing element
  /// by element) needs more samples for its RMS over the trajectory to converge with the mesh.
  std::map<std::string, int> scene_samples;
  /// The sample count of the scene named `scene`: its own, else `samples`.
  int samples_of(const std::string& scene) const {
    const auto it = scene_samples.find(scene);
    return it == scene_samples.end() ? samples : it->second;
  }
  /// Linear solver of each Newton step (reference/finite_strain_solver.hpp): "auto" (direct below
  /// 60 000 DOFs, and above while the Cholesky factor stays small), "direct" (UMFPACK) or "iterative" (PETSc CG + GAMG).
  reference::LinearSolverChoice linear_solver = reference::LinearSolverChoice::automatic;
  /// Cohesive fracture along the scene's cut_plane (experiments/reference_run/reference_fracture.hpp): "off"
  /// (default, as `kerf reference`), "auto" or "on".
  ReferenceFracture fracture = ReferenceFracture::off;
  /// The reference library ([reference] library, a folder relative to the study file): solved
  /// references kept with the study, each in a folder named by its cache key (reference_cache.hpp)
  /// with its key.txt. A solve whose key the library holds is taken from it instead of solved;
  /// any other is solved. Empty: none.
  std::filesystem::path library;
};

/// A calibration the study fits itself ([[calibrate]]): `model`'s free parameters
/// (experiments/calibration/free_parameters.hpp) fitted to the finest reference level on the
/// calibration trajectory — the scene's trajectory played `speed` times as fast (calibration_scene,
/// study_runner.hpp) — and
/// the fitted model scored on the scene's own trajectory, which the fit never saw.
struct StudyCalibrationFit {
  std::string scene;         ///< scene name (a study scene's file stem)
  std::string model;         ///< catalogue name; fracture, springs or voxel
  double speed = 2.0;        ///< the calibration trajectory is played this many times as fast (> 0, != 1)
  int max_evaluations = 40;  ///< model runs per simplex search (>= 1)
  int samples = 0;           ///< reference solves on the calibration trajectory; 0: the study's [reference] samples
};

struct StudySpec {
  std::filesystem::path file;
  std::string name;
  std::string description;
  std::vector<std::filesystem::path> scenes; ///< resolved scene files
  std::vector<std::string> models;
  bool has_reference = false;
  StudyReferenceSpec reference;
  /// Parameter files per scene name ([calibration]): each model one of them calibrates is run a
  /// second time on the scene with the file included, as the row "MODEL (calibrated)".
  std::map<std::string, std::vector<std::filesystem::path>> calibrations;
  /// Calibrations fitted by the study ([[calibrate]]); each adds the row "MODEL (calibrated)".
  std::vector<StudyCalibrationFit> fits;
  /// Resolutions per model ([models.NAME] resolutions, model_resolution.hpp), ascending and
  /// distinct: the model runs once at each instead of once at the scene's own resolution.
  std::map<std::string, std::vector<int>> resolutions;
};

class StudyError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// Reads and validates a study file; scene names resolve against the study file's folder, then
/// experiments/scenes. Model names must be in the catalogue.
StudySpec read_study(const std::filesystem::path& file);

/// The models a parameter file calibrates: the names of its [models.*] tables. Throws StudyError
/// naming the file on a syntax error.
std::vector<std::string> calibrated_models(const std::filesystem::path& parameter_file);

} // namespace kerf

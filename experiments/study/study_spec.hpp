#pragma once
// A study file (experiments/studies/NAME.toml): scenes x models x resolutions, the reference's
// settings and calibrations. Its format — every table and key with its type, default and meaning —
// is described once, in docs/studies.md ("Study file"); the reader is study_spec.cpp.

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
  /// Output samples of each reference solve, evenly spaced in time over the trajectory; every
  /// vertex of the motion is solved too (a segment's end, a dwell's start and end), and adaptive
  /// sampling adds samples where the force or the mode changes (`adaptive`).
  int samples = 40;
  /// Per-scene sample counts replacing `samples` for the scenes named ([reference] scene_samples =
  /// { NAME = N }): a scene whose force has finer structure (a cut's crack front advancing element
  /// by element) needs more samples for its RMS over the trajectory to converge with the mesh.
  std::map<std::string, int> scene_samples;
  /// The sample count of the scene named `scene`: its own, else `samples`.
  int samples_of(const std::string& scene) const {
    const auto it = scene_samples.find(scene);
    return it == scene_samples.end() ? samples : it->second;
  }
  /// Adaptive sampling of every reference solve (ReferenceRunSettings::adaptive_force_change): where
  /// the force leaves the straight line through the samples before it by more than this fraction of
  /// its peak, or the interaction mode changes, the sample half way is solved first, down to a
  /// tool travel of 1/40 of the scene's own element size between two samples (the same at every
  /// mesh level). 0: off. The default, 20 % of the peak, resolves events and kinks (a release on
  /// the retreat) without chasing the few-percent saw-tooth of a crack front that advances element
  /// by element (which the verification in time measures instead).
  double adaptive = 0.2;
  /// Verification in time (reference_verification.hpp): the finest level solved a second time with
  /// half the load increment — 2N − 1 requested samples (the N of the first solve among them),
  /// the adaptive sampling's least travel halved — and the difference of the two profiles reported
  /// as the sampling uncertainty, beside the mesh's.
  bool time_verification = true;
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

/// A study file that cannot be used. what() reads "FILE:LINE:COLUMN: KEY: what was expected, got
/// what was written", as for scene files.
class StudyError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// Reads and validates a study file; scene names resolve against the study file's folder, then
/// experiments/scenes. Model names must be in the catalogue. Unknown keys, wrong types and values
/// out of range are StudyErrors.
StudySpec read_study(const std::filesystem::path& file);

/// The models a parameter file calibrates: the names of its [models.*] tables. Throws StudyError
/// naming the file on a syntax error.
std::vector<std::string> calibrated_models(const std::filesystem::path& parameter_file);

} // namespace kerf

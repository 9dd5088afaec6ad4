#pragma once
// Calibration (docs/studies.md): a fast model's free parameters (free_parameters.hpp) fitted to a target
// force profile — the finite-element reference, a measured profile, or one the model itself
// generated — by minimising the normalised RMS force error (profile_metrics.hpp) with the
// Nelder–Mead simplex (nelder_mead.hpp, which says why that method) over the logarithms of the
// parameters (so every trial value stays positive and a factor of two is one step whatever the
// unit). The result is written as a parameter file a scene includes.

#include "experiments/calibration/free_parameters.hpp"
#include "experiments/calibration/nelder_mead.hpp"
#include "formats/profile/force_profile.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene.hpp"
#include "meshes/tet_mesh.hpp"

#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// The values of a model's free parameters.
struct CalibratedParameters {
  std::string model;
  std::vector<double> values; ///< SI, in the order of free_parameters(model)
  /// Fracture only: the exponents i of f1 and j of f2 (paper 001 §6: 1, 2 or 3).
  std::optional<int> deformation_1_exponent, deformation_2_exponent;
};

/// The parameters `scene` gives `model` now (its scene sections; the spring scale defaults to 1).
/// Throws ModelMismatch if the scene lacks the model's section, std::invalid_argument if the model
/// has no free parameters.
CalibratedParameters scene_parameters(const std::string& model, const Scene& scene);

/// `scene` with `p` written into its model section.
Scene with_parameters(const Scene& scene, const CalibratedParameters& p);

/// The normalised RMS force error of `model` built for `scene` (on `mesh`) and run along the
/// scene's trajectories, against `target` on the samples both have (mean over the scene's tools
/// that the target holds). Throws std::invalid_argument if they share no sample or the target
/// carries no force (the error is then undefined).
double profile_error(const std::string& model, const Scene& scene, const TetMesh& mesh, const ForceProfile& target);

/// A profile to fit and the scene (trajectory) it was taken on.
struct CalibrationTarget {
  std::string label;     ///< what it is ("reference L0", "self-generated", a file)
  Scene scene;           ///< its trajectory; its model section is the starting guess
  ForceProfile profile;  ///< any subset of the trajectory's samples
};

struct CalibrationSettings {
  NelderMeadSettings simplex{150, 1e-4, 1e-12, 0.5}; ///< on ln(parameter): 1e-4 = 0.01 % of the value
  bool fit_exponents = true; ///< fracture: try every (i, j) in {1,2,3}², keep the best fit
  /// Fracture with fit_exponents: each of the nine pairs is first screened with a simplex of at
  /// most this many runs; the `refined_pairs` best then continue from where they stopped, with
  /// `simplex` (the nine pairs cost 9 x screening + refined_pairs x a full search, not 9 x a full
  /// search). Several are refined because a wrong pair can lead after a short screening (f2's
  /// exponent j and δ_c trade off on the unloading alone).
  int screening_evaluations = 40;
  int refined_pairs = 3;
};

struct CalibrationResult {
  CalibratedParameters initial, fitted;
  double initial_error = 0.0; ///< normalised RMS force error with the starting guess
  double fitted_error = 0.0;  ///< ... with the fitted parameters
  int evaluations = 0;        ///< model runs, all simplex searches together
  bool converged = false;     ///< the winning simplex met its tolerance
};

/// Fits `model`'s free parameters to `target`. `mesh` is the target scene's mesh (the parameters
/// change no geometry).
CalibrationResult calibrate(const std::string& model, const CalibrationTarget& target, const TetMesh& mesh,
                            const CalibrationSettings& settings = {});

/// The parameter file for `p`: `# ` + each line of `comment`, then `[models.<model>]` with every
/// fitted key written with its unit (so the scene reader converts it as any other value).
std::string parameter_file_text(const CalibratedParameters& p, const std::string& comment);

} // namespace kerf

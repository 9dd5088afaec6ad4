#pragma once
// Stability at the extremes (docs/studies.md): a model run on a scene whose numbers are pushed one axis at
// a time — servo rate, stiffness over six decades, toughness, tool speed, near-incompressibility,
// mesh size — and every run classified. Every model must fail gracefully past its edge: a clear
// refusal or a guarded state, never a NaN force and never a crash.

#include "formats/scene/scene.hpp"

#include <string>
#include <vector>

namespace kerf {

/// How one run ended.
enum class StabilityClass {
  bounded,     ///< forces finite, within the physical scale, no sustained oscillation
  oscillating, ///< force increments reverse sign in more than `oscillation_fraction` of samples
  diverged,    ///< peak force beyond `divergence_factor` times the expected scale
  non_finite,  ///< a NaN or Inf force left the model (a contract violation)
  refused      ///< the model declined the parameters with a message (graceful)
};
std::string_view to_string(StabilityClass c);

/// One axis of the sweep: its name and the values it takes. Axes: "rate" and "speed" and
/// "stiffness" and "toughness" and "element_size" are factors on the scene's nominal value;
/// "poisson" takes absolute values of ν.
struct StabilityAxis {
  std::string name;
  std::vector<double> values;
};

/// The default sweep: rate ×(1/4 … 16), stiffness ×(1e-3 … 1e3: six decades), toughness
/// ×(1e-2 … 1e2), speed ×(0.1 … 100), poisson (0.3, 0.45, 0.49, 0.499), element size ×(0.5, 2).
std::vector<StabilityAxis> default_stability_axes();

struct StabilitySettings {
  std::vector<StabilityAxis> axes = default_stability_axes();
  double divergence_factor = 100.0;  ///< diverged above this × the expected peak force
  double oscillation_fraction = 0.1; ///< oscillating above this fraction of reversing increments
};

/// One point of the sweep.
struct StabilityPoint {
  std::string axis;
  double value = 0.0;
  StabilityClass outcome = StabilityClass::bounded;
  double peak_force = 0.0;       ///< [N], over all tools and samples
  double expected_scale = 0.0;   ///< [N], the nominal peak scaled by the axis where forces scale
  double reversal_fraction = 0.0;
  std::string note;              ///< the refusal message, or what was guarded
};

/// Applies `value` of axis `axis` to a copy of `nominal` (see StabilityAxis). Stiffness scales E
/// and every stiffness-like model parameter (paper 001's f_r, lateral and pre-sliding stiffness;
/// paper 002's elastic coefficient); toughness scales J_c of the body and every layer.
/// Throws std::invalid_argument for an unknown axis.
Scene scaled_scene(const Scene& nominal, const std::string& axis, double value);

/// The documented edge of a model: one Markdown list item per axis, in sweep order, naming the
/// tested values where the model stayed bounded and every value where it did not, with the class
/// (and, for a refusal, its message): "- stiffness ×1e-3 … ×1e3: bounded at all 6" or
/// "- rate ×0.25 … ×16: bounded at ×0.5 … ×16; ×0.25 oscillating (38 % reversing)". Factors are
/// on the nominal scene; Poisson's ratio is absolute.
std::string stability_edges(const std::vector<StabilityPoint>& points);

/// Runs `model` on the nominal scene and on every point of the sweep and classifies each run.
/// Throws only if the nominal run itself fails (the sweep then has no scale to judge by).
std::vector<StabilityPoint> stability_sweep(const Scene& nominal, const std::string& model,
                                            const StabilitySettings& settings = {});

} // namespace kerf

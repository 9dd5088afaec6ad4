#pragma once
// How far a model's force profile is from the reference's on the same trajectory samples
// (../shared/DESIGN.md, "Measures that every study reports").

#include "experiments/profile/force_profile.hpp"

#include <optional>
#include <string>

namespace kerf {

/// The measures of one model against the reference, for one tool. Errors are signed where a sign
/// means something (model minus reference) and relative where a scale exists.
struct ProfileMetrics {
  std::size_t samples = 0;            ///< samples compared (rows of this tool in both profiles)
  /// sqrt(mean_k |f_m,k - f_r,k|^2) / max_k |f_r,k|: RMS of the force difference over the
  /// trajectory, normalised by the reference's peak force magnitude.
  double normalised_rms_force_error = 0.0;
  /// (max_k |f_m,k| - max_k |f_r,k|) / max_k |f_r,k|.
  double peak_force_error = 0.0;
  /// Tool travel from its first sample to the first `rupture` sample, model minus reference [m];
  /// empty when either profile has no rupture.
  std::optional<double> rupture_displacement_error;
  /// Mean force along `axis` over the model's `cutting` samples, relative to the expected steady
  /// cutting force (paper 001 Eq. 10: J_c l): (f_mean - J_c l) / (J_c l); empty without cutting
  /// samples or without an expected value.
  std::optional<double> steady_cutting_force_error;
  /// (W_m - W_r) / |W_r|, W the work the tool does on the body (trapezoidal rule) [–].
  double work_error = 0.0;
  /// Fraction of samples where both profiles report the same interaction mode.
  double mode_agreement = 0.0;
  /// max_k |f_r,k| over the compared samples [N]: the scale of the relative measures, so that an
  /// error can be set beside the reference's own uncertainty in newtons.
  double reference_peak_force = 0.0;
};

/// The steady cutting force a blade should feel (paper 001 Eq. 10) and the direction it advances.
struct SteadyCuttingExpectation {
  double force = 0.0;                                          ///< J_c l [N] > 0
  Eigen::Vector3d cutting_direction = -Eigen::Vector3d::UnitZ(); ///< unit; the body resists along -it
};

/// Compares the rows of `tool` in `model` and `reference`. The two must hold the same samples
/// (same count, times equal to 1e-9 s): std::invalid_argument otherwise. With `cutting`, the
/// steady cutting force error is measured too. A reference with zero peak force or zero work
/// makes the relative measures undefined: std::invalid_argument.
ProfileMetrics compare_profiles(const ForceProfile& model, const ForceProfile& reference, const std::string& tool,
                                const std::optional<SteadyCuttingExpectation>& cutting = std::nullopt);

} // namespace kerf

#pragma once
// How far a model's force profile is from the reference's on the same trajectory samples
// (../shared/DESIGN.md, "Measures that every study reports").

#include "formats/profile/force_profile.hpp"

#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// The force error of a model within one phase of the reference (its interaction mode at the
/// compared times: paper 001 Fig. 11's deformation-1, rupture, cutting, deformation-2, no-contact).
struct PhaseError {
  InteractionMode mode = InteractionMode::no_contact;
  double time_fraction = 0.0;        ///< Σ_{k∈phase} w_k / Σ_k w_k: the share of the trajectory's time
  /// sqrt(Σ_{k∈phase} w_k |Δf_k|² / Σ_{k∈phase} w_k) / max_k |f_r,k|: the RMS error within the
  /// phase, on the scale of the whole profile's peak.
  double normalised_rms_force_error = 0.0;
  /// Σ_{k∈phase} w_k |Δf_k|² / Σ_k w_k |Δf_k|²: the phase's share of the squared error over the
  /// trajectory (0 when the model is exact everywhere).
  double error_share = 0.0;
};

/// The measures of one model against the reference, for one tool. Errors are signed where a sign
/// means something (model minus reference) and relative where a scale exists.
///
/// The force error is compared at the reference's output times t_k (the samples it solved), each
/// weighted by the time it stands for, w_k = (t_{k+1} − t_{k−1}) / 2 (half an interval at either
/// end): a time average over the trajectory, which does not depend on where the reference placed
/// its samples more densely (at a vertex, where adaptive sampling resolved an event).
struct ProfileMetrics {
  std::size_t samples = 0;            ///< samples compared (rows of this tool in both profiles)
  /// sqrt(Σ_k w_k |f_m,k − f_r,k|² / Σ_k w_k) / max_k |f_r,k|: the RMS of the force difference over
  /// the trajectory's time, normalised by the reference's peak force magnitude.
  double normalised_rms_force_error = 0.0;
  /// The same per phase of the reference, in the order the phases first occur.
  std::vector<PhaseError> phases;
  /// The phase with the largest share of the squared error (empty when the error is zero).
  [[nodiscard]] const PhaseError* dominant_phase() const;
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
  /// Fraction of the trajectory's time (w_k) where both profiles report the same interaction mode.
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

/// The time weights w_k of the samples at `times` (ascending): (t_{k+1} − t_{k−1}) / 2, half an
/// interval at either end; one sample alone weighs 1.
std::vector<double> sample_time_weights(const std::vector<double>& times);

/// Compares the rows of `tool` in `model` and `reference`. The two must hold the same samples
/// (same count, times equal to 1e-9 s): std::invalid_argument otherwise. With `cutting`, the
/// steady cutting force error is measured too. A reference with zero peak force or zero work
/// makes the relative measures undefined: std::invalid_argument.
ProfileMetrics compare_profiles(const ForceProfile& model, const ForceProfile& reference, const std::string& tool,
                                const std::optional<SteadyCuttingExpectation>& cutting = std::nullopt);

/// The rows of `a` whose tool and time (to 1e-9 s) also appear in `b`: the samples two runs have
/// in common — a reference that stopped early (a blade pressed further than an uncut body can
/// take) is compared on the samples it solved.
ForceProfile at_common_times(const ForceProfile& a, const ForceProfile& b);

} // namespace kerf

#pragma once
// The solution verification of a study's reference on one scene (every study does one): the scene's force profiles at its three finest mesh levels, compared on the
// samples all three solved, give the observed order, the Richardson-extrapolated value and the GCI
// (solution_verification.hpp) of two trajectory-wide quantities of the tool's force F:
//
//   RMS |F| = sqrt(Σ_k w_k |F_k|^2 / Σ_k w_k) over the common samples,   peak |F| = max_k |F_k|,
//
// (w_k the time a sample stands for, profile_metrics.hpp) and of the force profile itself, from
// the RMS of the differences between levels (difference_convergence): e21 = sqrt(Σ_k w_k |F2_k −
// F1_k|^2 / Σ_k w_k), e32 likewise. The same profile is verified in time (SamplingVerification). The profile's
// uncertainty U (in newtons, the scale of a model's RMS force error) is what the study table sets
// beside the models' RMS force errors, and the band a profile plot draws around the reference is
// the same estimate sample by sample (gci_band_half_width with the order used), or, where it is not
// available, the spread of the levels. The GCI of RMS |F| alone is no uncertainty of the profile:
// the levels' RMS values may agree by coincidence while their profiles differ sample by sample.

#include "formats/profile/force_profile.hpp"
#include "experiments/study/solution_verification.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// One level of a scene's reference: its mesh level, element size and profile.
struct ReferenceLevel {
  int level = 0;
  double element_size = 0.0; ///< [m]
  ForceProfile profile;
};

/// The verification of a scene's reference from its three finest levels.
struct ReferenceVerification {
  std::array<int, 3> levels{};            ///< finest first
  std::array<double, 3> element_sizes{};  ///< [m], finest first
  std::size_t samples = 0;                ///< samples all three levels solved (of `tool`)
  double rms_force = 0.0;                 ///< RMS |F| of the finest level [N]
  double peak_force = 0.0;                ///< peak |F| of the finest level [N]
  GridConvergence rms;                    ///< of RMS |F|
  GridConvergence peak;                   ///< of peak |F|
  DifferenceConvergence profile;          ///< of the force profile, in the RMS norm over the samples

  /// The uncertainty of the finest force profile in the RMS norm [N], when available.
  [[nodiscard]] std::optional<double> profile_uncertainty() const { return profile.uncertainty; }

  /// The uncertainty of the finest RMS |F| in newtons (GCI_fine × RMS |F|), when the GCI is available.
  [[nodiscard]] std::optional<double> rms_uncertainty() const;
  /// The uncertainty of the finest peak |F| in newtons, when the GCI is available.
  [[nodiscard]] std::optional<double> peak_uncertainty() const;
  /// One line for the study table: "GCI 1.4 % on RMS |F| = 3.17 N (p = 1.9, extrapolated 3.21 N);
  /// GCI 2 % on peak |F| = …; L-1, L0, L1 (h = 4, 2, 1 mm), 12 common samples", or why no GCI.
  [[nodiscard]] std::string summary() const;
};

/// The verification of a scene's reference in time (the load increment is a discretisation too: a
/// cut's crack front advances element by element between loads): its finest level solved with the
/// study's load increment (N requested samples) and again with half of it (2N − 1 requested, the N
/// among them, adaptive sampling's least travel halved). Two differences measure it: the two
/// profiles' difference at the output times both solved, in the time-weighted RMS norm of the
/// study's force error (profile_metrics.hpp) — the load path's effect on the solution — and the
/// shift of the time-weighted RMS |F| of each run over its own samples — the sampling's effect on
/// a time average (a crack front's element-by-element saw-tooth sampled at other phases). The
/// larger of the two is the sampling uncertainty of the finest profile.
struct SamplingVerification {
  std::size_t samples = 0;       ///< output times both runs solved (of the scored tool)
  std::size_t loads_whole = 0;   ///< samples the run at the study's increment solved
  std::size_t loads_half = 0;    ///< samples the run at half the increment solved
  double peak_force = 0.0;       ///< peak |F| of the run at the study's increment [N]
  /// sqrt(Σ_k w_k |F_k − F½_k|² / Σ_k w_k) over the common times [N].
  double rms_difference = 0.0;
  /// |RMS |F½| − RMS |F||, each the time-weighted RMS over its run's own samples [N].
  double rms_shift = 0.0;
  /// |max |F½| − max |F||, each peak over all the samples its run solved [N]: the peak a denser
  /// load path finds between the coarser one's samples.
  double peak_difference = 0.0;
  /// Where the two runs differ most: the common output time [s], the finest run's mode there, and
  /// |F| of either run [N] (a crack front that advanced by another step, a release).
  double largest_difference_time = 0.0;
  InteractionMode largest_difference_mode = InteractionMode::no_contact;
  double largest_difference_force = 0.0, largest_difference_force_half = 0.0;
  /// The sampling uncertainty [N]: max(rms_difference, rms_shift).
  [[nodiscard]] double uncertainty() const { return std::max(rms_difference, rms_shift); }
  /// "sampling uncertainty 0.8 % of the peak (…: 0.04 N RMS at 57 common times, RMS |F| moves
  /// 0.01 N, peak |F| 0.02 N; largest at t = 0.699 s, cutting: 0.141 N against 0.253 N)".
  [[nodiscard]] std::string summary() const;
};

/// The verification in time from the finest level's two runs (see SamplingVerification). Throws
/// std::invalid_argument when they share fewer than two output times of `tool`.
SamplingVerification verify_sampling(const ForceProfile& whole, const ForceProfile& half, const std::string& tool);

/// The uncertainty of the finest force profile in the study's RMS norm [N], the discretisations in
/// space and in time together: the root sum square of the two (ASME V&V 20-2009, §2-4: the
/// numerical uncertainty of independent sources combined as a root sum square), or the one that
/// is available; empty when neither is.
std::optional<double> combined_uncertainty(const std::optional<ReferenceVerification>& space,
                                           const std::optional<SamplingVerification>& time);

/// The verification from `levels` (any order; the three with the smallest element sizes are used)
/// for the rows of `tool`; `formal_order` caps the profile's observed order (the finite elements'
/// degree + 1, the L2 order of the displacement). Empty with fewer than three levels. Throws
/// std::invalid_argument when the three finest levels share fewer than two samples of `tool`.
std::optional<ReferenceVerification> verify_reference(const std::vector<ReferenceLevel>& levels, const std::string& tool,
                                                      double formal_order = 2.0);

/// The band a plot draws around the finest level's resisting force -F·d (d the unit direction of
/// advance) at each of its rows of `tool`, in row order: [low, high] [N]. With `verification`
/// usable for the profile: -F·d ± U_k, U_k = gci_band_half_width of the finest and the next level
/// at the sample, with the profile's order used. Otherwise: the minimum and maximum of -F·d over the
/// levels that solved the sample. A sample of the finest level that the next one did not solve
/// gets the spread of the levels that did (its own value alone: a zero-width band).
struct ReferenceBand {
  std::vector<double> low, high;
  bool from_gci = false; ///< true: the GCI band; false: the spread of the levels
};
ReferenceBand reference_band(const std::vector<ReferenceLevel>& levels, const std::optional<ReferenceVerification>& verification,
                             const std::string& tool, const Eigen::Vector3d& direction);

} // namespace kerf

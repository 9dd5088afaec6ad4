#pragma once
// The solution verification of a study's reference on one scene (every study does one): the scene's force profiles at its three finest mesh levels, compared on the
// samples all three solved, give the observed order, the Richardson-extrapolated value and the GCI
// (solution_verification.hpp) of two trajectory-wide quantities of the tool's force F:
//
//   RMS |F| = sqrt(mean_k |F_k|^2) over the common samples,   peak |F| = max_k |F_k|,
//
// and of the force profile itself, from the RMS of the differences between levels
// (difference_convergence): e21 = sqrt(mean_k |F2_k − F1_k|^2), e32 likewise. The profile's
// uncertainty U (in newtons, the scale of a model's RMS force error) is what the study table sets
// beside the models' RMS force errors, and the band a profile plot draws around the reference is
// the same estimate sample by sample (gci_band_half_width with the order used), or, where it is not
// available, the spread of the levels. The GCI of RMS |F| alone is no uncertainty of the profile:
// the levels' RMS values may agree by coincidence while their profiles differ sample by sample.

#include "experiments/profile/force_profile.hpp"
#include "experiments/study/solution_verification.hpp"

#include <Eigen/Core>

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

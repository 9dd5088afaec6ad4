#pragma once
// Does the live view make the servo loop miss deadlines more often than the machine does by
// itself? A paired comparison of the servo's overrun counter over interleaved sessions without
// and with the view (tests/viewer/test_live_view.cpp), for machines that miss deadlines on their
// own (docs/viewer.md, "Why the servo misses deadlines here"), where the literal check —
// zero with and without — cannot be met whatever the view does.

#include <cstdint>
#include <span>

namespace kerf::test {

/// One pair of sessions of the same length: the servo's overruns without and with the view.
struct OverrunPair {
  std::uint64_t without = 0;
  std::uint64_t with = 0;
};

enum class OverrunVerdict {
  view_missed_nothing, ///< every session with the view kept every deadline (the issue's check)
  view_not_worse,      ///< the viewed sessions missed some, no more than their view-less twins
  view_worse,          ///< the viewed sessions missed significantly more than their twins
  inconclusive         ///< too few pairs differ for any outcome to be significant
};

struct OverrunComparison {
  OverrunVerdict verdict = OverrunVerdict::inconclusive;
  double p_value = 1.0;   ///< one-sided sign-flip p of Σ (with − without); 1 when no pair differs
  int unequal_pairs = 0;  ///< pairs whose two counts differ (m)
};

/// One-sided exact sign-flip (paired permutation) p-value of the sum of `differences` (zeros are
/// dropped): with the m non-zero differences d_i and D = Σ d_i,
///   p = #{s ∈ {−1, +1}^m : Σ s_i |d_i| >= D} / 2^m.
/// Under the null hypothesis that the view changes nothing, the two sessions of a pair are
/// exchangeable (same length, interleaved, alternating which comes first), so each difference is
/// as likely to have either sign, whatever the distribution of the counts (bursts of overruns
/// from one late wake-up included). Throws std::invalid_argument for m > 24 (2^m enumerations).
double sign_flip_p_value(std::span<const long> differences);

/// The verdict on `pairs` at significance `alpha` (0 < alpha < 1):
/// - view_missed_nothing when every `with` is 0;
/// - else inconclusive when even the most extreme outcome, p = 2^-m, would not be below alpha
///   (the comparison could not have failed, so it does not pass either);
/// - else view_worse when p < alpha, view_not_worse otherwise.
OverrunComparison compare_overruns(std::span<const OverrunPair> pairs, double alpha);

} // namespace kerf::test

#pragma once
// Timing statistics of a servo session, kept in storage allocated once: histograms of the wake-up
// lateness, the period error and the model's compute time, plus overrun counts. Percentiles come
// from the histograms (bin width 0.5 us, so a percentile is exact to 0.5 us up to 10 ms; beyond
// that it reports the exact maximum).

#include <cstdint>
#include <vector>

namespace kerf {

/// Durations [s] binned at 0.5 us up to 10 ms, with the exact count, sum and maximum.
class DurationHistogram {
public:
  static constexpr double bin_width = 0.5e-6; ///< [s]
  static constexpr std::size_t bins = 20000;  ///< 10 ms
  DurationHistogram() : m_counts(bins + 1, 0) {}

  /// Adds one duration [s]; negative values count as zero. Allocation-free.
  void add(double seconds) noexcept;
  /// The p-th percentile [s], p in [0, 100]: the upper edge of the bin holding it (the exact
  /// maximum for the overflow bin, and never above the maximum). 0 when empty.
  [[nodiscard]] double percentile(double p) const noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept { return m_count; }
  [[nodiscard]] double max() const noexcept { return m_max; }
  [[nodiscard]] double mean() const noexcept { return m_count ? m_sum / static_cast<double>(m_count) : 0.0; }
  void clear() noexcept;

private:
  std::vector<std::uint32_t> m_counts; // last bin: overflow
  std::uint64_t m_count = 0;
  double m_sum = 0.0;
  double m_max = 0.0;
};

/// One session's timing: lateness = wake time - deadline (the scheduler's latency), period
/// jitter = |actual period - nominal period|, compute = the model step, tick = the whole tick's
/// work; an overrun is a tick whose work ended after the next deadline (those deadlines are
/// skipped, not caught up, and counted as missed).
struct TimingStatistics {
  DurationHistogram lateness;
  DurationHistogram period_jitter;
  DurationHistogram compute;
  DurationHistogram tick;
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  std::uint64_t missed_deadlines = 0;
};

} // namespace kerf

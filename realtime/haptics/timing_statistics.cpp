#include "realtime/haptics/timing_statistics.hpp"

#include <algorithm>
#include <cmath>

namespace kerf {

void DurationHistogram::add(double seconds) noexcept {
  const double s = std::isfinite(seconds) ? std::max(seconds, 0.0) : bin_width * static_cast<double>(bins);
  const double b = s / bin_width;
  const std::size_t bin = b >= static_cast<double>(bins) ? bins : static_cast<std::size_t>(b);
  ++m_counts[bin];
  ++m_count;
  m_sum += s;
  m_max = std::max(m_max, s);
}

double DurationHistogram::percentile(double p) const noexcept {
  if (m_count == 0) return 0.0;
  // The rank of the p-th percentile (nearest-rank definition): ceil(p/100 n), at least 1.
  const auto rank = std::max<std::uint64_t>(
      1, static_cast<std::uint64_t>(std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(m_count))));
  std::uint64_t seen = 0;
  for (std::size_t k = 0; k < bins; ++k) {
    seen += m_counts[k];
    if (seen >= rank) return std::min(m_max, static_cast<double>(k + 1) * bin_width);
  }
  return m_max;
}

void DurationHistogram::clear() noexcept {
  std::fill(m_counts.begin(), m_counts.end(), 0u);
  m_count = 0;
  m_sum = 0.0;
  m_max = 0.0;
}

} // namespace kerf

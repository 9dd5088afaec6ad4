#include "tests/viewer/overrun_comparison.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf::test {

double sign_flip_p_value(std::span<const long> differences) {
  std::vector<long> d;
  for (long x : differences)
    if (x != 0) d.push_back(x);
  const std::size_t m = d.size();
  if (m == 0) return 1.0;
  if (m > 24) throw std::invalid_argument("sign_flip_p_value: " + std::to_string(m) + " differences, at most 24");
  long observed = 0;
  for (long x : d) observed += x;
  // p = #{s : Σ s_i |d_i| >= D} / 2^m, every sign vector enumerated (bit i set: s_i = -1).
  std::uint64_t at_least = 0;
  for (std::uint64_t s = 0; s < (std::uint64_t{1} << m); ++s) {
    long sum = 0;
    for (std::size_t i = 0; i < m; ++i) sum += ((s >> i) & 1u) ? -std::labs(d[i]) : std::labs(d[i]);
    if (sum >= observed) ++at_least;
  }
  return static_cast<double>(at_least) / static_cast<double>(std::uint64_t{1} << m);
}

OverrunComparison compare_overruns(std::span<const OverrunPair> pairs, double alpha) {
  if (!(alpha > 0.0 && alpha < 1.0)) throw std::invalid_argument("compare_overruns: alpha must lie in (0, 1)");
  OverrunComparison c;
  bool view_missed = false;
  std::vector<long> d;
  for (const OverrunPair& p : pairs) {
    view_missed = view_missed || p.with > 0;
    d.push_back(static_cast<long>(p.with) - static_cast<long>(p.without));
    if (d.back() != 0) ++c.unequal_pairs;
  }
  c.p_value = sign_flip_p_value(d);
  if (!view_missed) {
    c.verdict = OverrunVerdict::view_missed_nothing;
  } else if (std::ldexp(1.0, -c.unequal_pairs) >= alpha) {
    c.verdict = OverrunVerdict::inconclusive;
  } else {
    c.verdict = c.p_value < alpha ? OverrunVerdict::view_worse : OverrunVerdict::view_not_worse;
  }
  return c;
}

} // namespace kerf::test

#include "formats/trajectory/trajectory_vertices.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace kerf {

std::vector<std::size_t> trajectory_vertices(const SampledTrajectory& trajectory, double tolerance) {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance))
    throw std::invalid_argument("trajectory vertices: the tolerance must be a positive length, got " + std::to_string(tolerance) + " m");
  const std::vector<ToolState>& s = trajectory.samples;
  std::vector<std::size_t> out;
  if (s.empty()) return out;
  std::vector<char> vertex(s.size(), 0);
  vertex.front() = vertex.back() = 1;
  // Ramer–Douglas–Peucker with an explicit stack of chords (a recorded hand may give deep recursions).
  std::vector<std::pair<std::size_t, std::size_t>> chords;
  if (s.size() > 2) chords.emplace_back(0, s.size() - 1);
  while (!chords.empty()) {
    const auto [a, b] = chords.back();
    chords.pop_back();
    const double ta = s[a].time, span = s[b].time - s[a].time;
    const Eigen::Vector3d& pa = s[a].position;
    const Eigen::Vector3d step = s[b].position - pa;
    double farthest = 0.0;
    std::size_t at = a;
    for (std::size_t k = a + 1; k < b; ++k) {
      // d_k = |p_k − p_a − (t_k − t_a)/(t_b − t_a) (p_b − p_a)|: the chord at the sample's own time.
      const double f = span > 0.0 ? (s[k].time - ta) / span : 0.0;
      const double d = (s[k].position - pa - f * step).norm();
      if (d > farthest) {
        farthest = d;
        at = k;
      }
    }
    if (farthest <= tolerance) continue;
    vertex[at] = 1;
    if (at - a > 1) chords.emplace_back(a, at);
    if (b - at > 1) chords.emplace_back(at, b);
  }
  for (std::size_t k = 0; k < s.size(); ++k)
    if (vertex[k]) out.push_back(k);
  return out;
}

std::vector<std::size_t> trajectory_vertices(const std::vector<SampledTrajectory>& trajectories, double tolerance) {
  std::vector<std::size_t> out;
  std::size_t n = 0;
  for (const SampledTrajectory& t : trajectories) {
    const std::vector<std::size_t> v = trajectory_vertices(t, tolerance);
    out.insert(out.end(), v.begin(), v.end());
    n = std::max(n, t.samples.size());
  }
  // A tool whose trajectory ends early rests from its last sample on: that sample is a corner of
  // the common time line too (it is one of its own vertices), and the common line ends at n − 1.
  if (n > 0) out.push_back(n - 1);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

} // namespace kerf

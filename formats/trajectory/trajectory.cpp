#include "formats/trajectory/trajectory.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace kerf {

namespace {

/// One piece of the scripted motion in time: from `from` at `t0` to `to` at `t1`.
struct Piece {
  double t0, t1;
  Eigen::Vector3d from, to;
  const std::string* label;
};

} // namespace

SampledTrajectory sample_trajectory(const TrajectorySpec& spec) {
  if (!(spec.rate > 0.0) || !std::isfinite(spec.rate))
    throw std::invalid_argument("trajectory: the sampling rate must be positive");
  std::vector<Piece> pieces;
  Eigen::Vector3d at = spec.start;
  double t = 0.0;
  for (std::size_t i = 0; i < spec.segments.size(); ++i) {
    const TrajectorySegment& s = spec.segments[i];
    double duration = 0.0;
    Eigen::Vector3d to = at;
    if (s.kind == TrajectorySegment::Kind::move) {
      if (!(s.speed > 0.0) || !std::isfinite(s.speed))
        throw std::invalid_argument("trajectory: segment " + std::to_string(i + 1) + " has a non-positive speed");
      to = s.target;
      duration = (to - at).norm() / s.speed;
    } else {
      if (!(s.duration > 0.0) || !std::isfinite(s.duration))
        throw std::invalid_argument("trajectory: segment " + std::to_string(i + 1) + " has a non-positive duration");
      duration = s.duration;
    }
    pieces.push_back({t, t + duration, at, to, &s.label});
    t += duration;
    at = to;
  }

  SampledTrajectory out;
  out.rate = spec.rate;
  // The small allowance keeps the last sample when T * rate is an integer up to rounding.
  const auto count = static_cast<std::size_t>(std::floor(t * spec.rate + 1e-9)) + 1;
  out.samples.reserve(count);
  out.labels.reserve(count);
  std::size_t piece = 0;
  for (std::size_t k = 0; k < count; ++k) {
    ToolState state;
    state.time = static_cast<double>(k) / spec.rate;
    while (piece + 1 < pieces.size() && state.time >= pieces[piece].t1) ++piece;
    if (pieces.empty()) {
      state.position = spec.start;
      out.labels.emplace_back();
    } else {
      const Piece& p = pieces[piece];
      const double span = p.t1 - p.t0;
      const double s = span > 0.0 ? std::clamp((state.time - p.t0) / span, 0.0, 1.0) : 1.0;
      state.position = p.from + s * (p.to - p.from);
      state.velocity = span > 0.0 ? Eigen::Vector3d((p.to - p.from) / span) : Eigen::Vector3d::Zero();
      out.labels.push_back(*p.label);
    }
    out.samples.push_back(state);
  }
  return out;
}

SampledTrajectory read_recorded_trajectory(const std::filesystem::path& csv, double rate) {
  if (!(rate > 0.0) || !std::isfinite(rate)) throw std::invalid_argument("trajectory: the sampling rate must be positive");
  std::ifstream in(csv);
  if (!in) throw std::runtime_error(csv.string() + ": cannot open the recorded trajectory");
  std::string line;
  int line_number = 0;
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(csv.string() + ":" + std::to_string(line_number) + ": " + what);
  };
  std::vector<double> times;
  std::vector<Eigen::Vector3d> points;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (!header_seen) {
      if (line != "t,px,py,pz") fail("expected the header \"t,px,py,pz\", found \"" + line + "\"");
      header_seen = true;
      continue;
    }
    std::stringstream fields(line);
    std::string field;
    double v[4];
    int n = 0;
    while (std::getline(fields, field, ',')) {
      if (n == 4) fail("expected 4 columns (t,px,py,pz), found more");
      std::size_t used = 0;
      try {
        v[n] = std::stod(field, &used);
      } catch (const std::exception&) {
        fail("column " + std::to_string(n + 1) + ": expected a number, found \"" + field + "\"");
      }
      if (used != field.size() || !std::isfinite(v[n]))
        fail("column " + std::to_string(n + 1) + ": expected a finite number, found \"" + field + "\"");
      ++n;
    }
    if (n != 4) fail("expected 4 columns (t,px,py,pz), found " + std::to_string(n));
    if (!times.empty() && !(v[0] > times.back())) fail("time must increase strictly");
    times.push_back(v[0]);
    points.emplace_back(v[1], v[2], v[3]);
  }
  if (times.size() < 2) throw std::runtime_error(csv.string() + ": a recorded trajectory needs at least two samples");

  SampledTrajectory out;
  out.rate = rate;
  const double t0 = times.front();
  // At most 1e7 resampled points (2.8 h at 1 kHz, ~0.9 GB of states): a longer span is a wrong
  // time column (e.g. nanoseconds), and its count must be checked before the size_t conversion.
  const double intervals = std::floor((times.back() - t0) * rate + 1e-9);
  if (!(intervals < 1e7))
    throw std::runtime_error(csv.string() + ": the recorded trajectory spans " + std::to_string(times.back() - t0) +
                             " s, over 1e7 samples at " + std::to_string(rate) + " Hz (is the time column in seconds?)");
  const auto count = static_cast<std::size_t>(intervals) + 1;
  out.samples.reserve(count);
  out.labels.reserve(count);
  std::size_t j = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const double t = t0 + static_cast<double>(k) / rate;
    while (j + 2 < times.size() && t > times[j + 1]) ++j;
    const double s = std::clamp((t - times[j]) / (times[j + 1] - times[j]), 0.0, 1.0);
    ToolState state;
    state.time = t - t0;
    state.position = points[j] + s * (points[j + 1] - points[j]);
    state.velocity = (points[j + 1] - points[j]) / (times[j + 1] - times[j]);
    out.samples.push_back(state);
    out.labels.emplace_back("recorded");
  }
  return out;
}

SampledTrajectory sample(const TrajectorySpec& spec) {
  if (!spec.recorded_file.empty()) return read_recorded_trajectory(spec.recorded_file, spec.rate);
  return sample_trajectory(spec);
}

} // namespace kerf

// The vertices of a sampled motion (formats/trajectory/trajectory_vertices.hpp), the loads a
// reference must pass through: against segment ends computed by hand for scripted motions, and
// against the defining property for a recorded one — between two consecutive vertices, every
// sample lies within the tolerance of the straight line in time through them.

#include "formats/trajectory/trajectory.hpp"
#include "formats/trajectory/trajectory_vertices.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace kerf;

namespace {

/// max over samples a < k < b of |p_k − chord(t_k)|, for consecutive vertices a, b.
double largest_deviation(const SampledTrajectory& t, const std::vector<std::size_t>& vertices) {
  double worst = 0.0;
  for (std::size_t v = 0; v + 1 < vertices.size(); ++v) {
    const std::size_t a = vertices[v], b = vertices[v + 1];
    for (std::size_t k = a + 1; k < b; ++k) {
      const double f = (t.samples[k].time - t.samples[a].time) / (t.samples[b].time - t.samples[a].time);
      const Eigen::Vector3d chord = t.samples[a].position + f * (t.samples[b].position - t.samples[a].position);
      worst = std::max(worst, (t.samples[k].position - chord).norm());
    }
  }
  return worst;
}

} // namespace

TEST(TrajectoryVertices, ScriptedCutHasItsSegmentEndsAndTheDwellsEnds) {
  // potato_wedge_cut's motion: 1 mm approach, 12 mm cut, a 0.5 s hold, 13 mm retreat, all at
  // 1 mm/s, sampled at 1 kHz: corners at t = 1, 13, 13.5 s and the ends 0 and 26.5 s.
  TrajectorySpec spec;
  spec.rate = 1000.0;
  spec.start = {0.025, 0.0, 0.018};
  spec.segments = {{TrajectorySegment::Kind::move, "approach", {0.025, 0.0, 0.017}, 0.001, 0.0},
                   {TrajectorySegment::Kind::move, "cut", {0.025, 0.0, 0.005}, 0.001, 0.0},
                   {TrajectorySegment::Kind::dwell, "hold", {}, 0.0, 0.5},
                   {TrajectorySegment::Kind::move, "retreat", {0.025, 0.0, 0.018}, 0.001, 0.0}};
  const SampledTrajectory t = sample_trajectory(spec);
  const std::vector<std::size_t> v = trajectory_vertices(t, 1e-6);
  // The approach and the cut are one straight line at one speed: no corner at t = 1 s.
  EXPECT_EQ(v, (std::vector<std::size_t>{0, 13000, 13500, 26500}));
  // The dwell is a corner in time although its path in space is a point on the line.
  EXPECT_NEAR(t.samples[13000].position.z(), 0.005, 1e-12);
  EXPECT_NEAR(t.samples[13500].position.z(), 0.005, 1e-12);
}

TEST(TrajectoryVertices, ASpeedChangeAlongOneLineIsACorner) {
  TrajectorySpec spec;
  spec.rate = 100.0;
  spec.start = {0.0, 0.0, 0.0};
  spec.segments = {{TrajectorySegment::Kind::move, "slow", {0.001, 0.0, 0.0}, 0.001, 0.0},
                   {TrajectorySegment::Kind::move, "fast", {0.003, 0.0, 0.0}, 0.002, 0.0}};
  const SampledTrajectory t = sample_trajectory(spec);
  // 1 s at 1 mm/s then 1 s at 2 mm/s: the chord from 0 to 2 s is at 1.5 mm at t = 1 s where the
  // tool is at 1 mm — 0.5 mm off, a corner at sample 100.
  EXPECT_EQ(trajectory_vertices(t, 1e-6), (std::vector<std::size_t>{0, 100, 200}));
}

TEST(TrajectoryVertices, ATurnBetweenSamplesKeepsBothSamplesAroundIt) {
  // The proportional-depth knife cut of sponge_knife_cut_proportional: 0.1 mm down, then 0.5 mm
  // down and 0.4 mm along together (0.640 mm at 1 mm/s: the corner at t = 0.7403 s falls between
  // two 1 kHz samples), then 0.6 mm up.
  TrajectorySpec spec;
  spec.rate = 1000.0;
  spec.start = {0.45e-3, 0.0, 1.5e-3};
  spec.segments = {{TrajectorySegment::Kind::move, "approach", {0.45e-3, 0.0, 1.4e-3}, 1e-3, 0.0},
                   {TrajectorySegment::Kind::move, "cut", {0.85e-3, 0.0, 0.9e-3}, 1e-3, 0.0},
                   {TrajectorySegment::Kind::move, "retreat", {0.85e-3, 0.0, 1.5e-3}, 1e-3, 0.0}};
  const SampledTrajectory t = sample_trajectory(spec);
  const std::vector<std::size_t> v = trajectory_vertices(t, 1e-9);
  // The approach ends at 0.1 s, on sample 100; the cut at 0.1 + 0.6403 s, between 740 and 741.
  ASSERT_GE(v.size(), 4u);
  EXPECT_EQ(v.front(), 0u);
  EXPECT_EQ(v.back(), t.samples.size() - 1);
  EXPECT_TRUE(std::find(v.begin(), v.end(), std::size_t{100}) != v.end());
  EXPECT_TRUE(std::find(v.begin(), v.end(), std::size_t{740}) != v.end() || std::find(v.begin(), v.end(), std::size_t{741}) != v.end());
  EXPECT_LE(largest_deviation(t, v), 1e-9);
}

TEST(TrajectoryVertices, ARecordedHandIsFollowedWithinTheTolerance) {
  // A hand drawing a circle of 5 mm radius in 2 s with a 0.05 mm tremor at 13 Hz, at 1 kHz.
  SampledTrajectory t;
  t.rate = 1000.0;
  for (int k = 0; k <= 2000; ++k) {
    ToolState s;
    s.time = k / 1000.0;
    const double a = M_PI * s.time;
    s.position = Eigen::Vector3d(5e-3 * std::cos(a), 5e-3 * std::sin(a), 0.05e-3 * std::sin(2.0 * M_PI * 13.0 * s.time));
    t.samples.push_back(s);
  }
  for (const double tolerance : {1e-6, 1e-5, 1e-4}) {
    const std::vector<std::size_t> v = trajectory_vertices(t, tolerance);
    EXPECT_LE(largest_deviation(t, v), tolerance) << tolerance;
    EXPECT_EQ(v.front(), 0u);
    EXPECT_EQ(v.back(), 2000u);
    // Fewer vertices the larger the tolerance; every tremor turn (26 in 2 s) beyond 1e-5 m is one.
    if (tolerance <= 1e-5) {
      EXPECT_GE(v.size(), 26u) << tolerance;
    }
  }
  EXPECT_LT(trajectory_vertices(t, 1e-4).size(), trajectory_vertices(t, 1e-6).size());
  EXPECT_THROW(trajectory_vertices(t, 0.0), std::invalid_argument);
}

TEST(TrajectoryVertices, SeveralToolsShareTheUnionOfTheirCorners) {
  TrajectorySpec left, right;
  left.rate = right.rate = 100.0;
  left.segments = {{TrajectorySegment::Kind::move, "", {0.001, 0.0, 0.0}, 0.001, 0.0}, {TrajectorySegment::Kind::dwell, "", {}, 0.0, 1.0}};
  right.segments = {{TrajectorySegment::Kind::move, "", {-0.0005, 0.0, 0.0}, 0.001, 0.0},
                    {TrajectorySegment::Kind::move, "", {-0.0005, 0.0, 0.001}, 0.001, 0.0}};
  // left: corner at 1 s (sample 100), ends at 2 s (200); right: corner at 0.5 s (50), ends at 1.5 s (150).
  EXPECT_EQ(trajectory_vertices(std::vector<SampledTrajectory>{sample_trajectory(left), sample_trajectory(right)}, 1e-6),
            (std::vector<std::size_t>{0, 50, 100, 150, 200}));
}

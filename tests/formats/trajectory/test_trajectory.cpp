// Trajectory sampling against hand-computed positions: straight segments at constant speed,
// dwells, and recorded CSVs resampled by linear interpolation.

#include "formats/trajectory/trajectory.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace kerf;

TEST(Trajectory, ApproachCutDwellRetreat) {
  TrajectorySpec spec;
  spec.rate = 1000.0;
  spec.start = {0.020, 0.0, 0.016};
  spec.segments = {{TrajectorySegment::Kind::move, "cut", {0.020, 0.0, 0.006}, 0.001, 0.0},
                   {TrajectorySegment::Kind::dwell, "dwell", {}, 0.0, 0.5},
                   {TrajectorySegment::Kind::move, "retreat", {0.020, 0.0, 0.016}, 0.002, 0.0}};
  const SampledTrajectory t = sample_trajectory(spec);
  // 10 mm at 1 mm/s = 10 s, dwell 0.5 s, 10 mm at 2 mm/s = 5 s: 15.5 s, 15501 samples.
  ASSERT_EQ(t.samples.size(), 15501u);
  EXPECT_DOUBLE_EQ(t.samples[2500].time, 2.5);
  EXPECT_NEAR(t.samples[2500].position.z(), 0.0135, 1e-12);
  EXPECT_NEAR(t.samples[2500].velocity.z(), -0.001, 1e-12);
  EXPECT_EQ(t.labels[2500], "cut");
  EXPECT_NEAR(t.samples[10200].position.z(), 0.006, 1e-12);
  EXPECT_EQ(t.labels[10200], "dwell");
  EXPECT_NEAR(t.samples[13000].position.z(), 0.006 + 0.002 * 2.5, 1e-12);
  EXPECT_NEAR(t.samples.back().position.z(), 0.016, 1e-12);
}

TEST(Trajectory, ProportionalDepthCutMovesDiagonally) {
  // Paper 002 Fig. 5: depth proportional to cut length — one straight diagonal move.
  TrajectorySpec spec;
  spec.rate = 100.0;
  spec.start = {0.0, 0.0, 0.001};
  spec.segments = {{TrajectorySegment::Kind::move, "cut", {0.0008, 0.0, 0.0005}, 0.001, 0.0}};
  const SampledTrajectory t = sample_trajectory(spec);
  // Depth over cut length stays 0.5 mm / 0.8 mm = 0.625 all along.
  for (std::size_t k = 1; k < t.samples.size(); ++k)
    EXPECT_NEAR((0.001 - t.samples[k].position.z()) / t.samples[k].position.x(), 0.625, 1e-9);
}

TEST(Trajectory, RejectsNonPositiveRatesSpeedsDurations) {
  TrajectorySpec spec;
  spec.rate = 0.0;
  EXPECT_THROW(sample_trajectory(spec), std::invalid_argument);
  spec.rate = 1000.0;
  spec.segments = {{TrajectorySegment::Kind::move, "", {1, 0, 0}, 0.0, 0.0}};
  EXPECT_THROW(sample_trajectory(spec), std::invalid_argument);
  spec.segments = {{TrajectorySegment::Kind::dwell, "", {}, 0.0, -1.0}};
  EXPECT_THROW(sample_trajectory(spec), std::invalid_argument);
}

TEST(Trajectory, RecordedCsvIsResampled) {
  const auto file = std::filesystem::temp_directory_path() / "kerf_test_recorded.csv";
  {
    std::ofstream out(file);
    out << "t,px,py,pz\n0,0,0,0\n1,0.001,0,0\n3,0.001,0.002,0\n";
  }
  const SampledTrajectory t = read_recorded_trajectory(file, 10.0);
  ASSERT_EQ(t.samples.size(), 31u);
  EXPECT_NEAR(t.samples[5].position.x(), 0.0005, 1e-15);
  EXPECT_NEAR(t.samples[20].position.y(), 0.001, 1e-15);
  EXPECT_NEAR(t.samples[20].velocity.y(), 0.001, 1e-15);
  std::filesystem::remove(file);
}

TEST(Trajectory, MalformedRecordedCsvNamesTheLine) {
  const auto file = std::filesystem::temp_directory_path() / "kerf_test_recorded_bad.csv";
  for (const char* body : {"t,px,py,pz\n0,0,0,0\n1,0,x,0\n", "t,px,py,pz\n0,0,0,0\n0,0,0,0\n",
                           "time,x,y,z\n0,0,0,0\n", "t,px,py,pz\n0,0,0\n1,0,0,0\n", "t,px,py,pz\n0,0,0,nan\n1,0,0,0\n"}) {
    {
      std::ofstream out(file);
      out << body;
    }
    try {
      read_recorded_trajectory(file, 1000.0);
      ADD_FAILURE() << "accepted: " << body;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(file.string() + ":"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove(file);
}

// Study metrics against values computed by hand on a four-sample synthetic pair of profiles.

#include "formats/profile/profile_metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace kerf;

namespace {

/// A blade going down 1 mm per sample; the body pushes back with +z forces `fz`.
ForceProfile descending(std::initializer_list<double> fz, std::initializer_list<InteractionMode> modes) {
  ForceProfile p;
  auto m = modes.begin();
  int k = 0;
  for (double f : fz) {
    ProfileRow r;
    r.t = k * 1e-3;
    r.tool = "blade";
    r.position = {0.0, 0.0, -1e-3 * k};
    r.force = {0.0, 0.0, f};
    r.mode = *m++;
    p.rows.push_back(r);
    ++k;
  }
  return p;
}

using M = InteractionMode;

} // namespace

TEST(ProfileMetrics, HandComputedValues) {
  const ForceProfile reference = descending({0, 1, 2, 3}, {M::deformation_1, M::deformation_1, M::rupture, M::cutting});
  const ForceProfile model = descending({0, 1, 2, 5}, {M::deformation_1, M::rupture, M::cutting, M::cutting});
  const ProfileMetrics e = compare_profiles(model, reference, "blade", SteadyCuttingExpectation{4.0, -Eigen::Vector3d::UnitZ()});
  EXPECT_EQ(e.samples, 4u);
  // Samples at t = 0, 1, 2, 3 s stand for 0.5, 1, 1, 0.5 s (trapezoidal weights, 3 s in all).
  // Differences 0, 0, 0, 2 N: RMS = sqrt(0.5 × 4 / 3) N, over the reference peak 3 N.
  EXPECT_NEAR(e.normalised_rms_force_error, std::sqrt(2.0 / 3.0) / 3.0, 1e-15);
  // Peaks 5 N and 3 N.
  EXPECT_NEAR(e.peak_force_error, 2.0 / 3.0, 1e-15);
  // Modes agree at samples 0 and 3: 0.5 s + 0.5 s of the 3 s.
  EXPECT_NEAR(e.mode_agreement, 1.0 / 3.0, 1e-15);
  // Per phase of the reference: deformation-1 (samples 0, 1: 1.5 s), rupture (sample 2: 1 s),
  // cutting (sample 3: 0.5 s); the whole error is in the cutting phase, its RMS there 2 N.
  ASSERT_EQ(e.phases.size(), 3u);
  EXPECT_EQ(e.phases[0].mode, M::deformation_1);
  EXPECT_NEAR(e.phases[0].time_fraction, 0.5, 1e-15);
  EXPECT_EQ(e.phases[0].normalised_rms_force_error, 0.0);
  EXPECT_EQ(e.phases[1].mode, M::rupture);
  EXPECT_NEAR(e.phases[1].time_fraction, 1.0 / 3.0, 1e-15);
  EXPECT_EQ(e.phases[2].mode, M::cutting);
  EXPECT_NEAR(e.phases[2].normalised_rms_force_error, 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(e.phases[2].error_share, 1.0, 1e-15);
  ASSERT_NE(e.dominant_phase(), nullptr);
  EXPECT_EQ(e.dominant_phase()->mode, M::cutting);
  // Rupture after 1 mm (model) and 2 mm (reference) of travel.
  ASSERT_TRUE(e.rupture_displacement_error.has_value());
  EXPECT_NEAR(*e.rupture_displacement_error, -1e-3, 1e-15);
  // Trapezoidal work over 1 mm steps: reference (0.5 + 1.5 + 2.5) mJ = 4.5 mJ, model 5.5 mJ.
  EXPECT_NEAR(e.work_error, 1.0 / 4.5, 1e-12);
  // Model cutting samples resist with 2 N and 5 N: mean 3.5 N against J_c l = 4 N.
  ASSERT_TRUE(e.steady_cutting_force_error.has_value());
  EXPECT_NEAR(*e.steady_cutting_force_error, -0.125, 1e-15);
}

TEST(ProfileMetrics, IdenticalProfilesHaveZeroError) {
  const ForceProfile p = descending({0, 1, 2, 3}, {M::deformation_1, M::deformation_1, M::rupture, M::cutting});
  const ProfileMetrics e = compare_profiles(p, p, "blade");
  EXPECT_EQ(e.normalised_rms_force_error, 0.0);
  EXPECT_EQ(e.peak_force_error, 0.0);
  EXPECT_EQ(e.work_error, 0.0);
  EXPECT_EQ(e.mode_agreement, 1.0);
  EXPECT_EQ(*e.rupture_displacement_error, 0.0);
  EXPECT_FALSE(e.steady_cutting_force_error.has_value());
}

TEST(ProfileMetrics, MismatchedSamplesAreRefused) {
  const ForceProfile a = descending({0, 1, 2}, {M::deformation_1, M::deformation_1, M::deformation_1});
  const ForceProfile b = descending({0, 1, 2, 3}, {M::deformation_1, M::deformation_1, M::deformation_1, M::deformation_1});
  EXPECT_THROW(compare_profiles(a, b, "blade"), std::invalid_argument);
  EXPECT_THROW(compare_profiles(b, b, "no_such_tool"), std::invalid_argument);
  const ForceProfile zero = descending({0, 0, 0}, {M::no_contact, M::no_contact, M::no_contact});
  EXPECT_THROW(compare_profiles(a, zero, "blade"), std::invalid_argument);
}

TEST(ProfileMetrics, TheRmsIsATimeAverageWhereverTheReferenceSampledDensely) {
  // The reference is 1 N throughout; the model is 1 N off at t = 0 only. Sampled every second over
  // 3 s, the sample at t = 0 stands for 0.5 s: RMS error sqrt(0.5 / 3) N against a 1 N peak. With
  // eight more samples crowded into [2, 3] s, where the error is zero, a plain mean over samples
  // would fall from sqrt(1/4) to sqrt(1/12) N; the time average stays where it was, the crowded
  // samples sharing the second they stand for.
  const auto profile = [](const std::vector<double>& times, bool model) {
    ForceProfile p;
    for (double t : times) {
      ProfileRow r;
      r.tool = "blade";
      r.t = t;
      r.position = {0.0, 0.0, -1e-3 * t}; // the blade advances 1 mm/s against the force: work is done
      r.force = {0.0, 0.0, 1.0 + (model && t < 0.5 ? 1.0 : 0.0)};
      p.rows.push_back(r);
    }
    return p;
  };
  const std::vector<double> even{0, 1, 2, 3};
  std::vector<double> crowded{0, 1, 2};
  for (int k = 1; k <= 8; ++k) crowded.push_back(2.0 + k / 9.0);
  crowded.push_back(3.0);
  const double a = compare_profiles(profile(even, true), profile(even, false), "blade").normalised_rms_force_error;
  const double b = compare_profiles(profile(crowded, true), profile(crowded, false), "blade").normalised_rms_force_error;
  EXPECT_NEAR(a, std::sqrt(0.5 / 3.0), 1e-15);
  EXPECT_NEAR(b, a, 1e-15);
  EXPECT_EQ(sample_time_weights({2.0}), std::vector<double>{1.0});
  EXPECT_EQ(sample_time_weights({0.0, 1.0, 3.0}), (std::vector<double>{0.5, 1.5, 1.0}));
}

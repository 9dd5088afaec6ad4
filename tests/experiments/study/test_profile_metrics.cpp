// Study metrics against values computed by hand on a four-sample synthetic pair of profiles.

#include "experiments/study/profile_metrics.hpp"

#include <gtest/gtest.h>

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
  // Differences 0, 0, 0, 2 N: RMS = sqrt(4/4) = 1 N, over the reference peak 3 N.
  EXPECT_NEAR(e.normalised_rms_force_error, 1.0 / 3.0, 1e-15);
  // Peaks 5 N and 3 N.
  EXPECT_NEAR(e.peak_force_error, 2.0 / 3.0, 1e-15);
  // Modes agree at samples 0 and 3.
  EXPECT_NEAR(e.mode_agreement, 0.5, 1e-15);
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

// Cohesive zone length and the reference's mode classification (reference/cohesive/cohesive_zone.hpp).

#include "reference/cohesive/cohesive_zone.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace kerf::reference {
namespace {

TEST(CohesiveZone, RiceEstimate) {
  // Potato tissue with σ_c = 0.5 MPa (E = 3 MPa, ν = 0.45, J_c = 200 J/m²; two_layer_cut's lower
  // layer; the potato scenes carry 1 MPa): l_cz = (9π/32) E/(1−ν²) J_c/σ_c², evaluated by hand:
  // 0.883573 × 3.761755e6 × 200 / 2.5e11 = 2.65903 mm.
  EXPECT_NEAR(cohesive_zone_length(3e6, 0.45, 200.0, 0.5e6), 2.65903e-3, 1e-8);
  // Halving σ_c quadruples the zone (l_cz ∝ 1/σ_c²).
  EXPECT_NEAR(cohesive_zone_length(3e6, 0.45, 200.0, 0.25e6) / cohesive_zone_length(3e6, 0.45, 200.0, 0.5e6), 4.0, 1e-12);
  EXPECT_THROW(cohesive_zone_length(3e6, 0.5, 200.0, 0.5e6), std::invalid_argument);
}

TEST(CohesiveZone, ModesFollowTheCrack) {
  // An approach, press, crack initiation, advance, hold, retreat and re-entry, sample by sample.
  struct Sample {
    bool contact;
    double failed;
    InteractionMode expected;
  };
  const std::vector<Sample> samples = {
      {false, 0.0, InteractionMode::no_contact},    {true, 0.0, InteractionMode::deformation_1},
      {true, 0.0, InteractionMode::deformation_1},  {true, 1e-6, InteractionMode::rupture},
      {true, 3e-6, InteractionMode::cutting},       {true, 5e-6, InteractionMode::cutting},
      {true, 5e-6, InteractionMode::deformation_2}, {false, 5e-6, InteractionMode::no_contact},
      {true, 5e-6, InteractionMode::deformation_2}, {true, 6e-6, InteractionMode::cutting}};
  CohesiveSampleState previous;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const CohesiveSampleState current{samples[k].contact, samples[k].failed};
    EXPECT_EQ(reference_mode(previous, current), samples[k].expected) << "sample " << k;
    previous = current;
  }
}

} // namespace
} // namespace kerf::reference

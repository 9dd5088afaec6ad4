// The stability sweep: scaled scenes against the factors applied by hand, and every model in the
// catalogue run at the extreme corners of every axis without a NaN force or a crash.

#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/stability_sweep.hpp"

#include <gtest/gtest.h>

using namespace kerf;

namespace {
Scene scene(const std::string& name) {
  return read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / (name + ".toml"));
}
} // namespace

TEST(StabilitySweep, ScaledScenesApplyTheFactor) {
  const Scene s = scene("potato_rect_cut");
  EXPECT_DOUBLE_EQ(scaled_scene(s, "stiffness", 1e3).material.youngs_modulus, 1e3 * s.material.youngs_modulus);
  EXPECT_DOUBLE_EQ(scaled_scene(s, "stiffness", 1e3).fracture->rupture_force_per_length,
                   1e3 * s.fracture->rupture_force_per_length);
  EXPECT_DOUBLE_EQ(scaled_scene(s, "toughness", 0.01).material.fracture_toughness, 0.01 * s.material.fracture_toughness);
  EXPECT_DOUBLE_EQ(scaled_scene(s, "rate", 4.0).tools[0].trajectory.rate, 4.0 * s.tools[0].trajectory.rate);
  EXPECT_DOUBLE_EQ(scaled_scene(s, "speed", 10.0).tools[0].trajectory.segments[1].speed,
                   10.0 * s.tools[0].trajectory.segments[1].speed);
  EXPECT_DOUBLE_EQ(scaled_scene(s, "poisson", 0.499).material.poisson_ratio, 0.499);
  EXPECT_DOUBLE_EQ(scaled_scene(s, "element_size", 2.0).geometry.element_size, 2.0 * s.geometry.element_size);
  EXPECT_THROW(scaled_scene(s, "colour", 1.0), std::invalid_argument);
}

TEST(StabilitySweep, FractureModelToughnessScalesTheCuttingForce) {
  // Paper 001 Eq. 10: the cutting force J_c l scales with J_c, so the peak force scales too once
  // cutting dominates (x10 toughness: 40 N plateau above the 6 N rupture peak).
  StabilitySettings settings;
  settings.axes = {{"toughness", {10.0}}};
  const auto points = stability_sweep(scene("potato_rect_cut"), "fracture", settings);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].outcome, StabilityClass::bounded);
  EXPECT_NEAR(points[0].peak_force, 10.0 * 200.0 * 0.020, 1e-6);
}

TEST(StabilitySweep, EveryModelSurvivesTheExtremeCornersWithoutNaN) {
  // Extreme corners: the smallest and largest value of every default axis. A refusal (with a
  // message) is graceful; a NaN force is not.
  StabilitySettings settings;
  settings.axes.clear();
  for (const StabilityAxis& a : default_stability_axes())
    settings.axes.push_back({a.name, {a.values.front(), a.values.back()}});
  for (const ModelDescription& m : model_catalogue()) {
    bool swept = false;
    for (const char* name : {"potato_rect_cut", "sponge_cut_constant", "clay_pull", "clay_tear"}) {
      Scene s = scene(name);
      try {
        require_model_for_scene(m.name, s);
      } catch (const std::exception&) {
        continue; // the model does not represent this scene
      }
      s = scaled_scene(s, "speed", 10.0); // a shorter trajectory keeps the sweep quick
      for (const StabilityPoint& p : stability_sweep(s, std::string(m.name), settings)) {
        EXPECT_NE(p.outcome, StabilityClass::non_finite) << m.name << " on " << name << ": " << p.axis << " = " << p.value;
        if (p.outcome == StabilityClass::refused) {
          EXPECT_FALSE(p.note.empty());
        }
      }
      swept = true;
      break;
    }
    EXPECT_TRUE(swept) << "model " << m.name << " accepts none of the sweep scenes";
  }
}

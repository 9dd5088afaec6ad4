// The session report counts the model steps that reported themselves over budget: a test model
// that flags every third step, ticked by hand (no clock involved), gives exactly a third.

#include "realtime/haptics/replay_device.hpp"
#include "realtime/haptics/servo_loop.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace kerf;

namespace {
/// No force; ForceSample::over_budget on every third step (steps 3, 6, 9, …).
class EveryThirdOverBudget final : public ToolModel {
public:
  [[nodiscard]] std::string_view name() const override { return "every-third-over-budget"; }
  [[nodiscard]] int tool_count() const override { return 1; }
  void reset() override { m_steps = 0; }
  void step(std::span<const ToolState>, double, std::span<ForceSample> forces) noexcept override {
    ++m_steps;
    forces[0] = ForceSample{Eigen::Vector3d::Zero(), InteractionMode::no_contact, 0.0, m_steps % 3 == 0};
  }

private:
  long m_steps = 0;
};
} // namespace

TEST(ServoReport, CountsTheModelStepsThatReportThemselvesOverBudget) {
  const auto file = std::filesystem::temp_directory_path() / ("kerf_report_" + std::to_string(getpid()) + ".csv");
  std::ofstream(file) << "t,px,py,pz\n0,0,0,0\n2,0,0,0\n";
  auto device = open_device("replay:" + file.string());
  EveryThirdOverBudget model;
  HapticDevice* devices[] = {device.get()};
  ServoSettings settings;
  settings.rate = 1000.0;
  settings.safety = {1e6, 1e12, 1e-9, 1.0}; // no effective clamp, rate limit or ramp; a 1 s watchdog
  settings.realtime = false;
  ServoLoop loop(model, devices, settings, nullptr);
  const int ticks = 300;
  for (int tick = 0; tick < ticks; ++tick) ASSERT_TRUE(loop.tick(1e-3 * tick, 0.0));
  std::filesystem::remove(file);
  EXPECT_EQ(loop.model_steps(), static_cast<std::uint64_t>(ticks));
  EXPECT_EQ(loop.model_steps_over_budget(), static_cast<std::uint64_t>(ticks / 3));
  EXPECT_LE(loop.model_steps_over_period(), loop.model_steps());
}

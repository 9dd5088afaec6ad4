// The records of a run: the content hash, SHA-256, against FIPS 180-4's published test vector;
// the steps a model reports over budget, counted by run_model against a model whose flags are
// known by construction.

#include "experiments/models/run_model.hpp"
#include "experiments/records/content_hash.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

TEST(RunRecord, Sha256MatchesFips180Vector) {
  // FIPS 180-4 example: SHA-256("abc").
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "kerf_test_run_record_abc.txt";
  std::ofstream(file, std::ios::binary) << "abc";
  EXPECT_EQ(kerf::file_sha256(file), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  std::filesystem::remove(file);
}

namespace {
/// Two tools; the first flags every third step over budget, the second every fifth.
class FlaggingModel final : public kerf::ToolModel {
public:
  [[nodiscard]] std::string_view name() const override { return "flagging"; }
  [[nodiscard]] int tool_count() const override { return 2; }
  void reset() override { m_step = 0; }
  void step(std::span<const kerf::ToolState>, double, std::span<kerf::ForceSample> forces) noexcept override {
    forces[0] = kerf::ForceSample{};
    forces[1] = kerf::ForceSample{};
    forces[0].over_budget = m_step % 3 == 0;
    forces[1].over_budget = m_step % 5 == 0;
    ++m_step;
  }

private:
  int m_step = 0;
};
} // namespace

TEST(RunRecord, CountsTheStepsAModelReportsOverBudget) {
  FlaggingModel model;
  kerf::SampledTrajectory trajectory;
  trajectory.rate = 1000.0;
  trajectory.samples.resize(30);
  const kerf::ForceProfile profile = kerf::run_model(model, {"a", "b"}, {trajectory, trajectory});
  EXPECT_EQ(profile.rows.size(), 60u);
  // Steps 0..29 flagged by either tool: multiples of 3 (10) or of 5 (6), less those of 15 (2),
  // each step counted once however many tools flag it.
  EXPECT_EQ(profile.steps_over_budget, 14u);
}

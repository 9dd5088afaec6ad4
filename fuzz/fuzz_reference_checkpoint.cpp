#include "fuzz/fuzz_targets.hpp"

#include "experiments/run/reference_checkpoint.hpp"
#include "experiments/run/reference_fracture.hpp"
#include "fuzz/fuzz_input_file.hpp"

namespace kerf::fuzz {

void fuzz_reference_checkpoint(std::span<const std::byte> data) {
  const std::filesystem::path file = write_input_file(data, "checkpoint.bin");
  ReferenceCheckpoint c;
  try {
    c = read_reference_checkpoint(file);
  } catch (const std::runtime_error&) {
    return; // the documented rejection, naming the file
  }
  if (c.solved > c.indices.size()) throw FuzzFinding("a checkpoint was accepted with more samples solved than requested");
  for (const ProfileRow& r : c.profile.rows)
    if (static_cast<int>(r.mode) < 0 || r.mode > InteractionMode::deformation_2)
      throw FuzzFinding("a checkpoint row was accepted with an invalid mode");
  // What run_reference does with the sample records when it resumes (reference_run.cpp): the sum
  // of their Newton iterations, and the last one's contact points and interface energy.
  int newton_total = 0;
  for (const auto& s : c.samples) newton_total += s.at("newton_iterations").get<int>();
  if (!c.samples.empty() && c.samples.back().contains("energy")) {
    (void)c.samples.back().at("contact_points").get<int>();
    (void)c.samples.back().at("energy").at("failed_area_m2").get<double>();
    (void)EnergyBookkeeping::from_json(c.samples.back().at("energy")); // with the kinetic energy of a dynamic run
  }
  (void)newton_total;
}

} // namespace kerf::fuzz

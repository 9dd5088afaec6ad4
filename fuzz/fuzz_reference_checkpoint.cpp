#include "fuzz/fuzz_targets.hpp"

#include "experiments/reference_run/reference_checkpoint.hpp"
#include "fuzz/fuzz_input_file.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

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
    // What EnergyBookkeeping::from_json (reference_fracture.cpp) reads on resume, field by field
    // (that file brings the reference's headers, which this parser-only build leaves out): an
    // accepted record must give every field without a json exception, the kinetic energy and the
    // trapezoid work and the damping dissipation of a dynamic run included.
    const nlohmann::json& e = c.samples.back().at("energy");
    for (const char* key : {"external_work_J", "stored_elastic_energy_J", "interface_energy_J", "cohesive_dissipation_J",
                            "viscous_dissipation_J", "failed_area_m2"})
      (void)e.at(key).get<double>();
    for (const char* key : {"contact_energy_J", "kinetic_energy_J", "cohesive_trapezoid_work_J", "damping_dissipation_J"})
      (void)e.value(key, 0.0);
    for (const char* key : {"last_positions_m", "last_forces_on_body_N"})
      for (const auto& v : e.at(key)) (void)Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
  }
  (void)newton_total;
}

} // namespace kerf::fuzz

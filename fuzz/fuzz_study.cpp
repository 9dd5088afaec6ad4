#include "fuzz/fuzz_targets.hpp"

#include "experiments/models/model_description.hpp"
#include "experiments/study/study_spec.hpp"
#include "fuzz/fuzz_input_file.hpp"

#include <algorithm>
#include <cstring>
#include <functional>
#include <system_error>

namespace kerf::fuzz {

namespace {

/// The parameter file beside the study that a [calibration] entry may name (written once).
void write_calibrated_parameter_file() {
  static const bool written = [] {
    const char text[] = "[models.fracture]\nrupture_deflection = \"2 mm\"\n";
    write_input_file({reinterpret_cast<const std::byte*>(text), std::strlen(text)}, "calibrated.toml");
    return true;
  }();
  (void)written;
}

} // namespace

void fuzz_study(std::span<const std::byte> data) {
  write_calibrated_parameter_file();
  const std::filesystem::path file = write_input_file(data, "study.toml");
  try {
    const StudySpec spec = read_study(file);
    // study_spec.hpp's ranges, for a study the reader accepted.
    if (spec.name.empty()) throw FuzzFinding("a study was accepted without a name");
    if (spec.scenes.empty() || spec.models.empty()) throw FuzzFinding("a study was accepted without scenes or models");
    std::error_code ec;
    for (const std::filesystem::path& scene : spec.scenes)
      if (!std::filesystem::exists(scene, ec)) throw FuzzFinding("a study was accepted with a missing scene");
    for (const std::string& model : spec.models)
      if (find_model(model) == nullptr) throw FuzzFinding("a study was accepted with a model not in the catalogue");
    const StudyReferenceSpec& r = spec.reference;
    if (r.degree && *r.degree != 1 && *r.degree != 2) throw FuzzFinding("a study was accepted with a degree other than 1 or 2");
    for (const auto& [scene, degree] : r.scene_degree)
      if (degree != 1 && degree != 2) throw FuzzFinding("a study was accepted with a scene degree other than 1 or 2");
    for (const auto& [scene, samples] : r.scene_samples)
      if (samples < 2) throw FuzzFinding("a study was accepted with fewer than 2 reference samples for a scene");
    if (r.refinements.empty() || std::any_of(r.refinements.begin(), r.refinements.end(), [](int l) {
          return l < minimum_study_mesh_level || l > 4;
        }))
      throw FuzzFinding("a study was accepted with a mesh level outside minimum_study_mesh_level..4");
    if (std::adjacent_find(r.refinements.begin(), r.refinements.end(), std::greater_equal<>()) != r.refinements.end())
      throw FuzzFinding("a study was accepted with mesh levels not strictly ascending");
    if (r.samples < 2) throw FuzzFinding("a study was accepted with fewer than 2 reference samples");
    for (const auto& calibration : spec.calibrations) {
      const std::string& scene = calibration.first;
      const bool known = std::any_of(spec.scenes.begin(), spec.scenes.end(),
                                     [&](const std::filesystem::path& s) { return s.stem() == scene; });
      if (!known || calibration.second.empty()) throw FuzzFinding("a calibration was accepted for a scene the study does not run");
    }
  } catch (const StudyError&) {
    // The documented rejection, naming file:line:column and the key.
  }
}

} // namespace kerf::fuzz

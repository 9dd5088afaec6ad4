#pragma once
// A study file (experiments/studies/NAME.toml): scenes x models x resolutions (issue 7).
//
//   [study]
//   name = "default"
//   description = "…"
//   scenes = ["potato_rect_cut", "clay_pull"]      # names in experiments/scenes, or paths
//   models = ["fracture", "springs", "edge", "voxel"]   # each runs on the scenes it can represent
//
//   [reference]                                    # optional: the finite-element ground truth
//   degree = 1
//   refinements = [0, 1]                           # mesh levels; the last is the finest
//   samples = 40                                   # trajectory samples the reference solves
//
//   [calibration]                                  # optional: calibrated rows beside the others
//   clay_pull = ["calibration/clay_pull.springs.toml"]   # parameter files (kerf calibrate -o),
//                                                  # relative to the study file; every model a file
//                                                  # calibrates also runs as "MODEL (calibrated)"
//
// Unknown keys and wrong types are errors naming file:line:column, as for scenes.

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf {

struct StudyReferenceSpec {
  int degree = 1;
  std::vector<int> refinements{0};
  int samples = 40; ///< equilibrium solves along each trajectory (evenly spaced samples)
};

struct StudySpec {
  std::filesystem::path file;
  std::string name;
  std::string description;
  std::vector<std::filesystem::path> scenes; ///< resolved scene files
  std::vector<std::string> models;
  bool has_reference = false;
  StudyReferenceSpec reference;
  /// Parameter files per scene name ([calibration]): each model one of them calibrates is run a
  /// second time on the scene with the file included, as the row "MODEL (calibrated)".
  std::map<std::string, std::vector<std::filesystem::path>> calibrations;
};

class StudyError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// Reads and validates a study file; scene names resolve against the study file's folder, then
/// experiments/scenes. Model names must be in the catalogue.
StudySpec read_study(const std::filesystem::path& file);

/// The models a parameter file calibrates: the names of its [models.*] tables. Throws StudyError
/// naming the file on a syntax error.
std::vector<std::string> calibrated_models(const std::filesystem::path& parameter_file);

} // namespace kerf

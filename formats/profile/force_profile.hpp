#pragma once
// Force profile: one row per tool per trajectory sample (../shared/DESIGN.md, "Force profile"),
// written as CSV with a JSON manifest. Both are written atomically: an interrupted run never
// leaves a half file under the final name.

#include "realtime/force_sample.hpp"

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace kerf {

/// One CSV row: `t,tool,px,py,pz,fx,fy,fz,mode,crack_extent,cost_s`.
struct ProfileRow {
  double t = 0.0;                                  ///< [s]
  std::string tool;                                ///< tool name from the scene
  Eigen::Vector3d position = Eigen::Vector3d::Zero(); ///< tool reference point [m]
  Eigen::Vector3d force = Eigen::Vector3d::Zero();    ///< force of the body on the tool [N]
  InteractionMode mode = InteractionMode::no_contact;
  double crack_extent = 0.0;                       ///< [m]
  double cost_s = 0.0; ///< compute seconds of the model step that produced this sample (shared by the tools of one step)
};

struct ForceProfile {
  std::vector<ProfileRow> rows;
  /// Model steps that reported themselves over budget (ForceSample::over_budget on any tool: an
  /// implicit spring step that did not converge in its iterations, a voxel grid left
  /// incomplete), counted by run_model. Not a CSV column: a run's manifest holds it.
  std::size_t steps_over_budget = 0;
};

/// The CSV header, exactly.
inline constexpr const char* profile_csv_header = "t,tool,px,py,pz,fx,fy,fz,mode,crack_extent,cost_s";

/// Writes the profile (full double precision, %.17g) to `csv` atomically.
void write_profile_csv(const ForceProfile& profile, const std::filesystem::path& csv);

/// Reads a profile CSV back. Throws std::runtime_error naming file:line and the column on a
/// wrong header, a wrong column count, a non-numeric or non-finite number, or an unknown mode.
ForceProfile read_profile_csv(const std::filesystem::path& csv);

/// The rows of the tool named `tool`, in profile order (pointers into `profile`).
std::vector<const ProfileRow*> rows_of_tool(const ForceProfile& profile, const std::string& tool);

/// Work done by the tool named `tool` on the body over rows [first, last] (indices into that
/// tool's rows), by the trapezoidal rule: W = sum ½ (g_k + g_{k-1}) . (p_k - p_{k-1}), where
/// g = -force is the force the tool applies to the body [J].
double tool_work(const ForceProfile& profile, const std::string& tool, std::size_t first, std::size_t last);

/// Writes `manifest` as pretty JSON to `path` atomically.
void write_manifest(const nlohmann::json& manifest, const std::filesystem::path& path);

} // namespace kerf

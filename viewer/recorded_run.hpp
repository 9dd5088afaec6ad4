#pragma once
// RecordedRun: one run directory as the replay shows it — its manifest, its force profile, and its
// body over time: a .vtu series the run wrote (the reference's fields.pvd, or a model's own series
// named in the manifest's "fields" entry, e.g. the spring network's springs.pvd), or else the
// model rebuilt from the manifest (scene file, model name, integrator) and re-stepped through the
// tool samples the profile recorded, snapshotted at evenly spaced times.

#include "formats/profile/force_profile.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene.hpp"
#include "viewer/body_view.hpp"
#include "viewer/model_adapter.hpp"
#include "viewer/pvd_series.hpp"

#include <Eigen/Geometry>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace kerf {

class RecordedRun {
public:
  /// Reads DIR/manifest.json and DIR/profile.csv (std::runtime_error naming the file when
  /// missing or malformed), then the run's series (DIR/fields.pvd, else the .pvd the manifest's
  /// fields.series names, else the only .pvd in DIR) if it has one, else rebuilds the model and
  /// re-steps it, keeping `frames` snapshots (>= 2) over the run. A reference run must have
  /// its fields.pvd.
  RecordedRun(const std::filesystem::path& dir, int frames);
  ~RecordedRun();
  RecordedRun(const RecordedRun&) = delete;
  RecordedRun& operator=(const RecordedRun&) = delete;

  /// "DIR-NAME (MODEL)".
  [[nodiscard]] const std::string& label() const { return m_label; }
  [[nodiscard]] const std::string& model_name() const { return m_model_name; }
  [[nodiscard]] const Scene& scene() const { return *m_scene; }
  /// True when the body comes from a .vtu series the run wrote (not re-stepped).
  [[nodiscard]] bool has_series() const { return m_pvd != nullptr; }
  /// Time of the last profile row [s].
  [[nodiscard]] double duration() const { return m_duration; }
  /// The bounding box [m] of the rest body, the tools' recorded positions, and the moved body:
  /// a series' last step, or every snapshot of a re-stepped model.
  [[nodiscard]] Eigen::AlignedBox3d bounds() const { return m_bounds; }
  /// The first tool's force-displacement curve: per profile row of that tool, the time [s], the
  /// distance of the tool from its first recorded position [m] and the force magnitude [N].
  [[nodiscard]] const std::vector<double>& curve_time() const { return m_curve_t; }
  [[nodiscard]] const std::vector<double>& curve_displacement() const { return m_curve_u; }
  [[nodiscard]] const std::vector<double>& curve_force() const { return m_curve_f; }
  /// Re-stepped run: the largest difference between the re-stepped model's force and the
  /// recorded one over the snapshots [N] (0 for a deterministic model); 0 for a series.
  [[nodiscard]] double replay_force_difference() const { return m_replay_difference; }
  /// Index of the first tool's last profile row at or before `t`.
  [[nodiscard]] std::size_t curve_index(double t) const;

  /// Draws the run at time `t` [s] into `view` (body, overlay, tools, forces, text).
  void show(double t, BodyView& view, bool text);

private:
  std::string m_label, m_model_name;
  std::unique_ptr<Scene> m_scene;
  ForceProfile m_profile;
  std::vector<std::string> m_tools;
  double m_duration = 0.0;
  Eigen::AlignedBox3d m_bounds;
  std::vector<double> m_curve_t, m_curve_u, m_curve_f;
  double m_replay_difference = 0.0;
  std::unique_ptr<PvdSeries> m_pvd;
  std::string m_series_name;
  // Fast model: snapshots.
  std::vector<double> m_frame_times;
  std::vector<BodyGeometry> m_frames;
};

} // namespace kerf

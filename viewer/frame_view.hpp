#pragma once
// FrameView: draws one model's ViewFrames in one renderer — the body through the model's
// adapter, the overlay, the tools and forces, and the text (scene and model, time, each tool's
// mode and force, the servo statistics, the model's status line).

#include "viewer/body_view.hpp"
#include "viewer/model_adapter.hpp"

#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

class vtkRenderer;

namespace kerf {

struct FrameViewSettings {
  std::string title;                    ///< first text line ("clay_pull / springs")
  std::vector<std::string> tool_names;  ///< one per tool
  std::vector<ToolGlyph> tools;         ///< one per tool
  Colouring colouring = Colouring::displacement;
  ElasticConstants elastic;             ///< for von Mises colouring
  double colour_max = 0.0;              ///< fixed colour range [0, max] (m or Pa); 0: the largest value shown so far
  bool overlay = true;
  bool text = true;                     ///< the text block and the colour legend
};

class FrameView {
public:
  FrameView(vtkRenderer* renderer, ModelAdapter& adapter, FrameViewSettings settings);

  /// Draws `frame` (render thread).
  void show(const ViewFrame& frame);
  /// A force magnitude seen by the tools [N]: arrows are scaled so that the largest one noted
  /// is a quarter of the body's diagonal.
  void note_force(double newtons);
  void toggle_overlay();
  /// The rest body's bounding box with the tools at their first positions [m] (for the camera).
  [[nodiscard]] Eigen::AlignedBox3d bounds() const { return m_bounds; }
  /// Extends the box the camera frames (e.g. by a tool's whole path).
  void extend_bounds(const Eigen::Vector3d& p) { m_bounds.extend(p); }
  [[nodiscard]] BodyView& body() { return m_body; }
  /// The body as last shown (positions, rest positions, cells) [m].
  [[nodiscard]] const BodyGeometry& shown() const { return m_geometry; }

private:
  ModelAdapter& m_adapter;
  FrameViewSettings m_settings;
  BodyView m_body;
  BodyGeometry m_geometry;
  Eigen::AlignedBox3d m_bounds;
  double m_force_max = 0.1;  ///< [N]: below this an arrow is not scaled up
  double m_colour_max = 0.0;
};

} // namespace kerf

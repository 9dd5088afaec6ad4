#pragma once
// ViewWindow: the VTK render window of `kerf view` — one renderer per body side by side (sharing
// one camera, so the bodies are compared from the same place) and optionally a chart strip along
// the bottom; on screen with an interactor and a display-rate timer, or off screen for
// screenshots (under Xvfb with Mesa when there is no screen).

#include <Eigen/Geometry>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

class vtkCamera;

namespace kerf {

/// Where the camera looks from.
enum class CameraView {
  oblique, ///< from the front-right, above (for pictures)
  front    ///< along +y (from y < 0), z up: x to the right, z up on the image
};
/// "oblique", "front".
std::optional<CameraView> camera_view_from_string(std::string_view name);

/// Throws std::runtime_error with a clear message when no X display can be opened (DISPLAY unset
/// or unreachable): VTK's X render window would abort the process instead.
void require_display();

/// Points `camera` at `box` (world, [m]) with a parallel projection that fits the whole box in a
/// viewport of width/height `aspect` with a 10% margin.
void frame_camera(vtkCamera* camera, const Eigen::AlignedBox3d& box, CameraView view, double aspect);

struct ViewWindowSettings {
  int width = 1280;     ///< [px]
  int height = 800;     ///< [px]
  bool offscreen = false;
  std::string title = "kerf view";
};

class ViewWindow {
public:
  /// `columns` body renderers side by side; `chart` adds a strip of 30% of the height below them.
  /// Checks the display first (require_display).
  ViewWindow(const ViewWindowSettings& settings, int columns, bool chart);
  ~ViewWindow();
  ViewWindow(const ViewWindow&) = delete;
  ViewWindow& operator=(const ViewWindow&) = delete;

  [[nodiscard]] vtkRenderer* body_renderer(int column) const { return m_bodies.at(static_cast<std::size_t>(column)); }
  /// The chart strip's renderer (null without a chart).
  [[nodiscard]] vtkRenderer* chart_renderer() const { return m_chart; }
  [[nodiscard]] vtkRenderWindow* window() const { return m_window; }
  /// The shared camera of the body renderers.
  [[nodiscard]] vtkCamera* camera() const;
  /// Width / height of one body viewport.
  [[nodiscard]] double body_aspect() const;

  void render();
  /// Renders and writes the window as a PNG (throws std::runtime_error naming the file on failure).
  void write_png(const std::filesystem::path& file);

  /// On screen: handles events and calls `tick` every `period` [s] until it returns false or the
  /// window is closed. `key` (may be empty) gets each key pressed ("o", "space", ...).
  void run(const std::function<bool()>& tick, double period, const std::function<void(const std::string&)>& key);
  /// The interactor of run() (null off screen).
  [[nodiscard]] vtkRenderWindowInteractor* interactor() const { return m_interactor; }

private:
  ViewWindowSettings m_settings;
  vtkSmartPointer<vtkRenderWindow> m_window;
  std::vector<vtkSmartPointer<vtkRenderer>> m_bodies;
  vtkSmartPointer<vtkRenderer> m_chart;
  vtkSmartPointer<vtkRenderWindowInteractor> m_interactor;
};

} // namespace kerf

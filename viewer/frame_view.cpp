#include "viewer/frame_view.hpp"

#include <vtkDataSet.h>

#include <cstdio>

namespace kerf {

FrameView::FrameView(vtkRenderer* renderer, ModelAdapter& adapter, FrameViewSettings settings)
    : m_adapter(adapter), m_settings(std::move(settings)), m_body(renderer, m_settings.colouring, m_settings.tools) {
  ViewFrame empty;
  m_adapter.geometry(empty, m_geometry);
  for (Eigen::Index i = 0; i < m_geometry.rest.rows(); ++i) m_bounds.extend(m_geometry.rest.row(i).transpose());
  // Floors of the automatic colour range: 0.1 mm, 1 kPa (below them a body at rest stays one colour).
  m_colour_max = m_settings.colour_max > 0.0 ? m_settings.colour_max
                                             : (m_settings.colouring == Colouring::displacement ? 1e-4 : 1e3);
  m_body.set_colour_range(m_colour_max);
  m_body.set_overlay_visible(m_settings.overlay);
  m_body.set_legend_visible(m_settings.text);
}

void FrameView::note_force(double newtons) {
  if (newtons > m_force_max) m_force_max = newtons;
}

void FrameView::toggle_overlay() { m_body.set_overlay_visible(!m_body.overlay_visible()); }

void FrameView::show(const ViewFrame& frame) {
  m_adapter.geometry(frame, m_geometry);
  m_body.set_body(body_dataset(m_geometry, m_settings.colouring == Colouring::von_mises ? &m_settings.elastic : nullptr));
  if (m_settings.colour_max <= 0.0 && m_body.data_maximum() > m_colour_max) {
    m_colour_max = m_body.data_maximum();
    m_body.set_colour_range(m_colour_max);
  }
  m_body.set_overlay(m_geometry.overlay_points, m_geometry.overlay_lines);

  const auto tools = static_cast<std::size_t>(std::max(frame.tool_count, 0));
  std::vector<Eigen::Vector3d> positions(tools), forces(tools);
  for (std::size_t i = 0; i < tools; ++i) {
    positions[i] = frame.tool_position[i];
    forces[i] = frame.force[i].force;
    note_force(forces[i].norm());
  }
  m_body.set_force_scale(0.25 * m_bounds.sizes().norm() / m_force_max);
  m_body.set_tools(positions, forces);

  if (!m_settings.text) {
    m_body.set_text("");
    return;
  }
  std::string text;
  char line[256];
  std::snprintf(line, sizeof line, "%s   t = %.3f s\n", m_settings.title.c_str(), std::max(frame.time, 0.0));
  text += line;
  for (std::size_t i = 0; i < tools; ++i) {
    const ForceSample& f = frame.force[i];
    const std::string name = i < m_settings.tool_names.size() ? m_settings.tool_names[i] : "tool " + std::to_string(i);
    std::snprintf(line, sizeof line, "%s: %s, |F| = %.3f N (%.3f, %.3f, %.3f)\n", name.c_str(),
                  std::string(to_string(f.mode)).c_str(), f.force.norm(), f.force.x(), f.force.y(), f.force.z());
    text += line;
  }
  if (frame.servo.ticks > 0) {
    std::snprintf(line, sizeof line, "servo: %llu ticks, %llu overruns, %llu missed; tick mean %.1f us, max %.1f us\n",
                  static_cast<unsigned long long>(frame.servo.ticks), static_cast<unsigned long long>(frame.servo.overruns),
                  static_cast<unsigned long long>(frame.servo.missed_deadlines), frame.servo.tick_mean * 1e6,
                  frame.servo.tick_max * 1e6);
    text += line;
  }
  text += m_geometry.status + "\n";
  text += "overlay: " + std::string(m_adapter.overlay_name()) + (m_body.overlay_visible() ? " (on" : " (off") + ", key o)";
  m_body.set_text(text);
}

} // namespace kerf

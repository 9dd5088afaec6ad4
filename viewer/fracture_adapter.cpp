#include "viewer/fracture_adapter.hpp"

#include <cstdio>

namespace kerf {

FractureAdapter::FractureAdapter(const FractureCuttingModel& model, const TetMesh& mesh) : m_model(model), m_mesh(mesh) {}

void FractureAdapter::reserve(ModelState& state) const {
  state.points.resize(3, 0);
  state.rest.resize(3, 0);
  state.cells.clear();
  state.point_count = 0;
  state.cell_count = 0;
}

void FractureAdapter::capture(ModelState& state) const noexcept {
  const Eigen::Vector3d& o = m_model.frame_origin();
  for (int i = 0; i < 3; ++i) state.scalars[static_cast<std::size_t>(i)] = o[i];
  state.scalars[3] = 1.0;
}

void FractureAdapter::geometry(const ViewFrame& frame, BodyGeometry& out) {
  out.points = m_mesh.nodes;
  out.rest = m_mesh.nodes;
  out.tets = m_mesh.tets;
  out.triangles.resize(0, 3);
  const double c = frame.tool_count > 0 ? frame.force[0].crack_extent : 0.0;
  const FractureCuttingSetup& s = m_model.setup();
  if (frame.model.scalars[3] > 0.5 && c > 0.0) {
    // The crack of paper 001 Fig. 3: from the entry point along the cutting axis to depth c,
    // across the edge length (centred on the edge midpoint, the tool's reference point).
    const Eigen::Vector3d o(frame.model.scalars[0], frame.model.scalars[1], frame.model.scalars[2]);
    const Eigen::Vector3d half = 0.5 * s.blade.edge_length * s.blade.edge_direction;
    const Eigen::Vector3d depth = c * s.blade.cutting_direction;
    out.overlay_points.resize(4, 3);
    out.overlay_points.row(0) = (o - half).transpose();
    out.overlay_points.row(1) = (o + half).transpose();
    out.overlay_points.row(2) = (o + half + depth).transpose();
    out.overlay_points.row(3) = (o - half + depth).transpose();
    out.overlay_lines.resize(5, 2);
    out.overlay_lines << 0, 1, 1, 2, 2, 3, 3, 0, 0, 2;
  } else {
    out.overlay_points.resize(0, 3);
    out.overlay_lines.resize(0, 2);
  }
  char line[128];
  std::snprintf(line, sizeof line, "fracture: crack depth %.2f mm, contact length %.2f mm", c * 1e3,
                m_model.contact_length() * 1e3);
  out.status = line;
}

} // namespace kerf

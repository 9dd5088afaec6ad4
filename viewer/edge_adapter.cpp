#include "viewer/edge_adapter.hpp"

#include <cstdio>

namespace kerf {

EdgeAdapter::EdgeAdapter(const DiscreteEdgeCuttingModel& model, const TetMesh& mesh) : m_model(model), m_mesh(mesh) {}

void EdgeAdapter::reserve(ModelState& state) const {
  const auto n = static_cast<Eigen::Index>(m_model.points().size());
  state.points = Eigen::Matrix3Xd::Zero(3, 3 * n);
  state.rest = Eigen::Matrix3Xd::Zero(3, 3 * n);
  // cells[i][0] = has_cut of point i (the only per-point flag the overlay needs).
  state.cells.assign(static_cast<std::size_t>(n), {});
  state.point_count = 0;
  state.cell_count = 0;
}

void EdgeAdapter::capture(ModelState& state) const noexcept {
  const auto& points = m_model.points();
  const auto n = std::min<Eigen::Index>(static_cast<Eigen::Index>(points.size()), state.points.cols() / 3);
  int cut = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& p = points[static_cast<std::size_t>(i)];
    state.points.col(i) = p.present;
    state.points.col(n + i) = p.entry;
    state.points.col(2 * n + i) = p.relaxed;
    state.cells[static_cast<std::size_t>(i)][0] = p.has_cut ? 1 : 0;
    cut += p.has_cut ? 1 : 0;
  }
  state.point_count = static_cast<int>(3 * n);
  state.cell_count = static_cast<int>(n);
  state.scalars[0] = cut;
}

void EdgeAdapter::geometry(const ViewFrame& frame, BodyGeometry& out) {
  const ModelState& state = frame.model;
  out.points = m_mesh.nodes;
  out.rest = m_mesh.nodes;
  out.tets = m_mesh.tets;
  out.triangles.resize(0, 3);
  const int n = state.cell_count;
  out.overlay_points = state.points.leftCols(state.point_count).transpose();
  std::vector<std::array<int, 2>> lines;
  for (int i = 0; i + 1 < n; ++i) lines.push_back({i, i + 1}); // the edge through its present points
  for (int i = 0; i < n; ++i)
    if (state.cells[static_cast<std::size_t>(i)][0] != 0) lines.push_back({n + i, 2 * n + i}); // a cut path
  out.overlay_lines.resize(static_cast<Eigen::Index>(lines.size()), 2);
  for (std::size_t l = 0; l < lines.size(); ++l) out.overlay_lines.row(static_cast<Eigen::Index>(l)) << lines[l][0], lines[l][1];
  char line[128];
  std::snprintf(line, sizeof line, "discrete edge: %d points, %d have cut", n, static_cast<int>(state.scalars[0]));
  out.status = line;
}

} // namespace kerf

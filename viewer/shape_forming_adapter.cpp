#include "viewer/shape_forming_adapter.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace kerf {

namespace {

/// The 12 edges of a cubic cell as pairs of local corners (corner a = bx + 2 by + 4 bz).
constexpr std::array<std::array<int, 2>, 12> cell_edges{{{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                                         {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

} // namespace

ShapeFormingAdapter::ShapeFormingAdapter(const ShapeFormingModel& model, const TetMesh& mesh)
    : m_model(model), m_mesh(mesh) {}

void ShapeFormingAdapter::reserve(ModelState& state) const {
  // Any stage's network: N cells per side, at most N³ kept cells, and node arrays of 8 per kept
  // cell (build_spring_network's capacity, room for the copies tearing adds).
  const long cells = static_cast<long>(m_model.setup().springs.cells) * m_model.setup().springs.cells *
                     m_model.setup().springs.cells;
  const long edge_points = static_cast<long>(m_model.edge().points().size());
  state.points = Eigen::Matrix3Xd::Zero(3, 8 * cells + edge_points);
  state.rest = Eigen::Matrix3Xd::Zero(3, 8 * cells);
  state.cells.assign(static_cast<std::size_t>(cells), {});
  state.point_count = 0;
  state.cell_count = 0;
  state.published = nullptr;
}

void ShapeFormingAdapter::capture(ModelState& state) const noexcept {
  const FormingStage* stage = m_model.active_stage();
  int m = 0;
  int cells = 0;
  if (stage) {
    const SpringNetwork& net = stage->springs->network();
    m = std::min<int>(net.node_count, static_cast<int>(state.rest.cols()));
    cells = std::min<int>(net.cell_count(), static_cast<int>(state.cells.size()));
    state.points.leftCols(m) = stage->springs->positions().leftCols(m);
    state.rest.leftCols(m) = net.rest.leftCols(m);
    for (int c = 0; c < cells; ++c) state.cells[static_cast<std::size_t>(c)] = net.cell_nodes[static_cast<std::size_t>(c)];
  }
  const auto& points = m_model.edge().points();
  const int n = std::min<int>(static_cast<int>(points.size()), static_cast<int>(state.points.cols()) - m);
  int cut = 0;
  for (int i = 0; i < n; ++i) {
    const auto& p = points[static_cast<std::size_t>(i)];
    state.points.col(m + i) = p.present;
    cut += p.has_cut ? 1 : 0;
  }
  state.point_count = m + n;
  state.cell_count = cells;
  state.published = stage;
  state.topology = reinterpret_cast<std::uintptr_t>(stage);
  state.scalars[0] = cut;
  state.scalars[1] = m;
  state.scalars[2] = n;
}

void ShapeFormingAdapter::geometry(const ViewFrame& frame, BodyGeometry& out) {
  const ModelState& state = frame.model;
  const auto* stage = static_cast<const FormingStage*>(state.published);
  const int m = static_cast<int>(state.scalars[1]);
  const int n = static_cast<int>(state.scalars[2]);
  std::vector<std::array<int, 2>> lines;
  for (int i = 0; i + 1 < n; ++i) lines.push_back({m + i, m + i + 1}); // the edge through its present points
  char line[160];
  if (!stage) {
    // Nothing cut yet (or nothing captured): the body at rest; a stage seen before is gone
    // (the model was reset), so its address means nothing any more.
    m_stage = nullptr;
    out.points = m_mesh.nodes;
    out.rest = m_mesh.nodes;
    out.tets = m_mesh.tets;
    std::snprintf(line, sizeof line, "shape forming: %d of %d edge points have cut, no cut applied yet",
                  static_cast<int>(state.scalars[0]), n);
  } else {
    if (stage != m_stage) {
      // The grid of the stage's network (set when it was built, before the stage was published).
      const SpringNetwork& net = stage->springs->network();
      m_net = SpringNetwork{};
      m_net.block = net.block;
      m_net.cell_index = net.cell_index;
      m_net.cell_at = net.cell_at;
      m_net.cell_nodes.assign(net.cell_index.size(), {});
      m_x = Eigen::Matrix3Xd::Zero(3, state.rest.cols());
      m_moved.resize(stage->mesh.nodes.rows(), 3);
      m_fragments = stage->fragment_of_tet.empty()
                        ? 0
                        : 1 + *std::max_element(stage->fragment_of_tet.begin(), stage->fragment_of_tet.end());
      m_stage = stage;
    }
    const int cells = std::min<int>(state.cell_count, static_cast<int>(m_net.cell_nodes.size()));
    for (int c = 0; c < cells; ++c) m_net.cell_nodes[static_cast<std::size_t>(c)] = state.cells[static_cast<std::size_t>(c)];
    m_x.leftCols(m) = state.points.leftCols(m);
    // Paper 000 §2.1: the fragment's fine nodes follow the network (the stage's embedding); the
    // other fragments stay where the cut left them.
    stage->embedding->apply(m_net, m_x, m_moved);
    out.points = stage->cut_mesh.nodes;
    for (std::size_t i = 0; i < stage->cut_mesh_node.size(); ++i)
      out.points.row(stage->cut_mesh_node[i]) = m_moved.row(static_cast<Eigen::Index>(i));
    out.rest = stage->cut_mesh.nodes;
    out.tets = stage->cut_mesh.tets;
    for (int c = 0; c < cells; ++c)
      for (const auto& e : cell_edges)
        lines.push_back({state.cells[static_cast<std::size_t>(c)][static_cast<std::size_t>(e[0])],
                         state.cells[static_cast<std::size_t>(c)][static_cast<std::size_t>(e[1])]});
    std::snprintf(line, sizeof line, "shape forming: cut in %d fragment(s), the stylus's one (%d) on %d cells",
                  m_fragments, stage->fragment, cells);
  }
  out.triangles.resize(0, 3);
  out.overlay_points = state.points.leftCols(state.point_count).transpose();
  out.overlay_lines.resize(static_cast<Eigen::Index>(lines.size()), 2);
  for (std::size_t l = 0; l < lines.size(); ++l) out.overlay_lines.row(static_cast<Eigen::Index>(l)) << lines[l][0], lines[l][1];
  out.status = line;
}

} // namespace kerf

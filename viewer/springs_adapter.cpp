#include "viewer/springs_adapter.hpp"

#include "realtime/springs/torn_tet_mesh.hpp"

#include <cstdio>
#include <stdexcept>

namespace kerf {

namespace {

/// The 12 edges of a cubic cell as pairs of local corners (corner a = bx + 2 by + 4 bz): the
/// pairs that differ in exactly one bit.
constexpr std::array<std::array<int, 2>, 12> cell_edges{{{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                                         {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

} // namespace

SpringsAdapter::SpringsAdapter(const SpringNetworkModel& model, const TetMesh& mesh)
    : m_model(model), m_mesh(mesh), m_net(model.network()), m_body(mesh) {
  if (model.tears() != 0)
    throw std::invalid_argument("viewer: the springs adapter must be built before the network tears");
  m_embedding = std::make_unique<NetworkEmbedding>(m_net, m_body.nodes, EmbeddingScheme::coons);
  m_x = m_net.rest;
}

void SpringsAdapter::reserve(ModelState& state) const {
  const SpringNetwork& net = m_model.network();
  state.points = Eigen::Matrix3Xd::Zero(3, net.node_capacity());
  state.rest = Eigen::Matrix3Xd::Zero(3, net.node_capacity());
  state.cells.assign(net.cell_nodes.size(), {});
  state.point_count = 0;
  state.cell_count = 0;
}

void SpringsAdapter::capture(ModelState& state) const noexcept {
  const SpringNetwork& net = m_model.network();
  const int n = std::min<int>(net.node_count, static_cast<int>(state.points.cols()));
  state.points.leftCols(n) = m_model.positions().leftCols(n);
  state.rest.leftCols(n) = net.rest.leftCols(n);
  const std::size_t cells = std::min(net.cell_nodes.size(), state.cells.size());
  for (std::size_t c = 0; c < cells; ++c) state.cells[c] = net.cell_nodes[c];
  state.point_count = n;
  state.cell_count = static_cast<int>(cells);
  state.topology = static_cast<std::uint64_t>(m_model.tears());
  state.scalars[0] = m_model.tears();
  state.scalars[1] = m_model.pieces();
}

void SpringsAdapter::rebuild_body(const ModelState& state) {
  const int n = state.point_count;
  m_net.node_count = n;
  m_net.rest.leftCols(n) = state.rest.leftCols(n);
  for (int c = 0; c < state.cell_count; ++c) m_net.cell_nodes[static_cast<std::size_t>(c)] = state.cells[static_cast<std::size_t>(c)];
  if (state.topology == 0) {
    m_body = m_mesh;
    m_embedding = std::make_unique<NetworkEmbedding>(m_net, m_body.nodes, EmbeddingScheme::coons);
  } else {
    // Paper 000 §2.2, Fig. 5: the fine tetrahedra are divided along the exposed cell faces and
    // each side is embedded in the cells of its own piece.
    // Each node is embedded in a kept cell of its own piece that holds it (TornTetMesh::host_cell).
    TornTetMesh torn = split_tet_mesh(m_mesh, m_net);
    m_body = std::move(torn.mesh);
    m_embedding = std::make_unique<NetworkEmbedding>(m_net, m_body.nodes, EmbeddingScheme::coons, &torn.host_cell);
  }
  m_topology = state.topology;
}

void SpringsAdapter::geometry(const ViewFrame& frame, BodyGeometry& out) {
  const ModelState& state = frame.model;
  if (state.point_count == 0) { // nothing captured yet: the rest mesh
    out.points = m_mesh.nodes;
    out.rest = m_mesh.nodes;
    out.tets = m_mesh.tets;
    out.triangles.resize(0, 3);
    out.overlay_points.resize(0, 3);
    out.overlay_lines.resize(0, 2);
    out.status = "spring network";
    return;
  }
  if (state.topology != m_topology) rebuild_body(state);
  const int n = state.point_count;
  m_x.leftCols(n) = state.points.leftCols(n);
  out.points.resize(m_body.nodes.rows(), 3);
  m_embedding->apply(m_net, m_x, out.points);
  out.rest = m_body.nodes;
  out.tets = m_body.tets;
  out.triangles.resize(0, 3);

  out.overlay_points = state.points.leftCols(n).transpose();
  out.overlay_lines.resize(static_cast<Eigen::Index>(state.cell_count) * 12, 2);
  for (int c = 0; c < state.cell_count; ++c)
    for (std::size_t e = 0; e < cell_edges.size(); ++e) {
      const auto& corners = state.cells[static_cast<std::size_t>(c)];
      out.overlay_lines(c * 12 + static_cast<Eigen::Index>(e), 0) = corners[static_cast<std::size_t>(cell_edges[e][0])];
      out.overlay_lines(c * 12 + static_cast<Eigen::Index>(e), 1) = corners[static_cast<std::size_t>(cell_edges[e][1])];
    }
  char line[128];
  std::snprintf(line, sizeof line, "spring network: %d cells, %d tears, %d piece(s)", state.cell_count,
                static_cast<int>(state.scalars[0]), static_cast<int>(state.scalars[1]));
  out.status = line;
}

} // namespace kerf

#include "viewer/springs_adapter.hpp"

#include "realtime/springs/torn_tet_mesh.hpp"
#include "realtime/springs/vertex_tearing.hpp"

#include <cstdio>
#include <stdexcept>

namespace kerf {

namespace {

/// The 12 edges of a cubic cell as pairs of local corners (corner a = bx + 2 by + 4 bz): the
/// pairs that differ in exactly one bit.
constexpr std::array<std::array<int, 2>, 12> cell_edges{{{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                                         {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

/// The cell each node of a torn fine mesh is embedded in (paper 000 §2.2, Fig. 5: each side of
/// the division follows the cells of its own piece): a kept cell of the node's piece (the piece
/// of the tetrahedra that use it, TornTetMesh::piece) whose closed box holds the node's rest
/// position; −1 when there is none (the node keeps its rest position). split_tet_mesh's own
/// host_cell is kept when it satisfies this; it gives each node the cell of the centroid of the
/// first tetrahedron that uses it, which for a node on a cell face, edge or corner can be a
/// neighbouring cell that does not hold the node, and NetworkEmbedding leaves such a node at
/// rest (behind its moved piece, as a spike). Allocates.
std::vector<int> torn_host_cells(const TornTetMesh& torn, const SpringNetwork& net) {
  std::vector<int> parent(static_cast<std::size_t>(net.node_capacity())), label(static_cast<std::size_t>(net.cell_count()));
  network_pieces(net, parent, label);
  const auto nodes = static_cast<std::size_t>(torn.mesh.nodes.rows());
  std::vector<int> piece(nodes, -1);
  for (Eigen::Index t = 0; t < torn.mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) piece[static_cast<std::size_t>(torn.mesh.tets(t, k))] = torn.piece[static_cast<std::size_t>(t)];
  const double h = net.block.cell_size;
  const double eps = 1e-9; // in cell widths, NetworkEmbedding's tolerance
  const auto holds = [&](int cell, const Eigen::Vector3d& q) {
    const Eigen::Vector3d xi = q - net.cell_index[static_cast<std::size_t>(cell)].cast<double>();
    return (xi.array() >= -eps).all() && (xi.array() <= 1.0 + eps).all();
  };
  std::vector<int> host(nodes, -1);
  for (std::size_t p = 0; p < nodes; ++p) {
    const Eigen::Vector3d q = (torn.mesh.nodes.row(static_cast<Eigen::Index>(p)).transpose() - net.block.origin) / h;
    const int given = torn.host_cell[p];
    if (given >= 0 && label[static_cast<std::size_t>(given)] == piece[p] && holds(given, q)) {
      host[p] = given;
      continue;
    }
    // The cells whose closed boxes hold q: q's own and its neighbours across the faces, edges and
    // corners q lies on, on either side (q = 0.035 m / 0.005 m rounds to just under 7: the cell
    // above the face holds it too).
    const Eigen::Vector3i base = q.array().floor().cast<int>();
    for (int k = 0; k < 27 && host[p] < 0; ++k) {
      const Eigen::Vector3i g = base + Eigen::Vector3i(k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1);
      const int c = net.cell_at_index(g);
      if (c >= 0 && label[static_cast<std::size_t>(c)] == piece[p] && holds(c, q)) host[p] = c;
    }
  }
  return host;
}

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
    TornTetMesh torn = split_tet_mesh(m_mesh, m_net);
    const std::vector<int> host = torn_host_cells(torn, m_net);
    m_body = std::move(torn.mesh);
    m_embedding = std::make_unique<NetworkEmbedding>(m_net, m_body.nodes, EmbeddingScheme::coons, &host);
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

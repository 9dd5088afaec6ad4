#include "realtime/springs/torn_tet_mesh.hpp"

#include "realtime/springs/vertex_tearing.hpp"
#include "meshes/tet_quality.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <map>
#include <tuple>

namespace kerf {

namespace {

using Tet = std::array<Eigen::Vector3d, 4>;

double signed_volume(const Tet& t) { return kerf::signed_volume(t[0], t[1], t[2], t[3]); }

/// The parts of tetrahedron `t` on each side of the plane x_axis = value: exact tilings.
void clip(const Tet& t, int axis, double value, double snap, std::vector<Tet>& below, std::vector<Tet>& above) {
  std::array<int, 4> s{};
  for (int i = 0; i < 4; ++i) {
    const double d = t[static_cast<std::size_t>(i)][axis] - value;
    s[static_cast<std::size_t>(i)] = d > snap ? 1 : d < -snap ? -1 : 0;
  }
  for (const int side : {1, -1}) {
    std::vector<Tet>& out = side > 0 ? above : below;
    std::vector<int> in, on, away;
    for (int i = 0; i < 4; ++i) (s[static_cast<std::size_t>(i)] == side ? in : s[static_cast<std::size_t>(i)] == 0 ? on : away).push_back(i);
    if (in.empty()) continue;
    if (away.empty()) {
      out.push_back(t);
      continue;
    }
    const auto P = [&t](int i) { return t[static_cast<std::size_t>(i)]; };
    // Point where edge (i, j) crosses the plane (endpoints in a fixed order for equal results).
    const auto Q = [&](int i, int j) {
      const Eigen::Vector3d& a = t[static_cast<std::size_t>(std::min(i, j))];
      const Eigen::Vector3d& b = t[static_cast<std::size_t>(std::max(i, j))];
      const double w = (value - a[axis]) / (b[axis] - a[axis]);
      Eigen::Vector3d q = a + w * (b - a);
      q[axis] = value;
      return q;
    };
    const std::size_t ni = in.size(), na = away.size();
    if (ni == 1 && na == 1) out.push_back({P(in[0]), Q(in[0], away[0]), P(on[0]), P(on[1])});
    else if (ni == 1 && na == 2) out.push_back({P(in[0]), Q(in[0], away[0]), Q(in[0], away[1]), P(on[0])});
    else if (ni == 1 && na == 3) out.push_back({P(in[0]), Q(in[0], away[0]), Q(in[0], away[1]), Q(in[0], away[2])});
    else if (ni == 2 && na == 1) { // pyramid: quad (in1, in2, q2, q1), apex on
      const Eigen::Vector3d q1 = Q(in[0], away[0]), q2 = Q(in[1], away[0]);
      out.push_back({P(in[0]), P(in[1]), q2, P(on[0])});
      out.push_back({P(in[0]), q2, q1, P(on[0])});
    } else { // prisms (a b c / a' b' c') split into 3 tetrahedra
      Eigen::Vector3d a, b, c, a2, b2, c2;
      if (ni == 3) {
        a = P(in[0]), b = P(in[1]), c = P(in[2]);
        a2 = Q(in[0], away[0]), b2 = Q(in[1], away[0]), c2 = Q(in[2], away[0]);
      } else { // 2-2
        a = P(in[0]), b = Q(in[0], away[0]), c = Q(in[0], away[1]);
        a2 = P(in[1]), b2 = Q(in[1], away[0]), c2 = Q(in[1], away[1]);
      }
      out.push_back({a, b, c, c2});
      out.push_back({a, b, c2, b2});
      out.push_back({a, b2, c2, a2});
    }
  }
}

} // namespace

TornTetMesh split_tet_mesh(const TetMesh& mesh, const SpringNetwork& net) {
  std::vector<int> parent(static_cast<std::size_t>(net.node_capacity())), label(static_cast<std::size_t>(net.cell_count()));
  network_pieces(net, parent, label);
  const double h = net.block.cell_size;
  const Eigen::Vector3i& n = net.block.cells;
  const auto grid = [&](const Eigen::Vector3d& p) { return Eigen::Vector3d((p - net.block.origin) / h); };
  const auto cell_of = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3i g = grid(p).array().floor().cast<int>().max(0).min(n.array() - 1);
    return net.cell_at_index(g);
  };
  TornTetMesh torn;
  std::map<std::tuple<int, long long, long long, long long>, int> node_of; // (piece, quantised position)
  std::vector<Eigen::Vector3d> nodes;
  std::vector<Eigen::Vector4i> tets;
  const double quantum = 1e-9 * h;
  // The host of a node of `piece`: a kept cell of that piece whose closed box holds the point
  // (to 1e-9 cell widths), or −1. A point on a cell face, edge or corner lies in up to 8 cells, on
  // either side of each face: its own cell and the neighbours across the faces it lies on, which
  // may be above as well as below (0.035 m / 0.005 m rounds to just under 7: the cell above the
  // face x = 35 mm holds the point too). Own cell first, then the others.
  const auto host_of = [&](const Eigen::Vector3d& p, int piece) {
    constexpr std::array<int, 3> offset{0, -1, 1};
    const Eigen::Vector3d q = grid(p);
    const Eigen::Vector3i base = q.array().floor().cast<int>();
    for (int k = 0; k < 27; ++k) {
      const Eigen::Vector3i g = base + Eigen::Vector3i(offset[static_cast<std::size_t>(k % 3)], offset[static_cast<std::size_t>((k / 3) % 3)],
                                                       offset[static_cast<std::size_t>(k / 9)]);
      const Eigen::Vector3d xi = q - g.cast<double>();
      if ((xi.array() < -1e-9).any() || (xi.array() > 1.0 + 1e-9).any()) continue;
      if (const int c = net.cell_at_index(g); c >= 0 && label[static_cast<std::size_t>(c)] == piece) return c;
    }
    return -1;
  };
  const auto add_tet = [&](Tet t, int piece) {
    if (signed_volume(t) < 0.0) std::swap(t[2], t[3]);
    if (!(signed_volume(t) > 0.0)) return;
    Eigen::Vector4i ids;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& p = t[static_cast<std::size_t>(k)];
      const auto key = std::make_tuple(piece, std::llround(p.x() / quantum), std::llround(p.y() / quantum), std::llround(p.z() / quantum));
      auto [it, inserted] = node_of.emplace(key, static_cast<int>(nodes.size()));
      if (inserted) {
        nodes.push_back(p);
        torn.host_cell.push_back(host_of(p, piece));
      }
      ids[k] = it->second;
    }
    tets.push_back(ids);
    torn.piece.push_back(piece);
  };
  std::vector<Tet> parts, next, below, above;
  for (int t = 0; t < mesh.tets.rows(); ++t) {
    Tet tet;
    for (int k = 0; k < 4; ++k) tet[static_cast<std::size_t>(k)] = mesh.nodes.row(mesh.tets(t, k)).transpose();
    // Pieces of the kept cells the tetrahedron's box overlaps.
    Eigen::Vector3d lo = grid(tet[0]), hi = lo;
    for (const auto& p : tet) lo = lo.cwiseMin(grid(p)), hi = hi.cwiseMax(grid(p));
    const Eigen::Vector3i glo = lo.array().floor().cast<int>().max(0).min(n.array() - 1);
    const Eigen::Vector3i ghi = (hi.array().ceil().cast<int>() - 1).max(0).min(n.array() - 1);
    int first_piece = -1;
    bool mixed = false;
    for (int k = glo.z(); k <= ghi.z(); ++k)
      for (int j = glo.y(); j <= ghi.y(); ++j)
        for (int i = glo.x(); i <= ghi.x(); ++i)
          if (const int c = net.cell_at_index({i, j, k}); c >= 0) {
            const int piece = label[static_cast<std::size_t>(c)];
            if (first_piece < 0) first_piece = piece;
            else mixed = mixed || piece != first_piece;
          }
    if (!mixed) {
      add_tet(tet, first_piece);
      continue;
    }
    parts.assign(1, tet);
    for (int axis = 0; axis < 3; ++axis)
      for (int g = static_cast<int>(std::floor(lo[axis])) + 1; g < hi[axis]; ++g) {
        next.clear();
        for (const Tet& part : parts) {
          below.clear();
          above.clear();
          clip(part, axis, net.block.origin[axis] + g * h, 1e-9 * h, below, above);
          next.insert(next.end(), below.begin(), below.end());
          next.insert(next.end(), above.begin(), above.end());
        }
        parts.swap(next);
      }
    for (const Tet& part : parts) {
      const int c = cell_of((part[0] + part[1] + part[2] + part[3]) / 4.0);
      add_tet(part, c >= 0 ? label[static_cast<std::size_t>(c)] : first_piece);
    }
  }
  torn.mesh.nodes.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (std::size_t k = 0; k < nodes.size(); ++k) torn.mesh.nodes.row(static_cast<Eigen::Index>(k)) = nodes[k].transpose();
  torn.mesh.tets.resize(static_cast<Eigen::Index>(tets.size()), 4);
  VolumeGroup body{"body", 1, {}};
  for (std::size_t k = 0; k < tets.size(); ++k) {
    torn.mesh.tets.row(static_cast<Eigen::Index>(k)) = tets[k].transpose();
    body.tets.push_back(static_cast<int>(k));
  }
  torn.mesh.volume_groups.push_back(std::move(body));
  return torn;
}

} // namespace kerf

#include "realtime/edge/geometric_cut.hpp"

#include "meshes/triangle_closest_point.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace kerf {

namespace {

/// Local nodes of the face opposite local node k, in cyclic order.
constexpr int tet_face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
constexpr int tet_edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

struct FaceKey {
  std::array<int, 3> v;
  bool operator==(const FaceKey&) const = default;
};
struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    return static_cast<std::size_t>(k.v[0]) * 73856093u ^ static_cast<std::size_t>(k.v[1]) * 19349663u ^
           static_cast<std::size_t>(k.v[2]) * 83492791u;
  }
};
FaceKey face_key(int a, int b, int c) {
  std::array<int, 3> v{a, b, c};
  std::sort(v.begin(), v.end());
  return {v};
}


} // namespace

CuttableBody::CuttableBody(TetMesh mesh) : m_mesh(std::move(mesh)) {
  for (Eigen::Index t = 0; t < m_mesh.tets.rows(); ++t) {
    auto node = [&](int k) { return Eigen::Vector3d(m_mesh.nodes.row(m_mesh.tets(t, k))); };
    if (!(signed_volume(node(0), node(1), node(2), node(3)) > 0.0))
      throw std::invalid_argument("geometric cut: tetrahedron " + std::to_string(t) + " is inverted or flat");
  }
  m_adjacency = tet_face_adjacency(m_mesh.tets);
  label_fragments();
}

void CuttableBody::label_fragments() {
  const auto n = static_cast<std::size_t>(m_mesh.tets.rows());
  m_fragment.assign(n, -1);
  m_fragment_count = 0;
  std::vector<int> stack;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (m_fragment[seed] >= 0) continue;
    m_fragment[seed] = m_fragment_count;
    stack.push_back(static_cast<int>(seed));
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      for (int k = 0; k < 4; ++k) {
        const int u = m_adjacency(t, k);
        if (u >= 0 && m_fragment[static_cast<std::size_t>(u)] < 0) {
          m_fragment[static_cast<std::size_t>(u)] = m_fragment_count;
          stack.push_back(u);
        }
      }
    }
    ++m_fragment_count;
  }
}

std::vector<double> CuttableBody::fragment_volumes() const {
  std::vector<double> v(static_cast<std::size_t>(m_fragment_count), 0.0);
  for (Eigen::Index t = 0; t < m_mesh.tets.rows(); ++t) {
    auto node = [&](int k) { return Eigen::Vector3d(m_mesh.nodes.row(m_mesh.tets(t, k))); };
    v[static_cast<std::size_t>(m_fragment[static_cast<std::size_t>(t)])] += signed_volume(node(0), node(1), node(2), node(3));
  }
  return v;
}

GeometricCutReport CuttableBody::cut(const SweptSurface& surface, const GeometricCutOptions& options) {
  if (!(options.snap_tolerance > 0.0 && options.snap_tolerance < 0.1))
    throw std::invalid_argument("geometric cut: snap tolerance must be in (0, 0.1)");
  if (!(options.reach > 0.0 && options.reach <= 1.0)) throw std::invalid_argument("geometric cut: reach must be in (0, 1]");
  GeometricCutReport report;
  report.fragments = m_fragment_count;
  report.min_volume_ratio = 1.0;
  const Eigen::Index node_count = m_mesh.nodes.rows();
  const Eigen::Index tet_count = m_mesh.tets.rows();

  // Nodes and tetrahedra made by this cut live beside the mesh until it is written back.
  std::vector<Eigen::Vector3d> added_nodes;
  std::vector<std::array<int, 4>> added_tets;
  std::vector<int> added_origin; // the original tetrahedron each added one was divided from
  auto position = [&](int g) -> Eigen::Vector3d {
    return g < node_count ? Eigen::Vector3d(m_mesh.nodes.row(g)) : added_nodes[static_cast<std::size_t>(g - node_count)];
  };
  auto corner = [&](int t, int k) -> int& {
    return t < tet_count ? m_mesh.tets(t, k) : added_tets[static_cast<std::size_t>(t - tet_count)][static_cast<std::size_t>(k)];
  };
  auto volume_of = [&](int t) {
    return signed_volume(position(corner(t, 0)), position(corner(t, 1)), position(corner(t, 2)), position(corner(t, 3)));
  };

  // The surface's triangles, their unit normals, and its bounds.
  std::vector<std::array<Eigen::Vector3d, 3>> triangles;
  std::vector<Eigen::Vector3d> normals;
  Eigen::AlignedBox3d surface_box;
  for (Eigen::Index f = 0; f < surface.triangles.rows(); ++f) {
    std::array<Eigen::Vector3d, 3> tri;
    for (int k = 0; k < 3; ++k) {
      const int v = surface.triangles(f, k);
      if (v < 0 || v >= surface.vertices.rows()) throw std::invalid_argument("geometric cut: surface triangle " + std::to_string(f) + " names a missing vertex");
      tri[static_cast<std::size_t>(k)] = surface.vertices.row(v).transpose();
    }
    const Eigen::Vector3d n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    if (!(n.norm() > 0.0) || !n.allFinite()) continue; // a zero-area patch cuts nothing
    for (const auto& v : tri) surface_box.extend(v);
    triangles.push_back(tri);
    normals.push_back(n.normalized());
  }
  if (triangles.empty()) return report;
  auto nearest = [&](const Eigen::Vector3d& p, double& distance) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t which = 0;
    for (std::size_t f = 0; f < triangles.size(); ++f) {
      const double d2 = (p - closest_point_on_triangle(p, triangles[f][0], triangles[f][1], triangles[f][2]).point).squaredNorm();
      if (d2 < best) { best = d2; which = f; }
    }
    distance = std::sqrt(best);
    return which;
  };

  // Candidates: tetrahedra whose box, grown by its own size, meets the surface's box. Every
  // tetrahedron holding a cross point (within reach <= 1/4 of an edge length of the surface) or a
  // node on the surface is among them, since its largest box side is at least edge / sqrt(3).
  std::vector<int> candidates;
  double edge_sum = 0.0;
  for (Eigen::Index t = 0; t < tet_count; ++t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 4; ++k) box.extend(position(m_mesh.tets(t, k)));
    const double size = box.sizes().maxCoeff();
    box.extend(box.min() - Eigen::Vector3d::Constant(size));
    box.extend(box.max() + Eigen::Vector3d::Constant(size));
    if (!box.intersects(surface_box)) continue;
    candidates.push_back(static_cast<int>(t));
    for (const auto& e : tet_edge) edge_sum += (position(m_mesh.tets(t, e[0])) - position(m_mesh.tets(t, e[1]))).norm();
  }
  if (candidates.empty()) return report;
  const double h = edge_sum / (6.0 * static_cast<double>(candidates.size()));
  const double snap = options.snap_tolerance * h;

  // Tetrahedra around each node of the candidates (kept up to date while dividing).
  std::unordered_map<int, std::vector<int>> around;
  for (int t : candidates)
    for (int k = 0; k < 4; ++k) around[m_mesh.tets(t, k)].push_back(t);

  // Signed distance φ of each candidate node to the plane of its nearest patch; side +1/-1, or
  // 0 on the surface (within the snap tolerance of the surface itself).
  std::unordered_map<int, int> side;
  std::unordered_map<int, double> phi;
  for (const auto& [g, unused] : around) {
    (void)unused;
    const Eigen::Vector3d p = position(g);
    double distance = 0.0;
    const std::size_t f = nearest(p, distance);
    const double value = normals[f].dot(p - triangles[f][0]);
    phi[g] = value;
    if (distance < snap) {
      side[g] = 0;
      ++report.snapped_nodes;
    } else {
      side[g] = value < 0.0 ? -1 : 1;
    }
  }

  // Cross points: on each edge whose ends lie on opposite sides, t = φ_a / (φ_a - φ_b) from the
  // lower-numbered end a; kept when the point lies on the swept surface itself (within reach x
  // edge length: the surface is approximated by its linear interpolant) and at least the snap
  // distance from both ends (no part thinner than that).
  struct Cross { int a, b; double t; };
  std::vector<Cross> crosses;
  std::unordered_set<std::uint64_t> seen;
  for (int t : candidates)
    for (const auto& e : tet_edge) {
      int a = m_mesh.tets(t, e[0]), b = m_mesh.tets(t, e[1]);
      if (side[a] * side[b] >= 0) continue;
      if (a > b) std::swap(a, b);
      if (!seen.insert(edge_key(a, b)).second) continue;
      const double x = phi[a] / (phi[a] - phi[b]);
      const double length = (position(b) - position(a)).norm();
      const Eigen::Vector3d point = (1.0 - x) * position(a) + x * position(b);
      double distance = 0.0;
      nearest(point, distance);
      if (distance <= options.reach * length && x * length >= snap && (1.0 - x) * length >= snap) crosses.push_back({a, b, x});
    }

  // Divide (Fig. 8) by bisecting every tetrahedron around each cut edge at its cross point p:
  // T -> T[a := p] and T[b := p]. Replacing one corner by a point of an incident edge scales the
  // signed volume by that point's barycentric weight, so both parts keep T's orientation and
  // their volumes add up to T's: V(T[a := p]) = (1 - t) V(T), V(T[b := p]) = t V(T). The whole
  // ring of the edge is divided alike, so the mesh stays conforming with no rule to propagate.
  // Once every crossing edge of a tetrahedron is bisected no part crosses the surface: the parts
  // on either side are Fig. 8's (a tetrahedron and a prism, two prisms, or with nodes on the
  // surface a tetrahedron and a pyramid, two tetrahedra), already tetrahedralised. A tetrahedron
  // where the cut ends keeps its uncut crossing edges whole: it is divided only at the cross
  // points the surface reaches and stays in one piece (see the opening below).
  std::vector<char> is_changed(static_cast<std::size_t>(tet_count), 0);
  std::vector<int> changed_old;
  std::unordered_set<int> divided_origin;
  auto origin_of = [&](int t) { return t < tet_count ? t : added_origin[static_cast<std::size_t>(t - tet_count)]; };
  auto mark_changed = [&](int t) {
    if (t < tet_count && !is_changed[static_cast<std::size_t>(t)]) {
      is_changed[static_cast<std::size_t>(t)] = 1;
      changed_old.push_back(t);
    }
  };
  auto erase_from = [](std::vector<int>& list, int t) { list.erase(std::find(list.begin(), list.end(), t)); };
  for (const Cross& x : crosses) {
    const int p = static_cast<int>(node_count + static_cast<Eigen::Index>(added_nodes.size()));
    added_nodes.push_back((1.0 - x.t) * position(x.a) + x.t * position(x.b));
    ++report.new_nodes;
    side[p] = 0;
    std::vector<int> ring;
    for (int t : around[x.a])
      for (int k = 0; k < 4; ++k)
        if (corner(t, k) == x.b) ring.push_back(t);
    std::vector<int>& around_p = around[p];
    for (int t : ring) {
      std::array<int, 4> second;
      for (int k = 0; k < 4; ++k) second[static_cast<std::size_t>(k)] = corner(t, k) == x.b ? p : corner(t, k);
      for (int k = 0; k < 4; ++k)
        if (corner(t, k) == x.a) corner(t, k) = p;
      const int u = static_cast<int>(tet_count + static_cast<Eigen::Index>(added_tets.size()));
      added_tets.push_back(second);
      added_origin.push_back(origin_of(t));
      divided_origin.insert(origin_of(t));
      mark_changed(t);
      erase_from(around[x.a], t);
      for (int g : second) around[g].push_back(u); // a, p and the two others
      around_p.push_back(t);
    }
  }
  report.cut_tets = static_cast<int>(divided_origin.size());
  report.new_tets = static_cast<int>(added_tets.size());

  // Opening: a face whose three corners lie on the surface and whose two tetrahedra lie on
  // opposite sides is cut through. Around each node on the surface, the tetrahedra joined through
  // faces that are not cut through form connected groups; each group beyond the first gets its
  // own copy of the node. Where the cut ends inside the body, the tetrahedra left crossing the
  // surface join the two sides around the front's nodes, so those stay shared: the crack opens
  // behind the front and closes at it (progressive splitting).
  auto tet_side = [&](int t) { // +1 / -1 on one side, 0 with no node off the surface, 2 across
    bool plus = false, minus = false;
    for (int k = 0; k < 4; ++k) {
      const auto it = side.find(corner(t, k));
      const int s = it == side.end() ? 0 : it->second;
      plus = plus || s > 0;
      minus = minus || s < 0;
    }
    return plus && minus ? 2 : plus ? 1 : minus ? -1 : 0;
  };
  auto on_surface = [&](int g) {
    const auto it = side.find(g);
    return it != side.end() && it->second == 0;
  };
  std::vector<int> surface_nodes;
  for (const auto& [g, s] : side)
    if (s == 0) surface_nodes.push_back(g);
  std::sort(surface_nodes.begin(), surface_nodes.end());
  for (int z : surface_nodes) {
    std::vector<int> ring = around[z];
    if (ring.size() < 2) continue;
    std::sort(ring.begin(), ring.end());
    std::vector<int> parent(ring.size());
    for (std::size_t i = 0; i < ring.size(); ++i) parent[i] = static_cast<int>(i);
    auto find = [&](int i) {
      while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
      return i;
    };
    std::unordered_map<FaceKey, int, FaceKeyHash> first_with;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const int t = ring[i];
      for (const auto& f : tet_face) {
        const int a = corner(t, f[0]), b = corner(t, f[1]), c = corner(t, f[2]);
        if (a != z && b != z && c != z) continue;
        const auto [it, fresh] = first_with.try_emplace(face_key(a, b, c), static_cast<int>(i));
        if (fresh) continue;
        const int j = it->second;
        const int si = tet_side(t), sj = tet_side(ring[static_cast<std::size_t>(j)]);
        const bool cut_through = on_surface(a) && on_surface(b) && on_surface(c) && si * sj == -1;
        if (!cut_through) parent[static_cast<std::size_t>(find(static_cast<int>(i)))] = find(j);
      }
    }
    std::unordered_map<int, int> copy_of_group;
    const int kept = find(0);
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const int group = find(static_cast<int>(i));
      if (group == kept) continue;
      auto [it, fresh] = copy_of_group.try_emplace(group, -1);
      if (fresh) {
        it->second = static_cast<int>(node_count + static_cast<Eigen::Index>(added_nodes.size()));
        added_nodes.push_back(position(z));
        side[it->second] = 0;
        ++report.new_nodes;
      }
      const int t = ring[i];
      for (int k = 0; k < 4; ++k)
        if (corner(t, k) == z) corner(t, k) = it->second;
      mark_changed(t);
      erase_from(around[z], t);
      around[it->second].push_back(t);
    }
  }

  // Smallest part against its original tetrahedron.
  std::unordered_map<int, double> origin_volume;
  for (int t : divided_origin) origin_volume[t] = 0.0;
  auto all_parts = changed_old;
  for (std::size_t i = 0; i < added_tets.size(); ++i) all_parts.push_back(static_cast<int>(tet_count + static_cast<Eigen::Index>(i)));
  for (int t : all_parts)
    if (const auto it = origin_volume.find(origin_of(t)); it != origin_volume.end()) it->second += volume_of(t);
  for (int t : all_parts)
    if (const auto it = origin_volume.find(origin_of(t)); it != origin_volume.end())
      report.min_volume_ratio = std::min(report.min_volume_ratio, volume_of(t) / it->second);

  // Write back: nodes and tetrahedra appended, volume groups extended by the origin's parts.
  m_mesh.nodes.conservativeResize(node_count + static_cast<Eigen::Index>(added_nodes.size()), 3);
  for (std::size_t i = 0; i < added_nodes.size(); ++i) m_mesh.nodes.row(node_count + static_cast<Eigen::Index>(i)) = added_nodes[i].transpose();
  m_mesh.tets.conservativeResize(tet_count + static_cast<Eigen::Index>(added_tets.size()), 4);
  m_adjacency.conservativeResize(m_mesh.tets.rows(), 4);
  for (std::size_t i = 0; i < added_tets.size(); ++i) {
    const Eigen::Index row = tet_count + static_cast<Eigen::Index>(i);
    for (int k = 0; k < 4; ++k) m_mesh.tets(row, k) = added_tets[i][static_cast<std::size_t>(k)];
    m_adjacency.row(row).setConstant(-1);
  }
  for (VolumeGroup& group : m_mesh.volume_groups)
    for (std::size_t i = 0; i < added_tets.size(); ++i)
      if (std::binary_search(group.tets.begin(), group.tets.end(), added_origin[i])) // stays sorted: appended rows grow
        group.tets.push_back(static_cast<int>(tet_count + static_cast<Eigen::Index>(i)));

  // Neighbour relation, updated locally: the changed and new tetrahedra and their old neighbours.
  std::vector<int> affected = all_parts;
  std::vector<int> neighbours;
  for (int t : changed_old)
    for (int k = 0; k < 4; ++k) {
      const int u = m_adjacency(t, k);
      if (u >= 0 && !is_changed[static_cast<std::size_t>(u)]) neighbours.push_back(u);
    }
  std::sort(neighbours.begin(), neighbours.end());
  neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
  std::unordered_map<FaceKey, std::array<int, 2>, FaceKeyHash> faces;
  auto key_of = [&](int t, int k) {
    return face_key(m_mesh.tets(t, tet_face[k][0]), m_mesh.tets(t, tet_face[k][1]), m_mesh.tets(t, tet_face[k][2]));
  };
  for (const std::vector<int>* list : {&affected, &neighbours})
    for (int t : *list)
      for (int k = 0; k < 4; ++k) {
        auto [it, fresh] = faces.try_emplace(key_of(t, k), std::array<int, 2>{t, -1});
        if (!fresh) it->second[1] = t;
      }
  auto across = [&](int t, int k) {
    const std::array<int, 2>& pair = faces.at(key_of(t, k));
    return pair[0] == t ? pair[1] : pair[0];
  };
  auto changed = [&](int u) { return u >= tet_count || is_changed[static_cast<std::size_t>(u)]; };
  for (int t : affected)
    for (int k = 0; k < 4; ++k) m_adjacency(t, k) = across(t, k);
  for (int t : neighbours)
    for (int k = 0; k < 4; ++k)
      if (const int u = m_adjacency(t, k); u >= 0 && changed(u)) m_adjacency(t, k) = across(t, k);

  label_fragments();
  report.fragments = m_fragment_count;
  return report;
}

} // namespace kerf

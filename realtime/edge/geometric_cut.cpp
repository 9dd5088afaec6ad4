#include "realtime/edge/geometric_cut.hpp"

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

/// A cross point on a mesh edge: its parameter from the lower-numbered node, and its two copies.
struct EdgeCross {
  double t = 0.0;
  bool valid = false;
  int plus = -1;
  int minus = -1;
};

} // namespace

double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d) {
  // V = det[b - a, c - a, d - a] / 6
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

CuttableBody::CuttableBody(TetMesh mesh) : m_mesh(std::move(mesh)) {
  for (Eigen::Index t = 0; t < m_mesh.tets.rows(); ++t) {
    auto node = [&](int k) { return Eigen::Vector3d(m_mesh.nodes.row(m_mesh.tets(t, k))); };
    if (!(signed_tet_volume(node(0), node(1), node(2), node(3)) > 0.0))
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
    v[static_cast<std::size_t>(m_fragment[static_cast<std::size_t>(t)])] += signed_tet_volume(node(0), node(1), node(2), node(3));
  }
  return v;
}

GeometricCutReport CuttableBody::cut(const SweptSurface& surface, const GeometricCutOptions& options) {
  if (!(options.snap_tolerance > 0.0 && options.snap_tolerance < 0.1))
    throw std::invalid_argument("geometric cut: snap tolerance must be in (0, 0.1)");
  if (!(options.reach > 0.0 && options.reach <= 1.0)) throw std::invalid_argument("geometric cut: reach must be in (0, 1]");
  GeometricCutReport report;
  const Eigen::Index node_count = m_mesh.nodes.rows();
  auto position = [&](int g) { return Eigen::Vector3d(m_mesh.nodes.row(g)); };

  // The surface's triangles, their unit normals, and its bounds.
  const Eigen::Index triangle_count = surface.triangles.rows();
  std::vector<std::array<Eigen::Vector3d, 3>> triangles;
  std::vector<Eigen::Vector3d> normals;
  Eigen::AlignedBox3d surface_box;
  for (Eigen::Index f = 0; f < triangle_count; ++f) {
    std::array<Eigen::Vector3d, 3> tri;
    for (int k = 0; k < 3; ++k) tri[static_cast<std::size_t>(k)] = surface.vertices.row(surface.triangles(f, k)).transpose();
    const Eigen::Vector3d n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    if (!(n.norm() > 0.0) || !n.allFinite()) continue; // a zero-area patch cuts nothing
    for (const auto& v : tri) surface_box.extend(v);
    triangles.push_back(tri);
    normals.push_back(n.normalized());
  }
  if (triangles.empty()) {
    report.fragments = m_fragment_count;
    return report;
  }
  auto nearest = [&](const Eigen::Vector3d& p, double& distance) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t which = 0;
    for (std::size_t f = 0; f < triangles.size(); ++f) {
      const double d2 = (p - closest_point_on_triangle(p, triangles[f][0], triangles[f][1], triangles[f][2])).squaredNorm();
      if (d2 < best) { best = d2; which = f; }
    }
    distance = std::sqrt(best);
    return which;
  };

  // Candidates: tetrahedra whose box, grown by its own size, meets the surface's box.
  std::vector<int> candidates;
  double edge_sum = 0.0;
  for (Eigen::Index t = 0; t < m_mesh.tets.rows(); ++t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 4; ++k) box.extend(position(m_mesh.tets(t, k)));
    const double size = box.sizes().maxCoeff();
    box.extend(box.min() - Eigen::Vector3d::Constant(size));
    box.extend(box.max() + Eigen::Vector3d::Constant(size));
    if (!box.intersects(surface_box)) continue;
    candidates.push_back(static_cast<int>(t));
    for (const auto& e : tet_edge) edge_sum += (position(m_mesh.tets(t, e[0])) - position(m_mesh.tets(t, e[1]))).norm();
  }
  if (candidates.empty()) {
    report.fragments = m_fragment_count;
    return report;
  }
  const double h = edge_sum / (6.0 * static_cast<double>(candidates.size()));
  const double snap = options.snap_tolerance * h;

  // Signed distance φ of each candidate node: to the plane of its nearest patch; side +1/-1, or
  // 0 on the surface (within the snap tolerance of it).
  std::unordered_map<int, int> side;
  std::unordered_map<int, double> phi;
  for (int t : candidates)
    for (int k = 0; k < 4; ++k) {
      const int g = m_mesh.tets(t, k);
      if (side.count(g)) continue;
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

  // Cross points on edges whose ends lie on opposite sides: t = φ_a / (φ_a - φ_b).
  std::unordered_map<std::uint64_t, EdgeCross> cross;
  auto signs_of = [&](int t, std::array<int, 4>& s) {
    for (int k = 0; k < 4; ++k) s[static_cast<std::size_t>(k)] = side[m_mesh.tets(t, k)];
  };
  std::vector<char> mixed(candidates.size(), 0), divided(candidates.size(), 0);
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    std::array<int, 4> s;
    signs_of(candidates[c], s);
    for (const auto& e : tet_edge) {
      if (s[static_cast<std::size_t>(e[0])] * s[static_cast<std::size_t>(e[1])] >= 0) continue;
      mixed[c] = 1;
      int a = m_mesh.tets(candidates[c], e[0]), b = m_mesh.tets(candidates[c], e[1]);
      if (a > b) std::swap(a, b);
      const std::uint64_t key = edge_key(a, b);
      if (cross.count(key)) continue;
      EdgeCross x;
      x.t = phi[a] / (phi[a] - phi[b]);
      const double length = (position(b) - position(a)).norm();
      const Eigen::Vector3d point = (1.0 - x.t) * position(a) + x.t * position(b);
      double distance = 0.0;
      nearest(point, distance);
      x.valid = distance <= options.reach * length && x.t * length >= snap && (1.0 - x.t) * length >= snap;
      cross[key] = x;
    }
  }
  // A tetrahedron is divided when all its crossing edges have valid cross points; edges of a
  // crossed tetrahedron left whole lose theirs (repeat until nothing changes).
  auto crossing_edges_valid = [&](std::size_t c, bool invalidate) {
    std::array<int, 4> s;
    signs_of(candidates[c], s);
    bool all = true, changed = false;
    for (const auto& e : tet_edge) {
      if (s[static_cast<std::size_t>(e[0])] * s[static_cast<std::size_t>(e[1])] >= 0) continue;
      EdgeCross& x = cross[edge_key(m_mesh.tets(candidates[c], e[0]), m_mesh.tets(candidates[c], e[1]))];
      if (!x.valid) all = false;
      else if (invalidate) { x.valid = false; changed = true; }
    }
    return invalidate ? changed : all;
  };
  for (std::size_t c = 0; c < candidates.size(); ++c) divided[c] = mixed[c] && crossing_edges_valid(c, false);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      if (!mixed[c]) continue;
      if (divided[c] && !crossing_edges_valid(c, false)) { divided[c] = 0; changed = true; }
      if (!divided[c] && crossing_edges_valid(c, true)) changed = true;
    }
  }

  // Which side(s) each candidate lies on; nodes on the surface get a second copy when every
  // tetrahedron around them is divided or on one side, and both sides meet there.
  std::unordered_map<int, std::array<bool, 3>> around; // zero node -> {whole, has plus, has minus}
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    std::array<int, 4> s;
    signs_of(candidates[c], s);
    bool plus = false, minus = false;
    for (int v : s) { plus = plus || v > 0; minus = minus || v < 0; }
    for (int k = 0; k < 4; ++k) {
      if (s[static_cast<std::size_t>(k)] != 0) continue;
      auto [it, fresh] = around.try_emplace(m_mesh.tets(candidates[c], k), std::array<bool, 3>{true, false, false});
      (void)fresh;
      if (mixed[c] && !divided[c]) it->second[0] = false;
      it->second[1] = it->second[1] || plus;
      it->second[2] = it->second[2] || minus;
    }
  }
  std::vector<Eigen::Vector3d> added;
  auto add_node = [&](const Eigen::Vector3d& p) {
    added.push_back(p);
    ++report.new_nodes;
    return static_cast<int>(node_count + static_cast<Eigen::Index>(added.size()) - 1);
  };
  std::unordered_map<int, int> minus_copy;
  for (const auto& [g, a] : around)
    if (a[0] && a[1] && a[2]) minus_copy[g] = add_node(position(g));
  for (auto& [key, x] : cross) {
    if (!x.valid) continue;
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    const Eigen::Vector3d p = (1.0 - x.t) * position(a) + x.t * position(b);
    x.plus = add_node(p);
    x.minus = add_node(p);
  }
  auto node_on = [&](int g, int s) {
    if (s < 0) {
      const auto it = minus_copy.find(g);
      if (it != minus_copy.end()) return it->second;
    }
    return g;
  };
  auto cross_on = [&](int a, int b, int s) {
    const EdgeCross& x = cross.at(edge_key(a, b));
    return s > 0 ? x.plus : x.minus;
  };
  m_mesh.nodes.conservativeResize(node_count + static_cast<Eigen::Index>(added.size()), 3);
  for (std::size_t i = 0; i < added.size(); ++i) m_mesh.nodes.row(node_count + static_cast<Eigen::Index>(i)) = added[i].transpose();

  // Divide (Fig. 8) and re-tetrahedralise; re-point whole tetrahedra at their side's node copies.
  std::vector<std::array<int, 4>> appended;
  std::vector<int> appended_parent;
  std::vector<int> changed_slots;
  report.min_volume_ratio = 1.0;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const int t = candidates[c];
    std::array<int, 4> s, n;
    signs_of(t, s);
    for (int k = 0; k < 4; ++k) n[static_cast<std::size_t>(k)] = m_mesh.tets(t, k);
    if (!divided[c]) {
      int tet_side = 0;
      for (int v : s) if (v != 0) tet_side = v;
      bool moved = false;
      for (int k = 0; k < 4; ++k) {
        const int g = node_on(n[static_cast<std::size_t>(k)], tet_side);
        if (g != n[static_cast<std::size_t>(k)]) { m_mesh.tets(t, k) = g; moved = true; }
      }
      if (moved) changed_slots.push_back(t);
      continue;
    }
    ++report.cut_tets;
    const double parent_volume = signed_tet_volume(position(n[0]), position(n[1]), position(n[2]), position(n[3]));
    std::vector<std::array<int, 4>> parts;
    for (int piece_side : {1, -1}) {
      std::vector<std::vector<int>> faces;
      std::vector<std::pair<int, int>> segments; // on the cut surface
      for (const auto& f : tet_face) {
        std::vector<int> polygon, on_surface;
        for (int i = 0; i < 3; ++i) {
          const int a = f[i], b = f[(i + 1) % 3];
          const int sa = s[static_cast<std::size_t>(a)], sb = s[static_cast<std::size_t>(b)];
          if (sa * piece_side >= 0) {
            polygon.push_back(node_on(n[static_cast<std::size_t>(a)], piece_side));
            if (sa == 0) on_surface.push_back(polygon.back());
          }
          if (sa * sb < 0) {
            polygon.push_back(cross_on(n[static_cast<std::size_t>(a)], n[static_cast<std::size_t>(b)], piece_side));
            on_surface.push_back(polygon.back());
          }
        }
        if (on_surface.size() == 2) segments.emplace_back(on_surface[0], on_surface[1]);
        if (polygon.size() >= 3 && on_surface.size() < polygon.size()) faces.push_back(polygon);
      }
      // The cut face: chain the on-surface segments into one polygon.
      if (segments.size() >= 3) {
        std::vector<int> polygon{segments[0].first, segments[0].second};
        std::vector<char> used(segments.size(), 0);
        used[0] = 1;
        for (std::size_t step = 1; step < segments.size(); ++step)
          for (std::size_t i = 0; i < segments.size(); ++i) {
            if (used[i]) continue;
            const int last = polygon.back();
            if (segments[i].first == last || segments[i].second == last) {
              const int next = segments[i].first == last ? segments[i].second : segments[i].first;
              used[i] = 1;
              if (next != polygon.front()) polygon.push_back(next);
              break;
            }
          }
        if (polygon.size() >= 3) faces.push_back(polygon);
      }
      int apex = std::numeric_limits<int>::max();
      for (const auto& f : faces) for (int g : f) apex = std::min(apex, g);
      for (auto f : faces) {
        if (std::find(f.begin(), f.end(), apex) != f.end()) continue;
        std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
        for (std::size_t i = 1; i + 1 < f.size(); ++i) {
          std::array<int, 4> tet{apex, f[0], f[i], f[i + 1]};
          double v = signed_tet_volume(position(tet[0]), position(tet[1]), position(tet[2]), position(tet[3]));
          if (v < 0.0) { std::swap(tet[2], tet[3]); v = -v; }
          report.min_volume_ratio = std::min(report.min_volume_ratio, v / parent_volume);
          parts.push_back(tet);
        }
      }
    }
    for (int k = 0; k < 4; ++k) m_mesh.tets(t, k) = parts[0][static_cast<std::size_t>(k)];
    changed_slots.push_back(t);
    for (std::size_t i = 1; i < parts.size(); ++i) {
      appended.push_back(parts[i]);
      appended_parent.push_back(t);
    }
  }
  const Eigen::Index old_count = m_mesh.tets.rows();
  m_mesh.tets.conservativeResize(old_count + static_cast<Eigen::Index>(appended.size()), 4);
  m_adjacency.conservativeResize(m_mesh.tets.rows(), 4);
  for (std::size_t i = 0; i < appended.size(); ++i) {
    const Eigen::Index row = old_count + static_cast<Eigen::Index>(i);
    for (int k = 0; k < 4; ++k) m_mesh.tets(row, k) = appended[i][static_cast<std::size_t>(k)];
    m_adjacency.row(row).setConstant(-1);
  }
  report.new_tets = static_cast<int>(appended.size());
  for (VolumeGroup& group : m_mesh.volume_groups)
    for (std::size_t i = 0; i < appended.size(); ++i)
      if (std::binary_search(group.tets.begin(), group.tets.end(), appended_parent[i]))
        group.tets.push_back(static_cast<int>(old_count + static_cast<Eigen::Index>(i)));

  // Neighbour relation, updated locally: the changed and new tetrahedra and their old neighbours.
  std::unordered_set<int> changed(changed_slots.begin(), changed_slots.end());
  std::vector<int> affected = changed_slots;
  for (Eigen::Index r = old_count; r < m_mesh.tets.rows(); ++r) affected.push_back(static_cast<int>(r));
  std::vector<int> neighbours;
  for (int t : changed_slots)
    for (int k = 0; k < 4; ++k) {
      const int u = m_adjacency(t, k);
      if (u >= 0 && !changed.count(u)) neighbours.push_back(u);
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
  for (int t : affected)
    for (int k = 0; k < 4; ++k) m_adjacency(t, k) = across(t, k);
  for (int t : neighbours)
    for (int k = 0; k < 4; ++k)
      if (const int u = m_adjacency(t, k); u >= 0 && changed.count(u)) m_adjacency(t, k) = across(t, k);

  label_fragments();
  report.fragments = m_fragment_count;
  return report;
}

} // namespace kerf

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

/// The swept surface as the cut reads it: its triangles, their unit normals, and its bounds.
struct SurfacePatches {
  std::vector<std::array<Eigen::Vector3d, 3>> triangles;
  std::vector<Eigen::Vector3d> normals;
  Eigen::AlignedBox3d box;
};

/// The patches of `surface`; a zero-area patch cuts nothing and is left out.
SurfacePatches surface_patches(const SweptSurface& surface) {
  SurfacePatches patches;
  for (Eigen::Index f = 0; f < surface.triangles.rows(); ++f) {
    std::array<Eigen::Vector3d, 3> tri;
    for (int k = 0; k < 3; ++k) {
      const int v = surface.triangles(f, k);
      if (v < 0 || v >= surface.vertices.rows()) throw std::invalid_argument("geometric cut: surface triangle " + std::to_string(f) + " names a missing vertex");
      tri[static_cast<std::size_t>(k)] = surface.vertices.row(v).transpose();
    }
    const Eigen::Vector3d n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    if (!(n.norm() > 0.0) || !n.allFinite()) continue; // a zero-area patch cuts nothing
    for (const auto& v : tri) patches.box.extend(v);
    patches.triangles.push_back(tri);
    patches.normals.push_back(n.normalized());
  }
  return patches;
}

/// The patch nearest to p; `distance` gets the distance to it.
std::size_t nearest_patch(const SurfacePatches& patches, const Eigen::Vector3d& p, double& distance) {
  const auto& triangles = patches.triangles;
  double best = std::numeric_limits<double>::infinity();
  std::size_t which = 0;
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const double d2 = (p - closest_point_on_triangle(p, triangles[f][0], triangles[f][1], triangles[f][2]).point).squaredNorm();
    if (d2 < best) { best = d2; which = f; }
  }
  distance = std::sqrt(best);
  return which;
}

/// The body during one cut: the mesh as it was, with the nodes and tetrahedra the cut makes kept
/// beside it until they are written back; the tetrahedra around each node near the surface (kept
/// up to date while dividing) and each such node's side of the surface; the original
/// tetrahedra the cut re-points.
struct CutMesh {
  explicit CutMesh(TetMesh& m)
      : mesh(m), node_count(m.nodes.rows()), tet_count(m.tets.rows()), is_changed(static_cast<std::size_t>(m.tets.rows()), 0) {}

  Eigen::Vector3d position(int g) const {
    return g < node_count ? Eigen::Vector3d(mesh.nodes.row(g)) : added_nodes[static_cast<std::size_t>(g - node_count)];
  }
  int& corner(int t, int k) {
    return t < tet_count ? mesh.tets(t, k) : added_tets[static_cast<std::size_t>(t - tet_count)][static_cast<std::size_t>(k)];
  }
  int corner(int t, int k) const {
    return t < tet_count ? mesh.tets(t, k) : added_tets[static_cast<std::size_t>(t - tet_count)][static_cast<std::size_t>(k)];
  }
  double volume_of(int t) const {
    return signed_volume(position(corner(t, 0)), position(corner(t, 1)), position(corner(t, 2)), position(corner(t, 3)));
  }
  /// The original tetrahedron t is (or was divided from).
  int origin_of(int t) const { return t < tet_count ? t : added_origin[static_cast<std::size_t>(t - tet_count)]; }
  void mark_changed(int t) {
    if (t < tet_count && !is_changed[static_cast<std::size_t>(t)]) {
      is_changed[static_cast<std::size_t>(t)] = 1;
      changed_old.push_back(t);
    }
  }
  /// Appends a node at p, on the surface; returns its index.
  int add_node(const Eigen::Vector3d& p) {
    const int g = static_cast<int>(node_count + static_cast<Eigen::Index>(added_nodes.size()));
    added_nodes.push_back(p);
    side[g] = 0;
    return g;
  }
  /// Side of tetrahedron t: +1 / -1 on one side, 0 with no node off the surface, 2 across.
  int tet_side(int t) const {
    bool plus = false, minus = false;
    for (int k = 0; k < 4; ++k) {
      const auto it = side.find(corner(t, k));
      const int s = it == side.end() ? 0 : it->second;
      plus = plus || s > 0;
      minus = minus || s < 0;
    }
    return plus && minus ? 2 : plus ? 1 : minus ? -1 : 0;
  }
  bool on_surface(int g) const {
    const auto it = side.find(g);
    return it != side.end() && it->second == 0;
  }
  /// The original tetrahedra the cut re-pointed, then the ones it added: every part it made.
  std::vector<int> parts() const {
    auto all = changed_old;
    for (std::size_t i = 0; i < added_tets.size(); ++i) all.push_back(static_cast<int>(tet_count + static_cast<Eigen::Index>(i)));
    return all;
  }

  TetMesh& mesh;
  const Eigen::Index node_count, tet_count; ///< of the mesh before this cut
  std::vector<Eigen::Vector3d> added_nodes;
  std::vector<std::array<int, 4>> added_tets;
  std::vector<int> added_origin; ///< the original tetrahedron each added one was divided from
  std::unordered_map<int, std::vector<int>> around; ///< tetrahedra around each node near the surface
  std::unordered_map<int, int> side;                ///< +1 / -1, or 0 on the surface
  std::vector<char> is_changed;                     ///< per original tetrahedron: re-pointed
  std::vector<int> changed_old;                     ///< the re-pointed original tetrahedra, in order
  std::unordered_set<int> divided_origin;           ///< original tetrahedra divided
};

/// Candidates: tetrahedra whose box, grown by its own size, meets the surface's box. Every
/// tetrahedron holding a cross point (within reach <= 1/4 of an edge length of the surface) or a
/// node on the surface is among them, since its largest box side is at least edge / sqrt(3).
/// `h` gets the candidates' mean edge length.
std::vector<int> candidate_tets(const CutMesh& body, const Eigen::AlignedBox3d& surface_box, double& h) {
  const TetMesh& mesh = body.mesh;
  std::vector<int> candidates;
  double edge_sum = 0.0;
  for (Eigen::Index t = 0; t < body.tet_count; ++t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 4; ++k) box.extend(body.position(mesh.tets(t, k)));
    const double size = box.sizes().maxCoeff();
    box.extend(box.min() - Eigen::Vector3d::Constant(size));
    box.extend(box.max() + Eigen::Vector3d::Constant(size));
    if (!box.intersects(surface_box)) continue;
    candidates.push_back(static_cast<int>(t));
    for (const auto& e : tet_edge) edge_sum += (body.position(mesh.tets(t, e[0])) - body.position(mesh.tets(t, e[1]))).norm();
  }
  if (!candidates.empty()) h = edge_sum / (6.0 * static_cast<double>(candidates.size()));
  return candidates;
}

/// Signed distance φ of each candidate node to the plane of its nearest patch; its side +1/-1,
/// or 0 on the surface (within the snap tolerance of the surface itself) into body.side.
/// `snapped` counts the nodes put on the surface.
std::unordered_map<int, double> signed_distances(CutMesh& body, const SurfacePatches& patches, double snap, int& snapped) {
  std::unordered_map<int, double> phi;
  for (const auto& [g, unused] : body.around) {
    (void)unused;
    const Eigen::Vector3d p = body.position(g);
    double distance = 0.0;
    const std::size_t f = nearest_patch(patches, p, distance);
    const double value = patches.normals[f].dot(p - patches.triangles[f][0]);
    phi[g] = value;
    if (distance < snap) {
      body.side[g] = 0;
      ++snapped;
    } else {
      body.side[g] = value < 0.0 ? -1 : 1;
    }
  }
  return phi;
}

struct CrossPoint { int a, b; double t; };

/// Cross points: on each edge whose ends lie on opposite sides, t = φ_a / (φ_a - φ_b) from the
/// lower-numbered end a; kept when the point lies on the swept surface itself (within reach x
/// edge length: the surface is approximated by its linear interpolant) and at least the snap
/// distance from both ends (no part thinner than that).
std::vector<CrossPoint> cross_points(CutMesh& body, const std::vector<int>& candidates, const std::unordered_map<int, double>& phi,
                                     const SurfacePatches& patches, double snap, double reach) {
  std::vector<CrossPoint> crosses;
  std::unordered_set<std::uint64_t> seen;
  for (int t : candidates)
    for (const auto& e : tet_edge) {
      int a = body.mesh.tets(t, e[0]), b = body.mesh.tets(t, e[1]);
      if (body.side[a] * body.side[b] >= 0) continue;
      if (a > b) std::swap(a, b);
      if (!seen.insert(edge_key(a, b)).second) continue;
      const double x = phi.at(a) / (phi.at(a) - phi.at(b));
      const double length = (body.position(b) - body.position(a)).norm();
      const Eigen::Vector3d point = (1.0 - x) * body.position(a) + x * body.position(b);
      double distance = 0.0;
      nearest_patch(patches, point, distance);
      if (distance <= reach * length && x * length >= snap && (1.0 - x) * length >= snap) crosses.push_back({a, b, x});
    }
  return crosses;
}

/// Divide (Fig. 8) by bisecting every tetrahedron around each cut edge at its cross point p:
/// T -> T[a := p] and T[b := p]. Replacing one corner by a point of an incident edge scales the
/// signed volume by that point's barycentric weight, so both parts keep T's orientation and
/// their volumes add up to T's: V(T[a := p]) = (1 - t) V(T), V(T[b := p]) = t V(T). The whole
/// ring of the edge is divided alike, so the mesh stays conforming with no rule to propagate.
/// Once every crossing edge of a tetrahedron is bisected no part crosses the surface: the parts
/// on either side are Fig. 8's (a tetrahedron and a prism, two prisms, or with nodes on the
/// surface a tetrahedron and a pyramid, two tetrahedra), already tetrahedralised. A tetrahedron
/// where the cut ends keeps its uncut crossing edges whole: it is divided only at the cross
/// points the surface reaches and stays in one piece (see open_crack).
/// `new_nodes` counts the cross points added.
void divide_at_cross_points(CutMesh& body, const std::vector<CrossPoint>& crosses, int& new_nodes) {
  auto erase_from = [](std::vector<int>& list, int t) { list.erase(std::find(list.begin(), list.end(), t)); };
  for (const CrossPoint& x : crosses) {
    const int p = body.add_node((1.0 - x.t) * body.position(x.a) + x.t * body.position(x.b));
    ++new_nodes;
    std::vector<int> ring;
    for (int t : body.around[x.a])
      for (int k = 0; k < 4; ++k)
        if (body.corner(t, k) == x.b) ring.push_back(t);
    std::vector<int>& around_p = body.around[p];
    for (int t : ring) {
      std::array<int, 4> second;
      for (int k = 0; k < 4; ++k) second[static_cast<std::size_t>(k)] = body.corner(t, k) == x.b ? p : body.corner(t, k);
      for (int k = 0; k < 4; ++k)
        if (body.corner(t, k) == x.a) body.corner(t, k) = p;
      const int u = static_cast<int>(body.tet_count + static_cast<Eigen::Index>(body.added_tets.size()));
      body.added_tets.push_back(second);
      body.added_origin.push_back(body.origin_of(t));
      body.divided_origin.insert(body.origin_of(t));
      body.mark_changed(t);
      erase_from(body.around[x.a], t);
      for (int g : second) body.around[g].push_back(u); // a, p and the two others
      around_p.push_back(t);
    }
  }
}

/// Union-find over the positions of a node's ring, with path halving.
struct RingGroups {
  explicit RingGroups(std::size_t n) : parent(n) {
    for (std::size_t i = 0; i < n; ++i) parent[i] = static_cast<int>(i);
  }
  int find(int i) {
    while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    return i;
  }
  void join(int i, int j) { parent[static_cast<std::size_t>(find(i))] = find(j); }
  std::vector<int> parent;
};

/// The tetrahedra of `ring` (around surface node z) joined through the faces at z that are not
/// cut through: a face whose three corners lie on the surface between tetrahedra on opposite
/// sides is cut through.
RingGroups join_through_uncut_faces(const CutMesh& body, int z, const std::vector<int>& ring) {
  RingGroups groups(ring.size());
  std::unordered_map<FaceKey, int, FaceKeyHash> first_with;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const int t = ring[i];
    for (const auto& f : tet_face) {
      const int a = body.corner(t, f[0]), b = body.corner(t, f[1]), c = body.corner(t, f[2]);
      if (a != z && b != z && c != z) continue;
      const auto [it, fresh] = first_with.try_emplace(face_key(a, b, c), static_cast<int>(i));
      if (fresh) continue;
      const int j = it->second;
      const int si = body.tet_side(t), sj = body.tet_side(ring[static_cast<std::size_t>(j)]);
      const bool cut_through = body.on_surface(a) && body.on_surface(b) && body.on_surface(c) && si * sj == -1;
      if (!cut_through) groups.join(static_cast<int>(i), j);
    }
  }
  return groups;
}

/// Opening: around each node on the surface, the tetrahedra joined through faces that are not
/// cut through form connected groups; each group beyond the first gets its own copy of the node.
/// Where the cut ends inside the body, the tetrahedra left crossing the surface join the two
/// sides around the front's nodes, so those stay shared: the crack opens behind the front and
/// closes at it (progressive splitting). `new_nodes` counts the copies.
void open_crack(CutMesh& body, int& new_nodes) {
  auto erase_from = [](std::vector<int>& list, int t) { list.erase(std::find(list.begin(), list.end(), t)); };
  std::vector<int> surface_nodes;
  for (const auto& [g, s] : body.side)
    if (s == 0) surface_nodes.push_back(g);
  std::sort(surface_nodes.begin(), surface_nodes.end());
  for (int z : surface_nodes) {
    std::vector<int> ring = body.around[z];
    if (ring.size() < 2) continue;
    std::sort(ring.begin(), ring.end());
    RingGroups groups = join_through_uncut_faces(body, z, ring);
    std::unordered_map<int, int> copy_of_group;
    const int kept = groups.find(0);
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const int group = groups.find(static_cast<int>(i));
      if (group == kept) continue;
      auto [it, fresh] = copy_of_group.try_emplace(group, -1);
      if (fresh) {
        it->second = body.add_node(body.position(z));
        ++new_nodes;
      }
      const int t = ring[i];
      for (int k = 0; k < 4; ++k)
        if (body.corner(t, k) == z) body.corner(t, k) = it->second;
      body.mark_changed(t);
      erase_from(body.around[z], t);
      body.around[it->second].push_back(t);
    }
  }
}

/// Smallest part against its original tetrahedron (1 when none is smaller).
double smallest_volume_ratio(const CutMesh& body, const std::vector<int>& parts) {
  std::unordered_map<int, double> origin_volume;
  for (int t : body.divided_origin) origin_volume[t] = 0.0;
  for (int t : parts)
    if (const auto it = origin_volume.find(body.origin_of(t)); it != origin_volume.end()) it->second += body.volume_of(t);
  double smallest = 1.0;
  for (int t : parts)
    if (const auto it = origin_volume.find(body.origin_of(t)); it != origin_volume.end())
      smallest = std::min(smallest, body.volume_of(t) / it->second);
  return smallest;
}

/// Write back: nodes and tetrahedra appended (their adjacency rows unset), volume groups extended
/// by the origin's parts.
void append_parts(CutMesh& body, Eigen::MatrixXi& adjacency) {
  TetMesh& mesh = body.mesh;
  const Eigen::Index node_count = body.node_count, tet_count = body.tet_count;
  mesh.nodes.conservativeResize(node_count + static_cast<Eigen::Index>(body.added_nodes.size()), 3);
  for (std::size_t i = 0; i < body.added_nodes.size(); ++i) mesh.nodes.row(node_count + static_cast<Eigen::Index>(i)) = body.added_nodes[i].transpose();
  mesh.tets.conservativeResize(tet_count + static_cast<Eigen::Index>(body.added_tets.size()), 4);
  adjacency.conservativeResize(mesh.tets.rows(), 4);
  for (std::size_t i = 0; i < body.added_tets.size(); ++i) {
    const Eigen::Index row = tet_count + static_cast<Eigen::Index>(i);
    for (int k = 0; k < 4; ++k) mesh.tets(row, k) = body.added_tets[i][static_cast<std::size_t>(k)];
    adjacency.row(row).setConstant(-1);
  }
  for (VolumeGroup& group : mesh.volume_groups)
    for (std::size_t i = 0; i < body.added_tets.size(); ++i)
      if (std::binary_search(group.tets.begin(), group.tets.end(), body.added_origin[i])) // stays sorted: appended rows grow
        group.tets.push_back(static_cast<int>(tet_count + static_cast<Eigen::Index>(i)));
}

/// Neighbour relation, updated locally: the parts (changed and new tetrahedra, `parts`) and the
/// old neighbours of the changed ones, matched through their faces.
void update_adjacency(const CutMesh& body, const std::vector<int>& parts, Eigen::MatrixXi& adjacency) {
  const TetMesh& mesh = body.mesh;
  const std::vector<int>& affected = parts;
  std::vector<int> neighbours;
  for (int t : body.changed_old)
    for (int k = 0; k < 4; ++k) {
      const int u = adjacency(t, k);
      if (u >= 0 && !body.is_changed[static_cast<std::size_t>(u)]) neighbours.push_back(u);
    }
  std::sort(neighbours.begin(), neighbours.end());
  neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
  std::unordered_map<FaceKey, std::array<int, 2>, FaceKeyHash> faces;
  auto key_of = [&](int t, int k) {
    return face_key(mesh.tets(t, tet_face[k][0]), mesh.tets(t, tet_face[k][1]), mesh.tets(t, tet_face[k][2]));
  };
  const std::vector<int>* lists[] = {&affected, &neighbours};
  for (const std::vector<int>* list : lists)
    for (int t : *list)
      for (int k = 0; k < 4; ++k) {
        auto [it, fresh] = faces.try_emplace(key_of(t, k), std::array<int, 2>{t, -1});
        if (!fresh) it->second[1] = t;
      }
  auto across = [&](int t, int k) {
    const std::array<int, 2>& pair = faces.at(key_of(t, k));
    return pair[0] == t ? pair[1] : pair[0];
  };
  auto changed = [&](int u) { return u >= body.tet_count || body.is_changed[static_cast<std::size_t>(u)]; };
  for (int t : affected)
    for (int k = 0; k < 4; ++k) adjacency(t, k) = across(t, k);
  for (int t : neighbours)
    for (int k = 0; k < 4; ++k)
      if (const int u = adjacency(t, k); u >= 0 && changed(u)) adjacency(t, k) = across(t, k);
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

  const SurfacePatches patches = surface_patches(surface);
  if (patches.triangles.empty()) return report;
  // Nodes and tetrahedra made by this cut live beside the mesh until it is written back.
  CutMesh body(m_mesh);
  double h = 0.0;
  const std::vector<int> candidates = candidate_tets(body, patches.box, h);
  if (candidates.empty()) return report;
  const double snap = options.snap_tolerance * h;
  for (int t : candidates)
    for (int k = 0; k < 4; ++k) body.around[m_mesh.tets(t, k)].push_back(t);

  const std::unordered_map<int, double> phi = signed_distances(body, patches, snap, report.snapped_nodes);
  const std::vector<CrossPoint> crosses = cross_points(body, candidates, phi, patches, snap, options.reach);
  divide_at_cross_points(body, crosses, report.new_nodes);
  report.cut_tets = static_cast<int>(body.divided_origin.size());
  report.new_tets = static_cast<int>(body.added_tets.size());
  open_crack(body, report.new_nodes);

  const std::vector<int> parts = body.parts();
  report.min_volume_ratio = smallest_volume_ratio(body, parts);
  append_parts(body, m_adjacency);
  update_adjacency(body, parts, m_adjacency);
  label_fragments();
  report.fragments = m_fragment_count;
  return report;
}

} // namespace kerf

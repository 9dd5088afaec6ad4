#include "meshes/crack_split.hpp"

#include "meshes/mesh_error.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <set>
#include <string>

namespace kerf {

namespace {

using FaceKey = std::array<int, 3>;

FaceKey sorted_key(int a, int b, int c) {
  FaceKey key{a, b, c};
  std::sort(key.begin(), key.end());
  return key;
}

/// Union–find over tetrahedra (path halving).
struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      auto& p = parent[static_cast<std::size_t>(x)];
      p = parent[static_cast<std::size_t>(p)];
      x = p;
    }
    return x;
  }
  void join(int a, int b) { parent[static_cast<std::size_t>(find(a))] = find(b); }
};

} // namespace

Eigen::VectorXi face_connected_components(const Eigen::MatrixXi& tets) {
  const Eigen::MatrixXi adjacency = tet_face_adjacency(tets);
  Eigen::VectorXi component = Eigen::VectorXi::Constant(tets.rows(), -1);
  std::vector<int> stack;
  int count = 0;
  for (Eigen::Index seed = 0; seed < tets.rows(); ++seed) {
    if (component(seed) >= 0) continue;
    component(seed) = count;
    stack.assign(1, static_cast<int>(seed));
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      for (int k = 0; k < 4; ++k) {
        const int u = adjacency(t, k);
        if (u >= 0 && component(u) < 0) {
          component(u) = count;
          stack.push_back(u);
        }
      }
    }
    ++count;
  }
  return component;
}

namespace {

/// The tetrahedra around each node, in compressed rows: star[start[v] .. start[v + 1]).
struct NodeStars {
  std::vector<int> start, star;
  explicit NodeStars(const TetMesh& mesh) : start(static_cast<std::size_t>(mesh.nodes.rows()) + 1, 0) {
    const Eigen::Index n_tets = mesh.tets.rows();
    for (Eigen::Index t = 0; t < n_tets; ++t)
      for (int j = 0; j < 4; ++j) ++start[static_cast<std::size_t>(mesh.tets(t, j)) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    star.resize(static_cast<std::size_t>(start.back()));
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (Eigen::Index t = 0; t < n_tets; ++t)
      for (int j = 0; j < 4; ++j) star[static_cast<std::size_t>(fill[static_cast<std::size_t>(mesh.tets(t, j))]++)] = static_cast<int>(t);
  }
  [[nodiscard]] int begin(int v) const { return start[static_cast<std::size_t>(v)]; }
  [[nodiscard]] int end(int v) const { return start[static_cast<std::size_t>(v) + 1]; }
  [[nodiscard]] int tet(int s) const { return star[static_cast<std::size_t>(s)]; }
};

/// Whether tetrahedron t has nodes b and c (it is in a's star: then it has the face a b c).
bool has_both(const TetMesh& mesh, int t, int b, int c) {
  int found = 0;
  for (int j = 0; j < 4; ++j) found += (mesh.tets(t, j) == b) + (mesh.tets(t, j) == c);
  return found == 2;
}

/// The two tetrahedra on either side of a crack face.
struct FaceSides {
  int plus_tet = -1;
  int minus_tet = -1;
};

/// Every crack triangle must be an interior face: the two tetrahedra sharing it, checked. The +
/// tetrahedron is the one whose fourth vertex lies on the side the triangle's normal
/// (b − a) × (c − a) points into.
std::vector<FaceSides> crack_face_sides(const TetMesh& mesh, const Eigen::MatrixXi& triangles, const NodeStars& stars,
                                        const std::string& name) {
  const Eigen::Index n_nodes = mesh.nodes.rows();
  std::vector<FaceSides> sides(static_cast<std::size_t>(triangles.rows()));
  for (Eigen::Index f = 0; f < triangles.rows(); ++f) {
    const int a = triangles(f, 0), b = triangles(f, 1), c = triangles(f, 2);
    if (std::min({a, b, c}) < 0 || std::max({a, b, c}) >= n_nodes)
      throw MeshError("crack split: surface '" + name + "' triangle " + std::to_string(f) + " has a node index outside the mesh");
    std::vector<int> sharing;
    for (int s = stars.begin(a); s < stars.end(a); ++s)
      if (has_both(mesh, stars.tet(s), b, c)) sharing.push_back(stars.tet(s));
    if (sharing.size() != 2)
      throw MeshError("crack split: surface '" + name + "' triangle " + std::to_string(f) + " (nodes " + std::to_string(a) + ", " +
                      std::to_string(b) + ", " + std::to_string(c) + ") is shared by " + std::to_string(sharing.size()) +
                      " tetrahedra; expected an interior face shared by exactly 2");
    const Eigen::Vector3d pa = mesh.nodes.row(a).transpose();
    const Eigen::Vector3d pb = mesh.nodes.row(b).transpose();
    const Eigen::Vector3d pc = mesh.nodes.row(c).transpose();
    const Eigen::Vector3d normal = (pb - pa).cross(pc - pa);
    auto opposite_side = [&](int t) {
      for (int j = 0; j < 4; ++j) {
        const int v = mesh.tets(t, j);
        if (v != a && v != b && v != c) return normal.dot(Eigen::Vector3d(mesh.nodes.row(v).transpose()) - pa);
      }
      return 0.0;
    };
    const double s0 = opposite_side(sharing[0]), s1 = opposite_side(sharing[1]);
    if (!(s0 * s1 < 0.0))
      throw MeshError("crack split: surface '" + name + "' triangle " + std::to_string(f) +
                      ": the two tetrahedra sharing it do not lie on opposite sides (degenerate or folded mesh)");
    sides[static_cast<std::size_t>(f)] = s0 > 0.0 ? FaceSides{sharing[0], sharing[1]} : FaceSides{sharing[1], sharing[0]};
  }
  return sides;
}

/// For each node on the crack, its star grouped into the sets connected through non-crack faces:
/// the first set keeps the node, every further set gets a new copy (split.original_node grows,
/// split.mesh.tets takes the copies).
void copy_crack_nodes(const TetMesh& mesh, const std::set<FaceKey>& crack, const std::vector<char>& on_crack,
                      const NodeStars& stars, CrackSplit& split) {
  const Eigen::MatrixXi adjacency = tet_face_adjacency(mesh.tets);
  DisjointSets sets(static_cast<std::size_t>(mesh.tets.rows()));
  for (Eigen::Index v = 0; v < mesh.nodes.rows(); ++v) {
    if (!on_crack[static_cast<std::size_t>(v)]) continue;
    const int begin = stars.begin(static_cast<int>(v)), end = stars.end(static_cast<int>(v));
    // Local union–find restricted to this star (reset the entries it touches).
    for (int s = begin; s < end; ++s) sets.parent[static_cast<std::size_t>(stars.tet(s))] = stars.tet(s);
    for (int s = begin; s < end; ++s) {
      const int t = stars.tet(s);
      for (int k = 0; k < 4; ++k) {
        if (mesh.tets(t, k) == v) continue; // the face opposite v does not contain v
        const int u = adjacency(t, k);
        if (u < 0) continue;
        FaceKey key{};
        for (int j = 0, m = 0; j < 4; ++j)
          if (j != k) key[static_cast<std::size_t>(m++)] = mesh.tets(t, j);
        std::sort(key.begin(), key.end());
        if (!crack.count(key)) sets.join(t, u);
      }
    }
    std::map<int, int> copy_of_root; // root tetrahedron → node index for that set
    for (int s = begin; s < end; ++s) {
      const int t = stars.tet(s);
      const int root = sets.find(t);
      auto [it, inserted] = copy_of_root.try_emplace(root, -1);
      if (inserted) {
        if (copy_of_root.size() == 1) {
          it->second = static_cast<int>(v);
        } else {
          it->second = static_cast<int>(split.original_node.size());
          split.original_node.push_back(static_cast<int>(v));
        }
      }
      for (int j = 0; j < 4; ++j)
        if (mesh.tets(t, j) == v) split.mesh.tets(t, j) = it->second;
    }
  }
}

/// The node tetrahedron t of the split mesh uses in place of input node v.
int node_in_tet(const TetMesh& mesh, const CrackSplit& split, int t, int v) {
  for (int j = 0; j < 4; ++j)
    if (mesh.tets(t, j) == v) return split.mesh.tets(t, j);
  throw MeshError("crack split: internal error, node " + std::to_string(v) + " not in tetrahedron " + std::to_string(t));
}

/// A surface group other than the crack, on the split mesh: each triangle takes the copies used
/// by a tetrahedron it bounds (every tetrahedron sharing a non-crack face lies in the same set for
/// each of the face's nodes).
SurfaceGroup carried_surface(const TetMesh& mesh, const CrackSplit& split, const SurfaceGroup& other,
                             const std::vector<char>& on_crack, const NodeStars& stars) {
  SurfaceGroup moved{other.name, other.tag, other.triangles};
  for (Eigen::Index f = 0; f < other.triangles.rows(); ++f) {
    const int a = other.triangles(f, 0), b = other.triangles(f, 1), c = other.triangles(f, 2);
    if (!on_crack[static_cast<std::size_t>(a)] && !on_crack[static_cast<std::size_t>(b)] && !on_crack[static_cast<std::size_t>(c)]) continue;
    int owner = -1;
    for (int s = stars.begin(a); s < stars.end(a) && owner < 0; ++s)
      if (has_both(mesh, stars.tet(s), b, c)) owner = stars.tet(s);
    if (owner < 0)
      throw MeshError("crack split: surface '" + other.name + "' triangle " + std::to_string(f) + " is not a face of any tetrahedron");
    for (int j = 0; j < 3; ++j) moved.triangles(f, j) = node_in_tet(mesh, split, owner, other.triangles(f, j));
  }
  return moved;
}

} // namespace

CrackSplit split_along_surface(const TetMesh& mesh, std::string_view surface) {
  const SurfaceGroup* group = mesh.find_surface_group(surface);
  const std::string name(surface);
  if (!group) throw MeshError("crack split: mesh has no surface group '" + name + "'");
  const Eigen::MatrixXi& triangles = group->triangles;
  if (triangles.rows() == 0) throw MeshError("crack split: surface group '" + name + "' is empty");

  // The crack faces, by their sorted node triple; the nodes on them.
  std::set<FaceKey> crack;
  for (Eigen::Index f = 0; f < triangles.rows(); ++f)
    crack.insert(sorted_key(triangles(f, 0), triangles(f, 1), triangles(f, 2)));
  const NodeStars stars(mesh);
  const std::vector<FaceSides> sides = crack_face_sides(mesh, triangles, stars, name);
  std::vector<char> on_crack(static_cast<std::size_t>(mesh.nodes.rows()), 0);
  for (Eigen::Index f = 0; f < triangles.rows(); ++f)
    for (int j = 0; j < 3; ++j) on_crack[static_cast<std::size_t>(triangles(f, j))] = 1;

  CrackSplit split;
  split.mesh.tets = mesh.tets;
  split.original_node.resize(static_cast<std::size_t>(mesh.nodes.rows()));
  std::iota(split.original_node.begin(), split.original_node.end(), 0);
  copy_crack_nodes(mesh, crack, on_crack, stars, split);
  split.mesh.nodes.resize(static_cast<Eigen::Index>(split.original_node.size()), 3);
  for (std::size_t i = 0; i < split.original_node.size(); ++i)
    split.mesh.nodes.row(static_cast<Eigen::Index>(i)) = mesh.nodes.row(split.original_node[i]);
  split.mesh.volume_groups = mesh.volume_groups;

  // The crack's two faces, each with the copies its own tetrahedron uses.
  split.plus_faces.resize(triangles.rows(), 3);
  split.minus_faces.resize(triangles.rows(), 3);
  for (Eigen::Index f = 0; f < triangles.rows(); ++f)
    for (int j = 0; j < 3; ++j) {
      split.plus_faces(f, j) = node_in_tet(mesh, split, sides[static_cast<std::size_t>(f)].plus_tet, triangles(f, j));
      split.minus_faces(f, j) = node_in_tet(mesh, split, sides[static_cast<std::size_t>(f)].minus_tet, triangles(f, j));
    }
  for (const SurfaceGroup& other : mesh.surface_groups) {
    if (other.name == name) {
      split.mesh.surface_groups.push_back({name + "+", other.tag, split.plus_faces});
      split.mesh.surface_groups.push_back({name + "-", other.tag, split.minus_faces});
    } else {
      split.mesh.surface_groups.push_back(carried_surface(mesh, split, other, on_crack, stars));
    }
  }
  return split;
}

} // namespace kerf

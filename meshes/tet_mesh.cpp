#include "meshes/tet_mesh.hpp"

#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <string>
#include <tuple>

namespace kerf {

namespace {

/// Local vertices of the face opposite local vertex k, ordered so that (b - a) x (c - a) points
/// out of a positively oriented tetrahedron: (1,2,3), (0,3,2), (0,1,3), (0,2,1).
constexpr std::array<std::array<int, 3>, 4> k_outward_faces{{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

/// One face of one tetrahedron, keyed by its sorted node indices.
struct FaceRecord {
  std::array<int, 3> key;
  int tet;
  int local; ///< local index of the opposite vertex
  friend bool operator<(const FaceRecord& x, const FaceRecord& y) {
    return std::tie(x.key, x.tet, x.local) < std::tie(y.key, y.tet, y.local);
  }
};

/// All 4 #T faces, sorted so that the faces with the same nodes are adjacent.
std::vector<FaceRecord> sorted_faces(const Eigen::MatrixXi& tets) {
  std::vector<FaceRecord> faces;
  faces.reserve(static_cast<std::size_t>(4 * tets.rows()));
  for (Eigen::Index t = 0; t < tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const auto& f = k_outward_faces[static_cast<std::size_t>(k)];
      std::array<int, 3> key{tets(t, f[0]), tets(t, f[1]), tets(t, f[2])};
      std::sort(key.begin(), key.end());
      faces.push_back({key, static_cast<int>(t), k});
    }
  std::sort(faces.begin(), faces.end());
  return faces;
}

const VolumeGroup& require_volume_group(const TetMesh& mesh, std::string_view name) {
  if (const VolumeGroup* group = mesh.find_volume_group(name)) return *group;
  throw MeshError("mesh has no volume group '" + std::string(name) + "'");
}

} // namespace

const VolumeGroup* TetMesh::find_volume_group(std::string_view name) const {
  for (const auto& group : volume_groups)
    if (group.name == name) return &group;
  return nullptr;
}

const SurfaceGroup* TetMesh::find_surface_group(std::string_view name) const {
  for (const auto& group : surface_groups)
    if (group.name == name) return &group;
  return nullptr;
}

Eigen::MatrixXi boundary_faces(const Eigen::MatrixXi& tets) {
  const auto faces = sorted_faces(tets);
  std::vector<std::array<int, 3>> boundary;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1) {
      const auto& f = k_outward_faces[static_cast<std::size_t>(faces[i].local)];
      boundary.push_back({tets(faces[i].tet, f[0]), tets(faces[i].tet, f[1]), tets(faces[i].tet, f[2])});
    }
    i = j;
  }
  Eigen::MatrixXi result(static_cast<Eigen::Index>(boundary.size()), 3);
  for (std::size_t b = 0; b < boundary.size(); ++b)
    for (int j = 0; j < 3; ++j) result(static_cast<Eigen::Index>(b), j) = boundary[b][static_cast<std::size_t>(j)];
  return result;
}

Eigen::MatrixXi tet_face_adjacency(const Eigen::MatrixXi& tets) {
  const auto faces = sorted_faces(tets);
  Eigen::MatrixXi adjacency = Eigen::MatrixXi::Constant(tets.rows(), 4, -1);
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i > 2)
      throw MeshError("tet_face_adjacency: face (" + std::to_string(faces[i].key[0]) + ", " +
                      std::to_string(faces[i].key[1]) + ", " + std::to_string(faces[i].key[2]) + ") is shared by " +
                      std::to_string(j - i) + " tetrahedra (non-manifold mesh)");
    if (j - i == 2) {
      adjacency(faces[i].tet, faces[i].local) = faces[i + 1].tet;
      adjacency(faces[i + 1].tet, faces[i + 1].local) = faces[i].tet;
    }
    i = j;
  }
  return adjacency;
}

double mesh_volume(const TetMesh& mesh) {
  double volume = 0.0;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    volume += signed_volume(mesh.nodes.row(mesh.tets(t, 0)).transpose(), mesh.nodes.row(mesh.tets(t, 1)).transpose(),
                            mesh.nodes.row(mesh.tets(t, 2)).transpose(), mesh.nodes.row(mesh.tets(t, 3)).transpose());
  return volume;
}

double group_volume(const TetMesh& mesh, std::string_view group) {
  double volume = 0.0;
  for (const int t : require_volume_group(mesh, group).tets)
    volume += signed_volume(mesh.nodes.row(mesh.tets(t, 0)).transpose(), mesh.nodes.row(mesh.tets(t, 1)).transpose(),
                            mesh.nodes.row(mesh.tets(t, 2)).transpose(), mesh.nodes.row(mesh.tets(t, 3)).transpose());
  return volume;
}

double surface_group_area(const TetMesh& mesh, std::string_view group) {
  const SurfaceGroup* surface = mesh.find_surface_group(group);
  if (surface == nullptr) throw MeshError("mesh has no surface group '" + std::string(group) + "'");
  double area = 0.0;
  for (Eigen::Index f = 0; f < surface->triangles.rows(); ++f) {
    const Eigen::Vector3d a = mesh.nodes.row(surface->triangles(f, 0)).transpose();
    const Eigen::Vector3d b = mesh.nodes.row(surface->triangles(f, 1)).transpose();
    const Eigen::Vector3d c = mesh.nodes.row(surface->triangles(f, 2)).transpose();
    // Triangle area |(b - a) x (c - a)| / 2.
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

Eigen::VectorXi tet_regions(const TetMesh& mesh, const std::vector<std::string>& region_names) {
  Eigen::VectorXi regions = Eigen::VectorXi::Constant(mesh.tets.rows(), -1);
  // Walk the names backwards so that the first group containing a tetrahedron wins.
  for (auto r = static_cast<int>(region_names.size()) - 1; r >= 0; --r) {
    const VolumeGroup& group = require_volume_group(mesh, region_names[static_cast<std::size_t>(r)]);
    for (const int t : group.tets) regions(t) = r;
  }
  return regions;
}

} // namespace kerf

#pragma once
// TetMesh: the one tetrahedral mesh type shared by the fast models and the reference.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <string_view>
#include <vector>

namespace kerf {

/// A gmsh physical volume: a named set of tetrahedra (e.g. `body`, `layer_upper`).
/// A tetrahedron may belong to several volume groups.
struct VolumeGroup {
  std::string name;
  int tag = -1;          ///< gmsh physical tag
  std::vector<int> tets; ///< indices into TetMesh::tets, ascending
};

/// A gmsh physical surface: a named set of triangles (e.g. `support`, `top`, `cut_plane`).
/// Triangles index TetMesh::nodes; `cut_plane` triangles are interior faces of the mesh.
struct SurfaceGroup {
  std::string name;
  int tag = -1;
  Eigen::MatrixXi triangles; ///< #F by 3 node indices
};

/// Tetrahedral mesh, libigl style: plain matrices plus named physical groups.
/// Units: metres. Every tetrahedron is stored with positive signed volume
/// (det[b-a, c-a, d-a] > 0) unless the input was inverted, which the quality summary reports.
struct TetMesh {
  Eigen::MatrixXd nodes; ///< #V by 3 node positions [m]
  Eigen::MatrixXi tets;  ///< #T by 4 node indices
  std::vector<VolumeGroup> volume_groups;
  std::vector<SurfaceGroup> surface_groups;

  /// The group with this name, or nullptr.
  [[nodiscard]] const VolumeGroup* find_volume_group(std::string_view name) const;
  [[nodiscard]] const SurfaceGroup* find_surface_group(std::string_view name) const;
};

/// Faces that belong to exactly one tetrahedron, oriented so their normal (b-a)x(c-a) points
/// out of that tetrahedron. #B by 3 node indices.
Eigen::MatrixXi boundary_faces(const Eigen::MatrixXi& tets);

/// Face adjacency: entry (t, k) is the tetrahedron sharing the face opposite local vertex k of
/// tetrahedron t, or -1 on the boundary. #T by 4.
Eigen::MatrixXi tet_face_adjacency(const Eigen::MatrixXi& tets);

/// Sum of signed tetrahedron volumes [m^3].
double mesh_volume(const TetMesh& mesh);

/// Volume of the tetrahedra of one group [m^3]. Throws MeshError if the group does not exist.
double group_volume(const TetMesh& mesh, std::string_view group);

/// Area of the triangles of one surface group [m^2]. Throws MeshError if it does not exist.
double surface_group_area(const TetMesh& mesh, std::string_view group);

/// Region index of each tetrahedron for a list of volume group names: entry t is the position in
/// `region_names` of the first group containing tetrahedron t, or -1. Used for layered bodies.
Eigen::VectorXi tet_regions(const TetMesh& mesh, const std::vector<std::string>& region_names);

} // namespace kerf

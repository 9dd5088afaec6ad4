#include "tests/reference/reference_test_meshes.hpp"

#include "meshes/box_tet_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace kerf::reference::test {

void name_bounding_faces(TetMesh& mesh) {
  const Eigen::MatrixXi faces = boundary_faces(mesh.tets);
  const Eigen::Vector3d lo = mesh.nodes.colwise().minCoeff(), hi = mesh.nodes.colwise().maxCoeff();
  const double tol = 1e-9 * (hi - lo).norm();
  const char* names[3][2] = {{"xmin", "xmax"}, {"ymin", "ymax"}, {"zmin", "zmax"}};
  std::vector<std::vector<int>> rows(7);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    rows[6].push_back(static_cast<int>(f));
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const double plane = side == 0 ? lo[axis] : hi[axis];
        bool on = true;
        for (int k = 0; k < 3; ++k) on = on && std::abs(mesh.nodes(faces(f, k), axis) - plane) < tol;
        if (on) rows[static_cast<std::size_t>(2 * axis + side)].push_back(static_cast<int>(f));
      }
  }
  mesh.surface_groups.clear();
  for (int g = 0; g < 7; ++g) {
    SurfaceGroup group;
    group.name = g < 6 ? names[g / 2][g % 2] : "boundary";
    group.tag = g + 1;
    group.triangles.resize(static_cast<Eigen::Index>(rows[static_cast<std::size_t>(g)].size()), 3);
    for (std::size_t r = 0; r < rows[static_cast<std::size_t>(g)].size(); ++r)
      group.triangles.row(static_cast<Eigen::Index>(r)) = faces.row(rows[static_cast<std::size_t>(g)][r]);
    mesh.surface_groups.push_back(std::move(group));
  }
}

TetMesh named_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, int nx, int ny, int nz) {
  TetMesh mesh = box_tet_mesh(lower, upper, nx, ny, nz);
  name_bounding_faces(mesh);
  return mesh;
}

TetMesh macneal_harder_patch() {
  // Nodes 0–7: the unit cube's corners; 8–15: MacNeal & Harder's interior nodes (Fig. 2).
  std::vector<Eigen::Vector3d> nodes = {
      {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
      {0.249, 0.342, 0.192}, {0.826, 0.288, 0.288}, {0.850, 0.649, 0.263}, {0.273, 0.750, 0.230},
      {0.320, 0.186, 0.643}, {0.677, 0.305, 0.683}, {0.788, 0.693, 0.644}, {0.165, 0.745, 0.702}};
  // Seven hexahedra (bottom quad, then top quad): the inner one and one per cube face.
  const std::vector<std::array<int, 8>> hexes = {
      {8, 9, 10, 11, 12, 13, 14, 15}, // inner
      {0, 1, 2, 3, 8, 9, 10, 11},     // z = 0
      {12, 13, 14, 15, 4, 5, 6, 7},   // z = 1
      {0, 1, 9, 8, 4, 5, 13, 12},     // y = 0
      {11, 10, 2, 3, 15, 14, 6, 7},   // y = 1
      {0, 8, 11, 3, 4, 12, 15, 7},    // x = 0
      {9, 1, 2, 10, 13, 5, 6, 14}};   // x = 1
  const int quads[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  std::map<std::array<int, 4>, int> face_centre;
  std::vector<Eigen::Vector4i> tets;
  for (const auto& h : hexes) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int v : h) c += nodes[static_cast<std::size_t>(v)] / 8.0;
    const int centre = static_cast<int>(nodes.size());
    nodes.push_back(c);
    for (const auto& q : quads) {
      std::array<int, 4> key{h[static_cast<std::size_t>(q[0])], h[static_cast<std::size_t>(q[1])],
                             h[static_cast<std::size_t>(q[2])], h[static_cast<std::size_t>(q[3])]};
      std::array<int, 4> sorted = key;
      std::sort(sorted.begin(), sorted.end());
      auto [it, added] = face_centre.emplace(sorted, static_cast<int>(nodes.size()));
      if (added) {
        Eigen::Vector3d fc = Eigen::Vector3d::Zero();
        for (int v : key) fc += nodes[static_cast<std::size_t>(v)] / 4.0;
        nodes.push_back(fc);
      }
      for (int e = 0; e < 4; ++e) {
        Eigen::Vector4i t(key[static_cast<std::size_t>(e)], key[static_cast<std::size_t>((e + 1) % 4)], it->second, centre);
        const Eigen::Vector3d a = nodes[static_cast<std::size_t>(t[0])];
        const double vol = (nodes[static_cast<std::size_t>(t[1])] - a)
                               .cross(nodes[static_cast<std::size_t>(t[2])] - a)
                               .dot(nodes[static_cast<std::size_t>(t[3])] - a);
        if (vol < 0.0) std::swap(t[0], t[1]);
        tets.push_back(t);
      }
    }
  }
  TetMesh mesh;
  mesh.nodes.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (std::size_t i = 0; i < nodes.size(); ++i) mesh.nodes.row(static_cast<Eigen::Index>(i)) = nodes[i];
  mesh.tets.resize(static_cast<Eigen::Index>(tets.size()), 4);
  VolumeGroup body{"body", 1, {}};
  for (std::size_t t = 0; t < tets.size(); ++t) {
    mesh.tets.row(static_cast<Eigen::Index>(t)) = tets[t];
    body.tets.push_back(static_cast<int>(t));
  }
  mesh.volume_groups.push_back(body);
  name_bounding_faces(mesh);
  return mesh;
}

TetMesh cook_membrane(int n) {
  TetMesh mesh = box_tet_mesh(Eigen::Vector3d(0.0, 0.0, -0.5e-3), Eigen::Vector3d(48e-3, 44e-3, 0.5e-3), n, n, 1);
  name_bounding_faces(mesh);
  // Map the 48 x 44 rectangle onto the trapezoid (code gallery, grid_y_transform):
  // y ↦ y_lower(x) + (y / 44) (y_upper(x) − y_lower(x)), y_lower = 44x/48, y_upper = 44 + 16x/48 (mm).
  for (Eigen::Index v = 0; v < mesh.nodes.rows(); ++v) {
    const double x = mesh.nodes(v, 0) * 1e3, y = mesh.nodes(v, 1) * 1e3;
    const double lower = 44.0 * x / 48.0, upper = 44.0 + 16.0 * x / 48.0;
    mesh.nodes(v, 1) = (lower + y / 44.0 * (upper - lower)) * 1e-3;
  }
  return mesh;
}

void add_interior_face_group(TetMesh& mesh, const std::string& name, const std::function<bool(const Eigen::Vector3d&)>& on_surface) {
  // Local vertices of the face opposite vertex k (any winding: crack_split orients by the sides).
  constexpr int opposite[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  const Eigen::MatrixXi adjacency = tet_face_adjacency(mesh.tets);
  std::vector<std::array<int, 3>> rows;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      if (adjacency(t, k) < t) continue; // boundary, or seen from the other tetrahedron already
      std::array<int, 3> tri{};
      bool on = true;
      for (int j = 0; j < 3; ++j) {
        tri[static_cast<std::size_t>(j)] = mesh.tets(t, opposite[k][j]);
        on = on && on_surface(mesh.nodes.row(tri[static_cast<std::size_t>(j)]).transpose());
      }
      if (on) rows.push_back(tri);
    }
  SurfaceGroup group{name, static_cast<int>(mesh.surface_groups.size()) + 100, Eigen::MatrixXi(static_cast<Eigen::Index>(rows.size()), 3)};
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (int j = 0; j < 3; ++j) group.triangles(static_cast<Eigen::Index>(r), j) = rows[r][static_cast<std::size_t>(j)];
  mesh.surface_groups.push_back(std::move(group));
}

FiniteStrainProblem cook_membrane_problem(TetMesh mesh, bool plane_strain) {
  FiniteStrainProblem p;
  p.mesh = std::move(mesh);
  const double mu = 422.5e3, nu = 0.3; // the gallery's parameters.prm
  p.materials.push_back({"body", LawKind::decoupled_neo_hookean, 2.0 * mu * (1.0 + nu), nu});
  p.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::bonded, {}, {}});
  if (plane_strain) {
    p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::sliding, {}, {}});
    p.displacement_boundaries.push_back({"zmax", DisplacementBoundary::Kind::sliding, {}, {}});
  }
  p.tractions.push_back({"xmax", Eigen::Vector3d(0.0, 1.0, 0.0)});
  return p;
}

FiniteStrainProblem affine_problem(TetMesh mesh, const Eigen::Matrix3d& G, const Eigen::Vector3d& b, LawKind law,
                                   double E, double nu) {
  FiniteStrainProblem p;
  p.mesh = std::move(mesh);
  p.materials.push_back({"body", law, E, nu});
  DisplacementBoundary bc;
  bc.surface = "boundary";
  bc.kind = DisplacementBoundary::Kind::prescribed;
  bc.displacement = [G, b](const Eigen::Vector3d& X, double load) -> Eigen::Vector3d { return load * (G * X + b); };
  p.displacement_boundaries.push_back(bc);
  return p;
}

} // namespace kerf::reference::test

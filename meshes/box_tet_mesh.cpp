#include "meshes/box_tet_mesh.hpp"

#include "meshes/mesh_error.hpp"

#include <array>
#include <utility>

namespace kerf {

TetMesh box_tet_mesh(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, int nx, int ny, int nz) {
  if (nx < 1 || ny < 1 || nz < 1) throw MeshError("box mesh: need at least one cell per direction");
  if (!((upper - lower).array() > 0.0).all()) throw MeshError("box mesh: upper corner must exceed lower corner");
  const std::array<int, 3> n{nx, ny, nz};
  auto node = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };

  TetMesh mesh;
  mesh.nodes.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const Eigen::Vector3d s(double(i) / nx, double(j) / ny, double(k) / nz);
        mesh.nodes.row(node(i, j, k)) = (lower.array() + s.array() * (upper - lower).array()).transpose();
      }

  // Kuhn subdivision: the 6 monotone paths from corner 000 to 111 of the unit cube, one
  // tetrahedron per permutation of the axes; corners are numbered by bits (x=1, y=2, z=4).
  static constexpr std::array<std::array<int, 3>, 6> permutations{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  mesh.tets.resize(6 * nx * ny * nz, 4);
  int t = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& axes : permutations) {
          int corner = 0;
          std::array<int, 4> v{};
          for (int s = 0; s < 4; ++s) {
            if (s > 0) corner |= 1 << axes[static_cast<std::size_t>(s - 1)];
            v[static_cast<std::size_t>(s)] = node(i + (corner & 1), j + ((corner >> 1) & 1), k + ((corner >> 2) & 1));
          }
          // Odd permutations give negative orientation: swap two vertices.
          const int odd = (axes[0] > axes[1]) + (axes[0] > axes[2]) + (axes[1] > axes[2]);
          if (odd % 2 != 0) std::swap(v[2], v[3]);
          mesh.tets.row(t++) << v[0], v[1], v[2], v[3];
        }

  VolumeGroup body{"body", 1, {}};
  body.tets.resize(static_cast<std::size_t>(t));
  for (int e = 0; e < t; ++e) body.tets[static_cast<std::size_t>(e)] = e;
  mesh.volume_groups.push_back(std::move(body));

  // Boundary quads split into two triangles each, outward oriented.
  auto quads = [&](int axis, int layer, bool outward_positive) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    Eigen::MatrixXi tri(2 * n[static_cast<std::size_t>(a)] * n[static_cast<std::size_t>(b)], 3);
    int f = 0;
    for (int q = 0; q < n[static_cast<std::size_t>(b)]; ++q)
      for (int p = 0; p < n[static_cast<std::size_t>(a)]; ++p) {
        auto at = [&](int dp, int dq) {
          std::array<int, 3> c{};
          c[static_cast<std::size_t>(axis)] = layer;
          c[static_cast<std::size_t>(a)] = p + dp;
          c[static_cast<std::size_t>(b)] = q + dq;
          return node(c[0], c[1], c[2]);
        };
        // (a, b, axis) is right-handed, so a-then-b winding has its normal along +axis.
        if (outward_positive) {
          tri.row(f++) << at(0, 0), at(1, 0), at(1, 1);
          tri.row(f++) << at(0, 0), at(1, 1), at(0, 1);
        } else {
          tri.row(f++) << at(0, 0), at(1, 1), at(1, 0);
          tri.row(f++) << at(0, 0), at(0, 1), at(1, 1);
        }
      }
    return tri;
  };
  mesh.surface_groups.push_back({"support", 2, quads(2, 0, false)});
  mesh.surface_groups.push_back({"top", 3, quads(2, nz, true)});
  std::vector<Eigen::MatrixXi> sides{quads(0, 0, false), quads(0, nx, true), quads(1, 0, false), quads(1, ny, true)};
  Eigen::Index rows = 0;
  for (const auto& s : sides) rows += s.rows();
  Eigen::MatrixXi all(rows, 3);
  rows = 0;
  for (const auto& s : sides) {
    all.middleRows(rows, s.rows()) = s;
    rows += s.rows();
  }
  mesh.surface_groups.push_back({"sides", 4, all});
  return mesh;
}

void add_height_layers(TetMesh& mesh, double interface_z) {
  VolumeGroup upper{"layer_upper", static_cast<int>(mesh.volume_groups.size()) + 10, {}};
  VolumeGroup lower{"layer_lower", upper.tag + 1, {}};
  for (int t = 0; t < mesh.tets.rows(); ++t) {
    double z = 0.0;
    for (int v = 0; v < 4; ++v) z += 0.25 * mesh.nodes(mesh.tets(t, v), 2);
    (z > interface_z ? upper : lower).tets.push_back(t);
  }
  mesh.volume_groups.push_back(std::move(upper));
  mesh.volume_groups.push_back(std::move(lower));
}

} // namespace kerf

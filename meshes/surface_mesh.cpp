#include "meshes/surface_mesh.hpp"

#include "meshes/mesh_error.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/triangle_closest_point.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

namespace kerf {

namespace {

/// Squared distance from p to an axis-aligned box (0 inside): the lower bound for best-first search.
double squared_distance_to_box(const Eigen::Vector3d& p, const Eigen::AlignedBox3d& box) {
  return box.squaredExteriorDistance(p);
}

/// Row i of a #N by 3 matrix as a column vector.
Eigen::Vector3d row3(const Eigen::MatrixXd& m, Eigen::Index i) { return m.row(i).transpose(); }

} // namespace

SurfaceMesh boundary_surface(const TetMesh& mesh) {
  const Eigen::MatrixXi faces = boundary_faces(mesh.tets);
  // Compact re-indexing in ascending order of the mesh's node indices.
  std::vector<int> new_index(static_cast<std::size_t>(mesh.nodes.rows()), -1);
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int j = 0; j < 3; ++j) new_index[static_cast<std::size_t>(faces(f, j))] = 0;
  int count = 0;
  for (auto& index : new_index)
    if (index == 0) index = count++;
  SurfaceMesh surface;
  surface.vertices.resize(count, 3);
  for (std::size_t v = 0; v < new_index.size(); ++v)
    if (new_index[v] >= 0) surface.vertices.row(new_index[v]) = mesh.nodes.row(static_cast<Eigen::Index>(v));
  surface.triangles.resize(faces.rows(), 3);
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int j = 0; j < 3; ++j) surface.triangles(f, j) = new_index[static_cast<std::size_t>(faces(f, j))];
  return surface;
}

double surface_area(const SurfaceMesh& surface) {
  double area = 0.0;
  for (Eigen::Index f = 0; f < surface.triangles.rows(); ++f) {
    const Eigen::Vector3d a = row3(surface.vertices, surface.triangles(f, 0));
    const Eigen::Vector3d b = row3(surface.vertices, surface.triangles(f, 1));
    const Eigen::Vector3d c = row3(surface.vertices, surface.triangles(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

double enclosed_volume(const SurfaceMesh& surface) {
  if (surface.vertices.rows() == 0) return 0.0;
  // Divergence theorem with the field (x - o) / 3: V = sum over triangles of
  // (a - o) . ((b - o) x (c - o)) / 6, for any origin o. Taking o at the centre of the bounding
  // box keeps the terms of the order of the body's size (no cancellation far from the origin).
  const Eigen::Vector3d o =
      0.5 * (surface.vertices.colwise().minCoeff() + surface.vertices.colwise().maxCoeff()).transpose();
  double volume = 0.0;
  for (Eigen::Index f = 0; f < surface.triangles.rows(); ++f) {
    const Eigen::Vector3d a = row3(surface.vertices, surface.triangles(f, 0)) - o;
    const Eigen::Vector3d b = row3(surface.vertices, surface.triangles(f, 1)) - o;
    const Eigen::Vector3d c = row3(surface.vertices, surface.triangles(f, 2)) - o;
    volume += a.dot(b.cross(c));
  }
  return volume / 6.0;
}

SurfaceQuery::SurfaceQuery(SurfaceMesh surface) : m_surface(std::move(surface)) {
  const Eigen::MatrixXd& V = m_surface.vertices;
  const Eigen::MatrixXi& F = m_surface.triangles;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int j = 0; j < 3; ++j)
      if (F(f, j) < 0 || F(f, j) >= V.rows())
        throw MeshError("SurfaceQuery: triangle " + std::to_string(f) + " indexes vertex " + std::to_string(F(f, j)) +
                        " of " + std::to_string(V.rows()));

  // Unit face normals n_f = (b - a) x (c - a) / |...| (zero for a zero-area triangle).
  m_face_normals = Eigen::MatrixXd::Zero(F.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d n = (row3(V, F(f, 1)) - row3(V, F(f, 0))).cross(row3(V, F(f, 2)) - row3(V, F(f, 0)));
    const double length = n.norm();
    if (length > 0.0) m_face_normals.row(f) = (n / length).transpose();
  }

  // Vertex pseudo-normal: n_v = sum over incident faces of alpha_f n_f, alpha_f the angle of
  // face f at v (Bærentzen & Aanæs 2005, eq. 2), normalised.
  m_vertex_normals = Eigen::MatrixXd::Zero(V.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d v = row3(V, F(f, j));
      const Eigen::Vector3d e1 = row3(V, F(f, (j + 1) % 3)) - v;
      const Eigen::Vector3d e2 = row3(V, F(f, (j + 2) % 3)) - v;
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      m_vertex_normals.row(F(f, j)) += angle * m_face_normals.row(f);
    }
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const double length = m_vertex_normals.row(v).norm();
    if (length > 0.0) m_vertex_normals.row(v) /= length;
  }

  // Edge pseudo-normal: n_e = n_f1 + n_f2 for the two faces sharing the edge (Bærentzen & Aanæs
  // 2005, section 3; the weights pi are common and drop out on normalising). Edges are matched
  // by their sorted vertex pair; an edge with one face (open surface) takes that face's normal.
  struct EdgeRecord {
    int low, high, face, local;
  };
  std::vector<EdgeRecord> edges;
  edges.reserve(static_cast<std::size_t>(3 * F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int u = F(f, (k + 1) % 3);
      const int w = F(f, (k + 2) % 3);
      edges.push_back({std::min(u, w), std::max(u, w), static_cast<int>(f), k});
    }
  std::sort(edges.begin(), edges.end(), [](const EdgeRecord& x, const EdgeRecord& y) {
    return std::tie(x.low, x.high, x.face, x.local) < std::tie(y.low, y.high, y.face, y.local);
  });
  m_edge_normals = Eigen::MatrixXd::Zero(3 * F.rows(), 3);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].low == edges[i].low && edges[j].high == edges[i].high) ++j;
    Eigen::RowVector3d n = Eigen::RowVector3d::Zero();
    for (std::size_t e = i; e < j; ++e) n += m_face_normals.row(edges[e].face);
    const double length = n.norm();
    if (length > 0.0) n /= length;
    for (std::size_t e = i; e < j; ++e) m_edge_normals.row(3 * edges[e].face + edges[e].local) = n;
    i = j;
  }

  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    auto& box = boxes[static_cast<std::size_t>(f)];
    for (int j = 0; j < 3; ++j) box.extend(row3(V, F(f, j)));
  }
  m_tree = AabbTree(boxes);
}

SurfaceQuery::Closest SurfaceQuery::closest_point(const Eigen::Vector3d& p) const {
  Closest result;
  result.signed_distance = std::numeric_limits<double>::infinity();
  if (m_tree.empty()) return result;
  const Eigen::MatrixXd& V = m_surface.vertices;
  const Eigen::MatrixXi& F = m_surface.triangles;
  TriangleFeature best_feature = TriangleFeature::face;
  double best_squared = std::numeric_limits<double>::infinity();
  // Best-first search over the AABB tree with squared distances (no square roots in the loop,
  // no allocation: the tree's traversal stack is a fixed array and the lambdas capture by reference).
  m_tree.for_each_nearest(
      std::numeric_limits<double>::infinity(), [&](const Eigen::AlignedBox3d& box) { return squared_distance_to_box(p, box); },
      [&](std::int32_t f) {
        const TriangleClosestPoint q = closest_point_on_triangle(p, row3(V, F(f, 0)), row3(V, F(f, 1)), row3(V, F(f, 2)));
        const double squared = (p - q.point).squaredNorm();
        if (squared < best_squared) {
          best_squared = squared;
          best_feature = q.feature;
          result.point = q.point;
          result.triangle = f;
        }
        return squared;
      });
  const int f = result.triangle;
  // Pseudo-normal of the feature holding the closest point (Bærentzen & Aanæs 2005, Theorem 1:
  // sign(p - q) . n_feature is the sign of the distance for a closed 2-manifold).
  switch (best_feature) {
  case TriangleFeature::vertex_a: result.normal = row3(m_vertex_normals, F(f, 0)); break;
  case TriangleFeature::vertex_b: result.normal = row3(m_vertex_normals, F(f, 1)); break;
  case TriangleFeature::vertex_c: result.normal = row3(m_vertex_normals, F(f, 2)); break;
  case TriangleFeature::edge_bc: result.normal = row3(m_edge_normals, 3 * f + 0); break;
  case TriangleFeature::edge_ca: result.normal = row3(m_edge_normals, 3 * f + 1); break;
  case TriangleFeature::edge_ab: result.normal = row3(m_edge_normals, 3 * f + 2); break;
  case TriangleFeature::face: result.normal = row3(m_face_normals, f); break;
  }
  const double distance = std::sqrt(best_squared);
  result.signed_distance = (p - result.point).dot(result.normal) < 0.0 ? -distance : distance;
  return result;
}

bool SurfaceQuery::contains(const Eigen::Vector3d& p) const { return closest_point(p).signed_distance < 0.0; }

} // namespace kerf

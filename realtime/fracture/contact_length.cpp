#include "realtime/fracture/contact_length.hpp"

#include "meshes/mesh_error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace kerf {

SegmentLengthInBody::SegmentLengthInBody(const TetMesh& mesh, const std::vector<std::string>& regions) {
  const auto tet_count = static_cast<std::size_t>(mesh.tets.rows());
  if (tet_count == 0) throw MeshError("contact length: the mesh has no tetrahedra");
  m_region.assign(tet_count, 0);
  if (!regions.empty()) {
    m_region_count = static_cast<int>(regions.size());
    const Eigen::VectorXi region = tet_regions(mesh, regions); // throws if a group is missing
    for (std::size_t t = 0; t < tet_count; ++t) {
      if (region[static_cast<Eigen::Index>(t)] < 0)
        throw MeshError("contact length: tetrahedron " + std::to_string(t) +
                        " belongs to none of the layer regions");
      m_region[t] = region[static_cast<Eigen::Index>(t)];
    }
  }

  m_faces.resize(tet_count);
  m_tolerance.resize(tet_count);
  std::vector<Eigen::AlignedBox3d> boxes(tet_count);
  std::vector<std::size_t> per_region(static_cast<std::size_t>(m_region_count), 0);
  // Face k is opposite local vertex k; the outward normal points away from that vertex.
  static constexpr int face_vertices[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (std::size_t t = 0; t < tet_count; ++t) {
    Eigen::Vector3d x[4];
    for (int v = 0; v < 4; ++v) x[v] = mesh.nodes.row(mesh.tets(static_cast<Eigen::Index>(t), v)).transpose();
    double size = 0.0;
    for (int v = 0; v < 4; ++v) {
      boxes[t].extend(x[v]);
      for (int w = v + 1; w < 4; ++w) size = std::max(size, (x[v] - x[w]).norm());
    }
    m_tolerance[t] = 1e-12 * size;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& a = x[face_vertices[k][0]];
      Eigen::Vector3d n = (x[face_vertices[k][1]] - a).cross(x[face_vertices[k][2]] - a);
      // Orient outward whatever the stored orientation: the opposite vertex must be inside.
      if (n.dot(x[k] - a) > 0.0) n = -n;
      const double norm = n.norm();
      if (norm > 0.0) n /= norm;
      m_faces[t][static_cast<std::size_t>(k)] = Face{n, n.dot(a)};
    }
    ++per_region[static_cast<std::size_t>(m_region[t])];
  }
  m_tree = AabbTree(boxes);
  m_scratch.resize(static_cast<std::size_t>(m_region_count));
  for (std::size_t r = 0; r < m_scratch.size(); ++r) m_scratch[r].reserve(per_region[r]);
}

double SegmentLengthInBody::lengths(const Eigen::Vector3d& a, const Eigen::Vector3d& b, std::span<double> out) {
  for (auto& s : m_scratch) s.clear(); // keeps capacity: no allocation below
  const Eigen::Vector3d d = b - a;
  Eigen::AlignedBox3d query(a.cwiseMin(b), a.cwiseMax(b));

  m_tree.for_each_overlapping(query, [&](int t) {
    const auto ti = static_cast<std::size_t>(t);
    double t0 = 0.0, t1 = 1.0;
    // Cyrus–Beck: the point a + s d is inside face plane k iff n.(a + s d) <= offset + tol.
    for (const Face& f : m_faces[ti]) {
      const double nd = f.normal.dot(d);
      const double r = f.offset + m_tolerance[ti] - f.normal.dot(a);
      if (std::abs(nd) <= 1e-15 * d.norm()) {
        if (r < 0.0) return; // parallel to the face and outside it
        continue;
      }
      const double s = r / nd;
      if (nd > 0.0) t1 = std::min(t1, s);
      else t0 = std::max(t0, s);
      if (t0 > t1) return;
    }
    m_scratch[static_cast<std::size_t>(m_region[ti])].push_back({t0, t1});
  });

  const double segment_length = d.norm();
  double total = 0.0;
  for (std::size_t r = 0; r < m_scratch.size(); ++r) {
    auto& intervals = m_scratch[r];
    // Measure of the union: sort by start, sweep (std::sort works in place).
    std::sort(intervals.begin(), intervals.end(), [](const Interval& p, const Interval& q) { return p.t0 < q.t0; });
    double measure = 0.0;
    double start = 0.0, end = -1.0;
    for (const Interval& iv : intervals) {
      if (iv.t0 > end) {
        if (end > start) measure += end - start;
        start = iv.t0;
        end = iv.t1;
      } else {
        end = std::max(end, iv.t1);
      }
    }
    if (end > start) measure += end - start;
    out[r] = measure * segment_length;
    total += out[r];
  }
  return total;
}

double SegmentLengthInBody::length(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  double per_region[16];
  if (m_region_count <= 16) return lengths(a, b, std::span<double>(per_region, static_cast<std::size_t>(m_region_count)));
  std::vector<double> many(static_cast<std::size_t>(m_region_count)); // not on the realtime path
  return lengths(a, b, many);
}

} // namespace kerf

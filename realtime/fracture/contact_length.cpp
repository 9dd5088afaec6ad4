#include "realtime/fracture/contact_length.hpp"

#include "meshes/mesh_error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

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

void SegmentLengthInBody::breakpoints_along(const Eigen::Vector3d& a, const Eigen::Vector3d& d, const Eigen::Vector3d& e,
                                            double s_min, double s_max, std::vector<double>& out) const {
  // The swept segment's box.
  Eigen::AlignedBox3d swept;
  for (const double s : {s_min, s_max}) {
    swept.extend(a + s * e);
    swept.extend(a + d + s * e);
  }
  const auto keep = [&](double s) {
    if (std::isfinite(s) && s >= s_min && s <= s_max) out.push_back(s);
  };
  m_tree.for_each_overlapping(swept, [&](int t) {
    const auto ti = static_cast<std::size_t>(t);
    // Face k: t_k(s) = α_k + β_k s where n·d ≠ 0; a parallel face switches at one s.
    double alpha[4], beta[4];
    int affine = 0;
    for (const Face& f : m_faces[ti]) {
      const double nd = f.normal.dot(d), ne = f.normal.dot(e);
      const double r0 = f.offset + m_tolerance[ti] - f.normal.dot(a); // r(s) = r0 − s n·e
      if (std::abs(nd) <= 1e-15 * d.norm()) {
        if (ne != 0.0) keep(r0 / ne);
        continue;
      }
      alpha[affine] = r0 / nd;
      beta[affine] = -ne / nd;
      ++affine;
    }
    for (int k = 0; k < affine; ++k) {
      if (beta[k] != 0.0) {
        keep(-alpha[k] / beta[k]);
        keep((1.0 - alpha[k]) / beta[k]);
      }
      for (int m = k + 1; m < affine; ++m)
        if (beta[k] != beta[m]) keep((alpha[m] - alpha[k]) / (beta[k] - beta[m]));
    }
  });
}

ContactLengthTable::ContactLengthTable(SegmentLengthInBody& body, const Eigen::Vector3d& p0, const Eigen::Vector3d& e,
                                       const Eigen::Vector3d& half, double s_min, double s_max)
    : m_body(&body), m_p0(p0), m_e(e), m_half(half), m_regions(body.region_count()) {
  std::vector<double> candidates{s_min, s_max};
  body.breakpoints_along(p0 - half, 2.0 * half, e, s_min, s_max, candidates);
  std::sort(candidates.begin(), candidates.end());
  for (const double s : candidates)
    if (m_breakpoints.empty() || s - m_breakpoints.back() > 1e-12) m_breakpoints.push_back(s);
  if (m_breakpoints.size() < 2) m_breakpoints.push_back(m_breakpoints.back() + 1e-9);
  const auto regions = static_cast<std::size_t>(m_regions);
  std::vector<double> l1(regions), l2(regions);
  const auto measure = [&](double s, std::vector<double>& into) { body.lengths(p0 + s * e - half, p0 + s * e + half, into); };
  const std::size_t intervals = m_breakpoints.size() - 1;
  m_value.resize(intervals * regions);
  m_slope.resize(intervals * regions);
  for (std::size_t j = 0; j < intervals; ++j) {
    const double b0 = m_breakpoints[j], width = m_breakpoints[j + 1] - b0;
    const double q1 = b0 + width / 3.0, q2 = b0 + 2.0 * width / 3.0;
    measure(q1, l1);
    measure(q2, l2);
    for (std::size_t r = 0; r < regions; ++r) {
      const double slope = (l2[r] - l1[r]) / (q2 - q1);
      m_slope[j * regions + r] = slope;
      m_value[j * regions + r] = l1[r] - slope * (q1 - b0);
    }
  }
}

double ContactLengthTable::parameter(const Eigen::Vector3d& p) const noexcept {
  if (m_breakpoints.empty()) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d r = p - m_p0;
  const double s = r.dot(m_e);
  if ((r - s * m_e).norm() > 1e-12 || s < m_breakpoints.front() || s > m_breakpoints.back())
    return std::numeric_limits<double>::quiet_NaN();
  return s;
}

double ContactLengthTable::lengths(double s, std::span<double> out) noexcept {
  const auto regions = static_cast<std::size_t>(m_regions);
  // The interval [b_j, b_{j+1}] holding s: the last one or its neighbours first (a blade moves
  // a micrometre per sample), else bisection.
  const std::size_t last = m_breakpoints.size() - 1;
  std::size_t j = std::min(m_last, last - 1);
  if (!(m_breakpoints[j] <= s && s <= m_breakpoints[j + 1])) {
    if (j + 2 <= last && m_breakpoints[j + 1] <= s && s <= m_breakpoints[j + 2]) ++j;
    else if (j > 0 && m_breakpoints[j - 1] <= s && s <= m_breakpoints[j]) --j;
    else j = std::clamp<std::size_t>(static_cast<std::size_t>(std::upper_bound(m_breakpoints.begin(), m_breakpoints.end(), s) -
                                                              m_breakpoints.begin()), 1, last) - 1;
  }
  m_last = j;
  // Next to a breakpoint, where a length may jump: measured on the mesh.
  if (s - m_breakpoints[j] <= 1e-12 || m_breakpoints[j + 1] - s <= 1e-12) {
    const Eigen::Vector3d p = m_p0 + s * m_e;
    return m_body->lengths(p - m_half, p + m_half, out);
  }
  double total = 0.0;
  for (std::size_t r = 0; r < regions; ++r) {
    // a zero length extrapolated may round below zero
    out[r] = std::max(m_value[j * regions + r] + m_slope[j * regions + r] * (s - m_breakpoints[j]), 0.0);
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

#include "meshes/tet_quality.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace kerf {

namespace {

/// Outward area vectors (twice the area times the unit normal) of the four faces of a positively
/// oriented tetrahedron (a, b, c, d); entry k is the face opposite vertex k:
/// (b, c, d), (a, d, c), (a, b, d), (a, c, b). For a negatively oriented tetrahedron all four
/// point inward, which leaves every dihedral angle unchanged.
std::array<Eigen::Vector3d, 4> face_area_vectors(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                 const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  return {(c - b).cross(d - b), (d - a).cross(c - a), (b - a).cross(d - a), (c - a).cross(b - a)};
}

double longest_edge(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d) {
  return std::sqrt(std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (d - a).squaredNorm(),
                             (c - b).squaredNorm(), (d - b).squaredNorm(), (d - c).squaredNorm()}));
}

} // namespace

double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d) {
  // V = det[b - a, c - a, d - a] / 6 = (b - a) . ((c - a) x (d - a)) / 6
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double min_dihedral_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d) {
  // The interior dihedral angle at the edge shared by the faces opposite vertices k and l is
  // pi minus the angle between their outward normals n_k, n_l (Shewchuk 2002, section 3):
  //   theta_kl = atan2(|n_k x n_l|, -n_k . n_l).
  // atan2 keeps full accuracy near 0 and pi and returns 0 (never NaN) when a face has zero area.
  const auto n = face_area_vectors(a, b, c, d);
  double smallest = std::numbers::pi;
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) {
      const auto& nk = n[static_cast<std::size_t>(k)];
      const auto& nl = n[static_cast<std::size_t>(l)];
      smallest = std::min(smallest, std::atan2(nk.cross(nl).norm(), -nk.dot(nl)));
    }
  return std::isfinite(smallest) ? smallest : 0.0;
}

double radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d) {
  // Scale-free: work in units of the longest edge so that no product below under- or overflows.
  const double h = longest_edge(a, b, c, d);
  if (!(h > 0.0) || !std::isfinite(h)) return 0.0;
  const Eigen::Vector3d u = (b - a) / h;
  const Eigen::Vector3d v = (c - a) / h;
  const Eigen::Vector3d w = (d - a) / h;
  // Inradius r_in = 3 |V| / A, A the sum of the face areas.
  // Circumcentre relative to a: o = (|u|^2 (v x w) + |v|^2 (w x u) + |w|^2 (u x v)) / (2 u.(v x w)),
  // so r_circ = |m| / (12 |V|) with m the numerator and 6 V = u.(v x w).
  // 3 r_in / r_circ = 3 (3 |V| / A) (12 |V| / |m|) = 108 V^2 / (A |m|)   (Shewchuk 2002, eq. for
  // the radius ratio; 1 for the regular tetrahedron).
  const double six_volume = u.dot(v.cross(w));
  const double volume = six_volume / 6.0;
  const auto n = face_area_vectors(Eigen::Vector3d::Zero(), u, v, w);
  const double area = 0.5 * (n[0].norm() + n[1].norm() + n[2].norm() + n[3].norm());
  const Eigen::Vector3d m = u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) + w.squaredNorm() * u.cross(v);
  const double denominator = area * m.norm();
  if (!(denominator > 0.0)) return 0.0;
  const double ratio = 108.0 * volume * volume / denominator;
  if (!std::isfinite(ratio)) return 0.0;
  return std::clamp(ratio, 0.0, 1.0);
}

TetQualitySummary tet_quality_summary(const TetMesh& mesh, const TetQualityThresholds& thresholds) {
  TetQualitySummary summary;
  summary.tet_count = static_cast<int>(mesh.tets.rows());
  summary.node_count = static_cast<int>(mesh.nodes.rows());
  if (summary.tet_count == 0) return summary;
  summary.min_volume = std::numeric_limits<double>::infinity();
  summary.min_dihedral_angle = std::numeric_limits<double>::infinity();
  summary.min_radius_ratio = std::numeric_limits<double>::infinity();
  double radius_ratio_sum = 0.0;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    const Eigen::Vector3d a = mesh.nodes.row(mesh.tets(t, 0)).transpose();
    const Eigen::Vector3d b = mesh.nodes.row(mesh.tets(t, 1)).transpose();
    const Eigen::Vector3d c = mesh.nodes.row(mesh.tets(t, 2)).transpose();
    const Eigen::Vector3d d = mesh.nodes.row(mesh.tets(t, 3)).transpose();
    const double volume = signed_volume(a, b, c, d);
    const double h = longest_edge(a, b, c, d);
    const double dihedral = min_dihedral_angle(a, b, c, d);
    const double ratio = radius_ratio(a, b, c, d);
    const double volume_floor = thresholds.degenerate_relative_volume * h * h * h;
    if (volume < -volume_floor)
      ++summary.inverted;
    else if (std::abs(volume) <= volume_floor)
      ++summary.degenerate;
    else if (dihedral < thresholds.sliver_min_dihedral || ratio < thresholds.sliver_radius_ratio)
      ++summary.slivers;
    summary.total_volume += volume;
    summary.min_volume = std::min(summary.min_volume, volume);
    summary.min_dihedral_angle = std::min(summary.min_dihedral_angle, dihedral);
    summary.min_radius_ratio = std::min(summary.min_radius_ratio, ratio);
    radius_ratio_sum += ratio;
  }
  summary.mean_radius_ratio = radius_ratio_sum / summary.tet_count;
  return summary;
}

} // namespace kerf

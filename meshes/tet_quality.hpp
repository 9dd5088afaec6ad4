#pragma once
// Element quality measures for tetrahedra. Shewchuk, "What is a good linear finite element?" (2002)
// discusses why dihedral angles and the radius ratio detect the elements that spoil
// interpolation and conditioning; an inverted element has negative signed volume.

#include "meshes/tet_mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kerf {

/// Signed volume det[b-a, c-a, d-a] / 6 [m^3]; positive for the positive orientation.
double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d);

/// Smallest of the six interior dihedral angles [rad]; pi/2 - ... ; 0 for a flat element.
/// A regular tetrahedron has acos(1/3) = 70.53 deg at every edge.
double min_dihedral_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, const Eigen::Vector3d& d);

/// Normalised radius ratio 3 r_in / r_circ in [0, 1]: 1 for the regular tetrahedron, 0 for a
/// degenerate one. r_in = 3V / (sum of face areas), r_circ from the circumsphere.
double radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d);

/// Thresholds that classify an element. A tetrahedron is
/// - inverted if its signed volume is < -degenerate_relative_volume * h^3,
/// - degenerate if |V| <= degenerate_relative_volume * h^3 (h = its longest edge),
/// - a sliver if it is neither but its min dihedral angle is below sliver_min_dihedral or its
///   radius ratio below sliver_radius_ratio.
struct TetQualityThresholds {
  double degenerate_relative_volume = 1e-10;
  double sliver_min_dihedral = 5.0 * 3.14159265358979323846 / 180.0; ///< [rad]
  double sliver_radius_ratio = 0.05;
};

/// What `kerf mesh` prints and what tests check.
struct TetQualitySummary {
  int tet_count = 0;
  int node_count = 0;
  int inverted = 0;
  int degenerate = 0;
  int slivers = 0;
  double total_volume = 0.0;        ///< [m^3]
  double min_volume = 0.0;          ///< [m^3]
  double min_dihedral_angle = 0.0;  ///< [rad], over all elements
  double min_radius_ratio = 0.0;
  double mean_radius_ratio = 0.0;
  [[nodiscard]] bool valid() const { return inverted == 0 && degenerate == 0; }
};

TetQualitySummary tet_quality_summary(const TetMesh& mesh, const TetQualityThresholds& thresholds = {});

} // namespace kerf

#pragma once
// The compliant grasp on the spring network: the elastic layer between a stylus and the disc of
// the body's surface it grasps (docs/scenes.md, "Grasp"), whose traction on the body is
// t = k(r) (d − u), k(r) = k (1 − r²/a²), lumped onto the network's nodes on that face as
// anchor springs (NodeAnchors) of stiffness K_p = ∫ N_p k(r) dA.

#include "realtime/springs/spring_network.hpp"

#include <Eigen/Core>

#include <vector>

namespace kerf {

/// The grasped disc and its layer (SI units).
struct GraspLayer {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();      ///< the disc's centre, on the grasped face [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();     ///< the face's outward unit normal (a coordinate axis)
  double radius = 0.0;                                   ///< a [m] > 0
  double stiffness = 0.0;                                ///< k [N/m³] > 0: the layer's stiffness per area at the centre
};

/// The layer lumped onto nodes: node[i] carries stiffness[i] = K_p [N/m].
struct LumpedGraspLayer {
  std::vector<int> node;
  std::vector<double> stiffness;
};

/// The layer's stiffness per node of the network's face under the disc: the outer faces (no kept
/// cell beyond them) of kept cells in the plane of the lattice normal to `normal` that bounds the
/// network at the centre's projection — the body's face itself when the lattice ends on it,
/// otherwise the network's face within h/2 of it (the disc is then taken on that face, centred
/// at the centre's projection). On such a face square the network's displacement is bilinear in the
/// corners' (the cell's trilinear shape functions restricted to the face), u = Σ_p N_p u_p, so
/// the layer's energy ½ ∫ k(r) |d − u|² dA has the nodal stiffness matrix ∫ N_p N_q k(r) dA I,
/// lumped by rows (Σ_q N_q = 1):
///   K_p = ∫ N_p(X) k(r(X)) dA,  k(r) = k max(0, 1 − r²/a²),  r = |X − centre|,
/// integrated per face square by a quadtree refined towards the rim (squares wholly inside the
/// disc by 3 x 3 Gauss points, exact for the bicubic N_p k; squares cut by the rim halved down to
/// a/1024). Σ_p K_p = ∫ k(r) dA = k π a² / 2 when the faces cover the disc, and
/// Σ_p K_p X_p = ∫ k(r) X dA (bilinear interpolation reproduces linear fields), so the lumped
/// layer has the continuous one's force and centre at any cell size. Returns the nodes with
/// K_p > 0 in node order. Throws std::invalid_argument when the normal is not a coordinate axis,
/// no face of the network lies within h/2 of the centre, or the faces cover less than 99.9 % of
/// ∫ k dA over the disc (the disc reaches past the network's face), naming the reason.
LumpedGraspLayer lump_grasp_layer(const SpringNetwork& net, const GraspLayer& layer);

} // namespace kerf

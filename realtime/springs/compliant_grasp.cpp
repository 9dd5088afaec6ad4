#include "realtime/springs/compliant_grasp.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace kerf {

namespace {

/// ∫ N_c k(r) dA over the part of one face square in the disc, for the square's four corners c
/// (corner c = bu + 2 bv at (u0 + bu h, v0 + bv h)), in the face's coordinates (u, v) with the
/// disc centre at (cu, cv).
class FaceSquareIntegral {
public:
  FaceSquareIntegral(double u0, double v0, double h, double cu, double cv, double a, double k, double finest)
      : m_u0(u0), m_v0(v0), m_h(h), m_cu(cu), m_cv(cv), m_a(a), m_k(k), m_finest(finest) {}

  std::array<double, 4> integrate() {
    m_sum = {0.0, 0.0, 0.0, 0.0};
    add(m_u0, m_v0, m_h);
    return m_sum;
  }

private:
  /// The sub-square [u, u + s] x [v, v + s].
  void add(double u, double v, double s) {
    // Nearest and farthest points of the sub-square from the disc centre.
    const double nu = std::clamp(m_cu, u, u + s) - m_cu, nv = std::clamp(m_cv, v, v + s) - m_cv;
    if (nu * nu + nv * nv >= m_a * m_a) return; // outside the disc: k = 0
    const double fu = std::max(std::abs(u - m_cu), std::abs(u + s - m_cu));
    const double fv = std::max(std::abs(v - m_cv), std::abs(v + s - m_cv));
    if (fu * fu + fv * fv > m_a * m_a && s > m_finest) { // cut by the rim: halve
      const double t = 0.5 * s;
      add(u, v, t), add(u + t, v, t), add(u, v + t, t), add(u + t, v + t, t);
      return;
    }
    // 3 x 3 Gauss–Legendre points: exact for N_c k(r), cubic in each of u and v, inside the disc.
    static constexpr std::array<double, 3> point{-0.7745966692414834, 0.0, 0.7745966692414834};
    static constexpr std::array<double, 3> weight{5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double pu = u + 0.5 * s * (1.0 + point[static_cast<std::size_t>(i)]);
        const double pv = v + 0.5 * s * (1.0 + point[static_cast<std::size_t>(j)]);
        const double r2 = (pu - m_cu) * (pu - m_cu) + (pv - m_cv) * (pv - m_cv);
        // k(r) = k max(0, 1 − r²/a²), times the sub-square's Jacobian (s/2)².
        const double w = weight[static_cast<std::size_t>(i)] * weight[static_cast<std::size_t>(j)] * 0.25 * s * s * m_k *
                         std::max(0.0, 1.0 - r2 / (m_a * m_a));
        const double xi = (pu - m_u0) / m_h, eta = (pv - m_v0) / m_h;
        m_sum[0] += w * (1.0 - xi) * (1.0 - eta);
        m_sum[1] += w * xi * (1.0 - eta);
        m_sum[2] += w * (1.0 - xi) * eta;
        m_sum[3] += w * xi * eta;
      }
  }

  double m_u0, m_v0, m_h, m_cu, m_cv, m_a, m_k, m_finest;
  std::array<double, 4> m_sum{};
};

} // namespace

LumpedGraspLayer lump_grasp_layer(const SpringNetwork& net, const GraspLayer& layer) {
  if (!(layer.radius > 0.0)) throw std::invalid_argument("springs: the compliant grasp's disc radius must be > 0 m");
  if (!(layer.stiffness > 0.0)) throw std::invalid_argument("springs: the compliant grasp's stiffness must be > 0 N/m^3");
  int axis = 0;
  layer.normal.cwiseAbs().maxCoeff(&axis);
  if (!(std::abs(layer.normal[axis]) >= 0.999 * layer.normal.norm()))
    throw std::invalid_argument("springs: a compliant grasp needs the grasped face normal to a coordinate axis (the "
                                "network's faces are); the surface normal at the grasp centre is (" +
                                std::to_string(layer.normal.x()) + ", " + std::to_string(layer.normal.y()) + ", " +
                                std::to_string(layer.normal.z()) + ")");
  const int side = layer.normal[axis] > 0.0 ? 1 : 0; // the cell face at the cell's upper (1) or lower (0) side
  const double h = net.block.cell_size;
  const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
  // The network's face under the centre: the outermost outer face, along the normal, of the kept
  // cells whose face squares hold the centre's projection. It is the body's face when the
  // lattice ends on it, else the lattice plane within h/2 of it that the pruning kept.
  const Eigen::Vector3d local = (layer.centre - net.block.origin) / h;
  const double slack = 1e-9;
  int layer_index = side ? std::numeric_limits<int>::min() : std::numeric_limits<int>::max();
  for (int c = 0; c < net.cell_count(); ++c) {
    const Eigen::Vector3i& g = net.cell_index[static_cast<std::size_t>(c)];
    if (local[u_axis] < g[u_axis] - slack || local[u_axis] > g[u_axis] + 1 + slack || local[v_axis] < g[v_axis] - slack ||
        local[v_axis] > g[v_axis] + 1 + slack)
      continue;
    layer_index = side ? std::max(layer_index, g[axis] + 1) : std::min(layer_index, g[axis]);
  }
  if (layer_index == std::numeric_limits<int>::min() || layer_index == std::numeric_limits<int>::max() ||
      std::abs(layer_index - local[axis]) > 0.5 + 1e-6)
    throw std::invalid_argument("springs: the network has no face within half a cell (" + std::to_string(0.5 * h * 1e3) +
                                " mm) of the compliant grasp's centre (" + std::to_string(layer.centre.x() * 1e3) + ", " +
                                std::to_string(layer.centre.y() * 1e3) + ", " + std::to_string(layer.centre.z() * 1e3) + ") mm");
  const double a = layer.radius;
  const double finest = a / 1024.0;
  std::vector<double> K(static_cast<std::size_t>(net.node_count), 0.0);
  for (int c = 0; c < net.cell_count(); ++c) {
    const Eigen::Vector3i& g = net.cell_index[static_cast<std::size_t>(c)];
    if (g[axis] + side != layer_index) continue;
    Eigen::Vector3i beyond = g;
    beyond[axis] += side ? 1 : -1;
    if (net.cell_at_index(beyond) >= 0) continue; // an inner face
    const Eigen::Vector3d lower = net.block.origin + h * g.cast<double>();
    FaceSquareIntegral square(lower[u_axis], lower[v_axis], h, layer.centre[u_axis], layer.centre[v_axis], a, layer.stiffness, finest);
    const std::array<double, 4> share = square.integrate();
    for (int corner = 0; corner < 4; ++corner) {
      // The cell's local corner with bit `axis` = side, bit u_axis = corner & 1, bit v_axis = corner >> 1.
      const int local = (side << axis) | ((corner & 1) << u_axis) | ((corner >> 1) << v_axis);
      K[static_cast<std::size_t>(net.cell_nodes[static_cast<std::size_t>(c)][static_cast<std::size_t>(local)])] +=
          share[static_cast<std::size_t>(corner)];
    }
  }
  LumpedGraspLayer out;
  double total = 0.0;
  for (int p = 0; p < net.node_count; ++p)
    if (K[static_cast<std::size_t>(p)] > 0.0) {
      out.node.push_back(p);
      out.stiffness.push_back(K[static_cast<std::size_t>(p)]);
      total += K[static_cast<std::size_t>(p)];
    }
  const double disc = layer.stiffness * M_PI * a * a / 2.0; // ∫ k (1 − r²/a²) dA over the disc
  if (total < 0.999 * disc)
    throw std::invalid_argument("springs: the network's face holds " + std::to_string(100.0 * total / disc) +
                                " % of the compliant grasp's layer (disc radius " + std::to_string(a * 1e3) +
                                " mm): the disc reaches past the network (its face is " + std::to_string(h * 1e3) +
                                " mm cells; a larger block or a smaller disc)");
  return out;
}

} // namespace kerf

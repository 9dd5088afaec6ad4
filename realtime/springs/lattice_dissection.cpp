#include "realtime/springs/lattice_dissection.hpp"

#include <stdexcept>

namespace kerf {

namespace {

struct Dissection {
  Eigen::Vector3i points;
  int leaf_points;
  std::vector<int> rank;
  int next = 0;

  void order_naturally(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x)
          rank[static_cast<std::size_t>(x + points.x() * (y + points.y() * z))] = next++;
  }

  /// The box of points lo … hi (inclusive).
  void dissect(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
    const Eigen::Vector3i extent = hi - lo + Eigen::Vector3i::Ones();
    if ((extent.array() <= 0).any()) return;
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (extent[a] > extent[axis]) axis = a;
    if (extent.prod() <= leaf_points || extent[axis] < 3) {
      order_naturally(lo, hi);
      return;
    }
    // Halves below and above the middle plane m, then the plane (it couples to both).
    const int m = (lo[axis] + hi[axis]) / 2;
    Eigen::Vector3i below_hi = hi, above_lo = lo, plane_lo = lo, plane_hi = hi;
    below_hi[axis] = m - 1;
    above_lo[axis] = m + 1;
    plane_lo[axis] = plane_hi[axis] = m;
    dissect(lo, below_hi);
    dissect(above_lo, hi);
    order_naturally(plane_lo, plane_hi);
  }
};

} // namespace

std::vector<int> lattice_nested_dissection(const Eigen::Vector3i& points, int leaf_points) {
  if ((points.array() < 1).any()) throw std::invalid_argument("lattice_nested_dissection: every axis needs at least one point");
  if (leaf_points < 1) throw std::invalid_argument("lattice_nested_dissection: leaf_points must be >= 1");
  Dissection d{points, leaf_points, std::vector<int>(static_cast<std::size_t>(points.prod()), -1), 0};
  d.dissect(Eigen::Vector3i::Zero(), points - Eigen::Vector3i::Ones());
  return d.rank;
}

} // namespace kerf

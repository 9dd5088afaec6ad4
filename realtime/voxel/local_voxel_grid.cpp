#include "realtime/voxel/local_voxel_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

namespace {
/// floor(x) as an int, clamped far outside any grid so the conversion is always defined.
int floor_index(double x) { return static_cast<int>(std::clamp(std::floor(x), -1e9, 1e9)); }
} // namespace

int LocalVoxelGrid::cell_index(double x) const { return floor_index(x / m_h); }

LocalVoxelGrid::LocalVoxelGrid(std::array<int, 3> cells, double cell_size, int triangle_capacity)
    : m_cells(cells), m_h(cell_size), m_triangle_capacity(triangle_capacity) {
  for (int k = 0; k < 3; ++k)
    if (cells[static_cast<std::size_t>(k)] < 1 || cells[static_cast<std::size_t>(k)] > 100000)
      throw std::invalid_argument("local voxel grid: cell count " + std::to_string(k) + " must be in [1, 100000]");
  if (!(cell_size > 0.0) || !std::isfinite(cell_size))
    throw std::invalid_argument("local voxel grid: cell size must be positive");
  if (triangle_capacity < 1) throw std::invalid_argument("local voxel grid: triangle capacity must be >= 1");
  const std::size_t columns = static_cast<std::size_t>(cells[1]) * static_cast<std::size_t>(cells[2]);
  m_surface.assign(columns, no_material);
  m_previous.assign(columns, no_material);
  m_hit_depth.assign(columns, no_material);
  m_hit_exit.assign(columns, 0);
  m_triangles.assign(static_cast<std::size_t>(triangle_capacity), -1);
  m_vertices.assign(3 * static_cast<std::size_t>(triangle_capacity), -1);
}

bool LocalVoxelGrid::column_at(double a, double b, int& i, int& j) const {
  if (!std::isfinite(a) || !std::isfinite(b)) return false;
  const double fi = std::floor(a / m_h) - m_column_u;
  const double fj = std::floor(b / m_h) - m_column_v;
  if (fi < 0.0 || fj < 0.0 || fi >= m_cells[1] || fj >= m_cells[2]) return false;
  i = static_cast<int>(fi);
  j = static_cast<int>(fj);
  return true;
}

bool LocalVoxelGrid::occupied(int i, int j, int k) const {
  const double centre = (m_layer_top + k + 0.5) * m_h;
  return centre > surface_depth(i, j);
}

bool LocalVoxelGrid::place(const VoxelFrame& frame, int column_u, int column_v, int layer_top,
                           const Eigen::MatrixXd& vertices, const Eigen::MatrixXi& triangles, const AabbTree& tree,
                           double slack, bool keep_overlap) noexcept {
  const bool overlap = keep_overlap && m_placed;
  const int old_u = m_column_u, old_v = m_column_v;
  if (overlap) std::copy(m_surface.begin(), m_surface.end(), m_previous.begin());
  m_frame = frame;
  m_column_u = column_u;
  m_column_v = column_v;
  m_layer_top = layer_top;
  m_placed = true;

  // The ray window: from one grid depth above both the grid's top and the frame origin's
  // tangent plane (where the untouched surface lies), down to the grid's bottom.
  const double w_bottom = (layer_top + m_cells[0]) * m_h;
  const double w_top = std::min(layer_top * m_h, 0.0) - m_cells[0] * m_h;
  const double a_lo = column_u * m_h, a_hi = (column_u + m_cells[1]) * m_h;
  const double b_lo = column_v * m_h, b_hi = (column_v + m_cells[2]) * m_h;

  // The neighbourhood: triangles whose (stale, hence widened by `slack`) boxes meet the grid's.
  Eigen::AlignedBox3d box;
  for (int corner = 0; corner < 8; ++corner) {
    const double w = (corner & 1) ? w_bottom : w_top;
    const double a = (corner & 2) ? a_hi : a_lo;
    const double b = (corner & 4) ? b_hi : b_lo;
    box.extend(frame.origin + w * frame.depth_axis + a * frame.u_axis + b * frame.v_axis);
  }
  box.min().array() -= slack + 1e-12;
  box.max().array() += slack + 1e-12;
  m_triangle_count = 0;
  m_vertex_count = 0;
  bool complete = true;
  tree.for_each_overlapping(box, [&](int f) {
    if (m_triangle_count >= m_triangle_capacity) {
      complete = false;
      return;
    }
    m_triangles[static_cast<std::size_t>(m_triangle_count++)] = f;
    for (int c = 0; c < 3; ++c) m_vertices[static_cast<std::size_t>(m_vertex_count++)] = triangles(f, c);
  });

  // Cast every column's centre line (direction +depth_axis) against the neighbourhood: each
  // triangle is projected onto the (a, b) plane and tested only against the columns its
  // projection covers; the nearest crossing below w_top decides the surface point.
  std::fill(m_hit_depth.begin(), m_hit_depth.end(), no_material);
  std::fill(m_hit_exit.begin(), m_hit_exit.end(), 0);
  for (int t = 0; t < m_triangle_count; ++t) {
    const int f = m_triangles[static_cast<std::size_t>(t)];
    Eigen::Vector3d p[3];
    for (int c = 0; c < 3; ++c) p[c] = frame.local(vertices.row(triangles(f, c)).transpose());
    // Signed doubled area of the projection; a triangle seen edge-on is parallel to the ray.
    const double area = (p[1].y() - p[0].y()) * (p[2].z() - p[0].z()) - (p[2].y() - p[0].y()) * (p[1].z() - p[0].z());
    if (std::abs(area) < 1e-30) continue;
    // Outward normal along the depth axis > 0: the line leaves the body through this triangle.
    const Eigen::Vector3d x0 = vertices.row(triangles(f, 0)).transpose();
    const Eigen::Vector3d x1 = vertices.row(triangles(f, 1)).transpose();
    const Eigen::Vector3d x2 = vertices.row(triangles(f, 2)).transpose();
    const Eigen::Vector3d world_normal = (x1 - x0).cross(x2 - x0);
    const bool exit = world_normal.dot(frame.depth_axis) > 0.0;
    const double pa_lo = std::min({p[0].y(), p[1].y(), p[2].y()}), pa_hi = std::max({p[0].y(), p[1].y(), p[2].y()});
    const double pb_lo = std::min({p[0].z(), p[1].z(), p[2].z()}), pb_hi = std::max({p[0].z(), p[1].z(), p[2].z()});
    const int i0 = std::max(0, floor_index(pa_lo / m_h - 0.5) - column_u);
    const int i1 = std::min(m_cells[1] - 1, floor_index(pa_hi / m_h - 0.5) + 1 - column_u);
    const int j0 = std::max(0, floor_index(pb_lo / m_h - 0.5) - column_v);
    const int j1 = std::min(m_cells[2] - 1, floor_index(pb_hi / m_h - 0.5) + 1 - column_v);
    for (int i = i0; i <= i1; ++i) {
      const double a = (column_u + i + 0.5) * m_h;
      for (int j = j0; j <= j1; ++j) {
        const double b = (column_v + j + 0.5) * m_h;
        // Barycentric coordinates of (a, b) in the projected triangle (inclusive edges).
        const double l1 = ((a - p[0].y()) * (p[2].z() - p[0].z()) - (p[2].y() - p[0].y()) * (b - p[0].z())) / area;
        const double l2 = ((p[1].y() - p[0].y()) * (b - p[0].z()) - (a - p[0].y()) * (p[1].z() - p[0].z())) / area;
        const double l0 = 1.0 - l1 - l2;
        constexpr double eps = -1e-12;
        if (l0 < eps || l1 < eps || l2 < eps) continue;
        const double w = l0 * p[0].x() + l1 * p[1].x() + l2 * p[2].x();
        if (w < w_top || w > w_bottom) continue;
        const std::size_t k = index(i, j);
        if (w < m_hit_depth[k]) {
          m_hit_depth[k] = w;
          m_hit_exit[k] = exit ? 1 : 0;
        }
      }
    }
  }
  for (std::size_t k = 0; k < m_surface.size(); ++k) {
    // Nearest crossing leaves the body: the column is material from above the window on.
    m_surface[k] = m_hit_depth[k] == no_material ? no_material : (m_hit_exit[k] ? w_top : m_hit_depth[k]);
  }
  if (overlap) {
    for (int i = 0; i < m_cells[1]; ++i) {
      const int oi = column_u + i - old_u;
      if (oi < 0 || oi >= m_cells[1]) continue;
      for (int j = 0; j < m_cells[2]; ++j) {
        const int oj = column_v + j - old_v;
        if (oj < 0 || oj >= m_cells[2]) continue;
        m_surface[index(i, j)] = m_previous[index(oi, oj)];
      }
    }
  }
  return complete;
}

double LocalVoxelGrid::lower(int i, int j, double depth, Eigen::MatrixXd& vertices,
                             const Eigen::MatrixXd& original_vertices) noexcept {
  double& s = m_surface[index(i, j)];
  if (!(depth > s) || !std::isfinite(depth)) return 0.0;
  s = depth;
  const double a_lo = a_lower(i), b_lo = b_lower(j);
  double moved = 0.0;
  for (int k = 0; k < m_vertex_count; ++k) {
    const int v = m_vertices[static_cast<std::size_t>(k)];
    const Eigen::Vector3d q = m_frame.local(vertices.row(v).transpose());
    if (q.y() < a_lo || q.y() >= a_lo + m_h || q.z() < b_lo || q.z() >= b_lo + m_h || q.x() >= depth) continue;
    vertices.row(v) += (depth - q.x()) * m_frame.depth_axis.transpose();
    moved = std::max(moved, (vertices.row(v) - original_vertices.row(v)).norm());
  }
  return moved;
}

std::size_t LocalVoxelGrid::memory_bytes() const {
  return sizeof(*this) + (m_surface.capacity() + m_previous.capacity() + m_hit_depth.capacity()) * sizeof(double) +
         m_hit_exit.capacity() * sizeof(unsigned char) + (m_triangles.capacity() + m_vertices.capacity()) * sizeof(int);
}

} // namespace kerf

#pragma once
// LocalVoxelGrid: the voxel structure paper 002 §2.3 step 2 builds "around the contact point
// locally" when the cutting stick touches the polygon surface: a small grid of cubes (10 x 20 x
// 20 in paper 002 §4, instead of 500^3 for the whole body) aligned with the contact's depth
// direction, storing per column the surface point, where the column meets the polygon surface.

#include "meshes/aabb_tree.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

namespace kerf {

/// The frame of one contact episode: `origin` on the body surface where the stick first touched
/// it, `depth_axis` into the body (minus the outward surface normal there), `u_axis` and
/// `v_axis` across it (all unit, right-handed: depth x u = v). Local coordinates of a point are
/// (w, a, b): depth below the origin's tangent plane and the two lateral offsets [m].
struct VoxelFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d depth_axis = -Eigen::Vector3d::UnitZ();
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d v_axis = Eigen::Vector3d::UnitY();

  /// (w, a, b) of world point `p` [m].
  [[nodiscard]] Eigen::Vector3d local(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d r = p - origin;
    return {r.dot(depth_axis), r.dot(u_axis), r.dot(v_axis)};
  }
};

/// A grid of depth_cells x u_cells x v_cells cubes of edge `cell_size`, placed in a VoxelFrame
/// at whole-cell offsets (so that a re-centred grid lines up with the one before it). Each of
/// its u_cells x v_cells columns stores its surface point: the depth w at which the column's
/// centre line enters the body. A cell is material when its centre lies below its column's
/// surface point. Cutting lowers surface points (`lower`) and moves the polygon vertices in the
/// lowered column with them (paper 002 §2.3 step 3), so that the cut outlives the local grid.
///
/// All storage is sized in the constructor from the cell counts and a triangle capacity, never
/// from the body: its memory (`memory_bytes`) is the same for a 1 mm and a 100 mm body, and
/// `build`, `lower` and the queries allocate nothing.
class LocalVoxelGrid {
public:
  /// No material in a column (its line misses the body within the grid's window) [m].
  static constexpr double no_material = 1e300;

  /// `cells` = {depth, u, v} counts (each >= 1), `cell_size` [m] > 0, and the most polygon
  /// triangles the grid's neighbourhood may hold (`triangle_capacity` >= 1). Throws
  /// std::invalid_argument on bad sizes.
  LocalVoxelGrid(std::array<int, 3> cells, double cell_size, int triangle_capacity);

  /// Places the grid in `frame` so that it spans global columns [column_u, column_u + u_cells) x
  /// [column_v, column_v + v_cells) (column I covers a in [I h, (I+1) h)) and depth layers
  /// [layer_top, layer_top + depth_cells), and computes every column's surface point by casting
  /// its centre line, from above both the grid and the frame origin's tangent plane down to the
  /// grid's bottom, against the polygon (`vertices` #V x 3, `triangles` #F x 3, outward)
  /// through `tree` (one box per triangle, as built; `slack` [m] >= the largest distance any
  /// vertex moved since, so stale boxes still find every triangle). Columns this grid shares with
  /// the previous placement in the same frame keep their surface points (`keep_overlap`).
  /// Returns false when the neighbourhood held more than `triangle_capacity` triangles (the
  /// surface points then come from the first triangle_capacity of them).
  bool place(const VoxelFrame& frame, int column_u, int column_v, int layer_top, const Eigen::MatrixXd& vertices,
             const Eigen::MatrixXi& triangles, const AabbTree& tree, double slack, bool keep_overlap) noexcept;

  /// The frame of the last placement.
  [[nodiscard]] const VoxelFrame& frame() const { return m_frame; }
  /// Edge of a cell = the advance length [m].
  [[nodiscard]] double cell_size() const { return m_h; }
  /// Cell counts along the depth axis, u and v.
  [[nodiscard]] int depth_cells() const { return m_cells[0]; }
  [[nodiscard]] int u_cells() const { return m_cells[1]; }
  [[nodiscard]] int v_cells() const { return m_cells[2]; }
  /// True once `place` has run.
  [[nodiscard]] bool placed() const { return m_placed; }
  /// Global cell index floor(x / h) of a local coordinate x [m], clamped to ±1e9 (defined for
  /// any input).
  [[nodiscard]] int cell_index(double x) const;
  /// First global column along u and v, first depth layer.
  [[nodiscard]] int column_u() const { return m_column_u; }
  [[nodiscard]] int column_v() const { return m_column_v; }
  [[nodiscard]] int layer_top() const { return m_layer_top; }

  /// Grid column (i, j) holding lateral position (a, b); false outside the grid.
  [[nodiscard]] bool column_at(double a, double b, int& i, int& j) const;
  /// Lateral bounds of column (i, j): a in [a_lower, a_lower + h), b likewise [m].
  [[nodiscard]] double a_lower(int i) const { return (m_column_u + i) * m_h; }
  [[nodiscard]] double b_lower(int j) const { return (m_column_v + j) * m_h; }
  /// Surface point of column (i, j): depth w where material begins [m] (no_material if none).
  [[nodiscard]] double surface_depth(int i, int j) const { return m_surface[index(i, j)]; }
  /// True if cell (i, j, k) (k counted down from layer_top) is material: its centre lies below
  /// its column's surface point.
  [[nodiscard]] bool occupied(int i, int j, int k) const;

  /// Removes material of column (i, j) down to depth `depth` (no-op if the surface point is
  /// already that deep): the surface point becomes `depth` and every polygon vertex of the grid's
  /// neighbourhood inside the column's footprint and above `depth` moves along the depth axis
  /// onto it (paper 002 §2.3 step 3, "renew the position of polygon vertex"). Returns the
  /// largest distance of a moved vertex from its position in `original_vertices` [m] (0 if none
  /// moved).
  double lower(int i, int j, double depth, Eigen::MatrixXd& vertices, const Eigen::MatrixXd& original_vertices) noexcept;

  /// Bytes held by the grid (surface points, scratch, neighbourhood buffers): fixed at
  /// construction by the cell counts and the triangle capacity.
  [[nodiscard]] std::size_t memory_bytes() const;

private:
  [[nodiscard]] std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(i) * static_cast<std::size_t>(m_cells[2]) + static_cast<std::size_t>(j);
  }

  std::array<int, 3> m_cells;
  double m_h;
  int m_triangle_capacity;
  VoxelFrame m_frame;
  bool m_placed = false;
  int m_column_u = 0, m_column_v = 0, m_layer_top = 0;
  std::vector<double> m_surface;       ///< u_cells * v_cells surface points [m]
  std::vector<double> m_previous;      ///< the placement before, for keep_overlap
  std::vector<double> m_hit_depth;     ///< ray-cast scratch: nearest crossing per column
  std::vector<unsigned char> m_hit_exit; ///< ray-cast scratch: that crossing leaves the body
  std::vector<int> m_triangles;        ///< the neighbourhood's triangles (capacity fixed)
  std::vector<int> m_vertices;         ///< their vertices, with repeats (capacity 3x)
  int m_triangle_count = 0;
  int m_vertex_count = 0;
};

} // namespace kerf

#include "realtime/springs/lattice_forces.hpp"

#include "realtime/springs/vector_clones.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace kerf {

namespace {

/// The 13 lattice directions of the 28 cell springs, each with its first non-zero component
/// positive: 3 edges, 6 face diagonals, 4 body diagonals.
constexpr std::array<std::array<int, 3>, 13> directions{{{1, 0, 0},  {0, 1, 0},  {0, 0, 1},  {1, 1, 0},  {1, -1, 0},
                                                         {1, 0, 1},  {1, 0, -1}, {0, 1, 1},  {0, 1, -1}, {1, 1, 1},
                                                         {1, 1, -1}, {1, -1, 1}, {1, -1, -1}}};

/// The deformation gradient of one lattice cell, F = c Σ_a x_a ⊗ s_a (c = 1/(4h), s_a the corner
/// signs), read column by column from coordinate planes: `o` are the lattice offsets of corners
/// 1..7 from corner 0 (the cell's lower corner p).
struct CellGradient {
  int o1, o2, o3, o4, o5, o6, o7;
  double c;
  CellGradient(const int* corner, double c_)
      : o1(corner[1]), o2(corner[2]), o3(corner[3]), o4(corner[4]), o5(corner[5]), o6(corner[6]), o7(corner[7]), c(c_) {}
  /// Column i of c Σ_a w_a ⊗ s_a from one coordinate plane W (the row).
  [[gnu::always_inline]] double column(const double* __restrict W, int p, int i) const {
    switch (i) {
    case 0: return c * ((W[p + o1] - W[p]) + (W[p + o3] - W[p + o2]) + (W[p + o5] - W[p + o4]) + (W[p + o7] - W[p + o6]));
    case 1: return c * ((W[p + o2] - W[p]) + (W[p + o3] - W[p + o1]) + (W[p + o6] - W[p + o4]) + (W[p + o7] - W[p + o5]));
    default: return c * ((W[p + o4] - W[p]) + (W[p + o5] - W[p + o1]) + (W[p + o6] - W[p + o2]) + (W[p + o7] - W[p + o3]));
    }
  }
  /// F's first column a = (ax, ay, az) and cof(F) = [b × d, d × a, a × b] (columns c0, c1, c2),
  /// F's columns a (i = 0), b (1), d (2) read from the position planes X, Y, Z (rows x, y, z).
  struct Cofactor {
    double ax, ay, az, c0x, c0y, c0z, c1x, c1y, c1z, c2x, c2y, c2z;
  };
  [[gnu::always_inline]] Cofactor cofactor(const double* __restrict X, const double* __restrict Y, const double* __restrict Z, int p) const {
    const double ax = column(X, p, 0), ay = column(Y, p, 0), az = column(Z, p, 0);
    const double bx = column(X, p, 1), by = column(Y, p, 1), bz = column(Z, p, 1);
    const double dx = column(X, p, 2), dy = column(Y, p, 2), dz = column(Z, p, 2);
    return {ax, ay, az, by * dz - bz * dy, bz * dx - bx * dz, bx * dy - by * dx, dy * az - dz * ay, dz * ax - dx * az, dx * ay - dy * ax,
            ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx};
  }
};

/// One spring's force on its start point p and its elastic energy: the spring from p to q.
template <class Real>
struct SpringForce {
  Real x, y, z; ///< f_a [N]; the end point q takes −f_a
  Real energy;  ///< ½ k (l − L)² [J]
};

/// The spring from lattice point p to q = p + o, with stiffness kp, in double precision on
/// absolute positions X and velocities V (one plane per coordinate), the law of cell_forces
/// (spring_network.cpp; paper 000 §2.1's springs, with the scene's Kelvin–Voigt damping time τ):
///   f_a = k (l − L) d + τ k ((v_b − v_a)·d) d,  d = e / l,  e = x_b − x_a,
/// and no force (nor energy) when the ends coincide (l ≤ tiny: no direction).
[[gnu::always_inline]] inline SpringForce<double> spring_force(int p, int q, double kp, double rest, double tau, double tiny,
                                                               const double* __restrict X, const double* __restrict Y,
                                                               const double* __restrict Z, const double* __restrict VX,
                                                               const double* __restrict VY, const double* __restrict VZ) {
  const double ex = X[q] - X[p], ey = Y[q] - Y[p], ez = Z[q] - Z[p];
  const double l = std::sqrt(ex * ex + ey * ey + ez * ez);
  const double inv_l = l > tiny ? 1.0 / l : 0.0;
  const double stretch = l - rest;
  const double rate = (VX[q] - VX[p]) * ex + (VY[q] - VY[p]) * ey + (VZ[q] - VZ[p]) * ez;
  const double scale = kp * (stretch + tau * rate * inv_l) * inv_l;
  return {scale * ex, scale * ey, scale * ez, inv_l > 0.0 ? 0.5 * kp * stretch * stretch : 0.0};
}

/// The same spring in single precision on displacements from the lattice's rest positions
/// (U = x − X, so that the spring vector e = h o_d + (U[q] − U[p]) keeps the displacement's
/// digits, where single-precision absolute positions would lose them; (ox, oy, oz) = h o_d), with
/// the stretch written without cancellation, l − L = (2 L_vec·Δu + |Δu|²) / (l + L).
[[gnu::always_inline]] inline SpringForce<float> spring_force(int p, int q, float kp, float ox, float oy, float oz, float rest,
                                                              float tau, float tiny, const float* __restrict UX,
                                                              const float* __restrict UY, const float* __restrict UZ,
                                                              const float* __restrict VX, const float* __restrict VY,
                                                              const float* __restrict VZ) {
  const float ux = UX[q] - UX[p], uy = UY[q] - UY[p], uz = UZ[q] - UZ[p];
  const float ex = ox + ux, ey = oy + uy, ez = oz + uz;
  const float l = std::sqrt(ex * ex + ey * ey + ez * ez);
  // One division for both quotients: w = 1 / (l (l + L)), 1/l = (l + L) w, 1/(l + L) = l w.
  const bool apart = l > tiny;
  const float w = 1.0f / (apart ? l * (l + rest) : 1.0f);
  const float inv_l = apart ? (l + rest) * w : 0.0f;
  // l − L = (l² − L²)/(l + L),  l² − L² = 2 L_vec·Δu + |Δu|²
  const float stretch = (2.0f * (ox * ux + oy * uy + oz * uz) + (ux * ux + uy * uy + uz * uz)) * (l * w);
  const float rate = (VX[q] - VX[p]) * ex + (VY[q] - VY[p]) * ey + (VZ[q] - VZ[p]) * ez;
  const float scale = kp * (stretch + tau * rate * inv_l) * inv_l;
  return {scale * ex, scale * ey, scale * ez, inv_l > 0.0f ? 0.5f * kp * stretch * stretch : 0.0f};
}

/// The springs of one lattice direction, from lattice points p in [begin, end) to p + o: adds
/// each spring's force on its start point to F and stores it in G (the end point takes −G, in
/// direction_ends). Returns their elastic energy [J].
KERF_VECTOR_CLONES
double direction_springs(int begin, int end, int o, double rest, double tau, double tiny, const double* __restrict k,
                         const double* __restrict X, const double* __restrict Y, const double* __restrict Z,
                         const double* __restrict VX, const double* __restrict VY, const double* __restrict VZ,
                         double* __restrict FX, double* __restrict FY, double* __restrict FZ, double* __restrict GX,
                         double* __restrict GY, double* __restrict GZ) {
  double energy = 0.0;
#pragma omp simd reduction(+ : energy)
  for (int p = begin; p < end; ++p) {
    const SpringForce<double> g = spring_force(p, p + o, k[p], rest, tau, tiny, X, Y, Z, VX, VY, VZ);
    FX[p] += g.x, FY[p] += g.y, FZ[p] += g.z;
    GX[p] = g.x, GY[p] = g.y, GZ[p] = g.z;
    energy += g.energy;
  }
  return energy;
}

/// direction_springs with the end points' share taken in the same loop (F[p + o] −= the
/// force), for directions whose offset |o| is at least the widest SIMD width in double
/// precision (8 lanes): then no two lanes of one vector touch the same point, and `safelen(8)`
/// lets the loop vectorise although F is read and written at p and at p + o (every direction
/// but the lattice's x edges once a row has 8 points or more). Returns the elastic energy [J].
KERF_VECTOR_CLONES
double direction_springs_fused(int begin, int end, int o, double rest, double tau, double tiny, const double* __restrict k,
                               const double* __restrict X, const double* __restrict Y, const double* __restrict Z,
                               const double* __restrict VX, const double* __restrict VY, const double* __restrict VZ, double* FX,
                               double* FY, double* FZ) {
  double energy = 0.0;
#pragma omp simd reduction(+ : energy) safelen(8)
  for (int p = begin; p < end; ++p) {
    const SpringForce<double> g = spring_force(p, p + o, k[p], rest, tau, tiny, X, Y, Z, VX, VY, VZ);
    FX[p] += g.x, FY[p] += g.y, FZ[p] += g.z;
    FX[p + o] -= g.x, FY[p + o] -= g.y, FZ[p + o] -= g.z;
    energy += g.energy;
  }
  return energy;
}

/// F[p + o] −= G[p] for p in [begin, end): the end points' share of one direction's springs.
template <class Real>
[[gnu::always_inline]] inline void direction_ends_of(int begin, int end, int o, const Real* __restrict GX, const Real* __restrict GY,
                                                     const Real* __restrict GZ, Real* __restrict FX, Real* __restrict FY,
                                                     Real* __restrict FZ) {
#pragma omp simd
  for (int p = begin; p < end; ++p) {
    FX[p + o] -= GX[p];
    FY[p + o] -= GY[p];
    FZ[p + o] -= GZ[p];
  }
}
KERF_VECTOR_CLONES
void direction_ends(int begin, int end, int o, const double* __restrict GX, const double* __restrict GY,
                    const double* __restrict GZ, double* __restrict FX, double* __restrict FY, double* __restrict FZ) {
  direction_ends_of(begin, end, o, GX, GY, GZ, FX, FY, FZ);
}
KERF_VECTOR_CLONES
void direction_ends_single(int begin, int end, int o, const float* __restrict GX, const float* __restrict GY,
                           const float* __restrict GZ, float* __restrict FX, float* __restrict FY, float* __restrict FZ) {
  direction_ends_of(begin, end, o, GX, GY, GZ, FX, FY, FZ);
}

/// direction_springs in single precision (spring_force on displacements U): forces into F
/// (single), the end points' share into G; returns the elastic energy [J].
KERF_VECTOR_CLONES
float direction_springs_single(int begin, int end, int o, float ox, float oy, float oz, float rest, float tau, float tiny,
                               const float* __restrict k, const float* __restrict UX, const float* __restrict UY,
                               const float* __restrict UZ, const float* __restrict VX, const float* __restrict VY,
                               const float* __restrict VZ, float* __restrict FX, float* __restrict FY, float* __restrict FZ,
                               float* __restrict GX, float* __restrict GY, float* __restrict GZ) {
  float energy = 0.0f;
#pragma omp simd reduction(+ : energy)
  for (int p = begin; p < end; ++p) {
    const SpringForce<float> g = spring_force(p, p + o, k[p], ox, oy, oz, rest, tau, tiny, UX, UY, UZ, VX, VY, VZ);
    FX[p] += g.x, FY[p] += g.y, FZ[p] += g.z;
    GX[p] = g.x, GY[p] = g.y, GZ[p] = g.z;
    energy += g.energy;
  }
  return energy;
}

/// direction_springs_single with the end points' share taken in the same loop (F[p + o] −= the
/// force), for directions whose offset |o| is at least the widest SIMD width in single precision
/// (16 lanes): then no two lanes of one vector touch the same point, and `safelen(16)` lets the
/// loop vectorise although F is read and written at p and at p + o. Returns the elastic energy [J].
KERF_VECTOR_CLONES
float direction_springs_single_fused(int begin, int end, int o, float ox, float oy, float oz, float rest, float tau, float tiny,
                                     const float* __restrict k, const float* __restrict UX, const float* __restrict UY,
                                     const float* __restrict UZ, const float* __restrict VX, const float* __restrict VY,
                                     const float* __restrict VZ, float* FX, float* FY, float* FZ) {
  float energy = 0.0f;
#pragma omp simd reduction(+ : energy) safelen(16)
  for (int p = begin; p < end; ++p) {
    const SpringForce<float> g = spring_force(p, p + o, k[p], ox, oy, oz, rest, tau, tiny, UX, UY, UZ, VX, VY, VZ);
    FX[p] += g.x, FY[p] += g.y, FZ[p] += g.z;
    FX[p + o] -= g.x, FY[p + o] -= g.y, FZ[p + o] -= g.z;
    energy += g.energy;
  }
  return energy;
}

/// The volume forces on corners 0..3 of one cell, f_a = −P c cof(F) s_a (s_a the corner signs,
/// s_0 = (−,−,−), s_1 = (+,−,−), s_2 = (−,+,−), s_3 = (+,+,−)), into 12 planes of `stride`
/// entries (plane 3 a + r: corner a, row r), at W; corner 7 − a takes −f_a (s_{7−a} = −s_a):
///   f_0 = pc (c_0 + c_1 + c_2),  f_1 = pc (c_2 + c_1 − c_0),  f_2 = pc (c_2 − c_1 + c_0),
///   f_3 = pc (c_2 − c_1 − c_0),   with pc = P c and c_i column i of cof(F).
template <class Real>
[[gnu::always_inline]] inline void corner_forces(Real pc, Real c0x, Real c0y, Real c0z, Real c1x, Real c1y, Real c1z, Real c2x,
                                                 Real c2y, Real c2z, Real* __restrict W, int stride) {
  const Real c0[3] = {c0x, c0y, c0z}, c1[3] = {c1x, c1y, c1z}, c2[3] = {c2x, c2y, c2z};
  for (int r = 0; r < 3; ++r) {
    const Real sum = c0[r] + c1[r], difference = c0[r] - c1[r];
    W[r * stride] = pc * (c2[r] + sum);
    W[(3 + r) * stride] = pc * (c2[r] - difference);
    W[(6 + r) * stride] = pc * (c2[r] + difference);
    W[(9 + r) * stride] = pc * (c2[r] - sum);
  }
}

/// cell_volumes in single precision on displacements U = x − X: F = I + G with G = c Σ_a u_a ⊗ s_a,
/// and J − 1 = det(I + G) − 1 = tr G + I₂(G) + det G (I₂ the second invariant), without the
/// cancellation of det F − 1 in single precision.
KERF_VECTOR_CLONES
float cell_volumes_single(int end, const int* corner, float c, float kappa_v0, float tau, const float* __restrict mask,
                          const float* __restrict UX, const float* __restrict UY, const float* __restrict UZ,
                          const float* __restrict VX, const float* __restrict VY, const float* __restrict VZ,
                          float* __restrict Q, int stride, int pad) {
  float energy = 0.0f;
  const int o1 = corner[1], o2 = corner[2], o3 = corner[3], o4 = corner[4], o5 = corner[5], o6 = corner[6], o7 = corner[7];
  const auto column = [=](const float* __restrict W, int p, int i) -> float {
    switch (i) {
    case 0: return c * ((W[p + o1] - W[p]) + (W[p + o3] - W[p + o2]) + (W[p + o5] - W[p + o4]) + (W[p + o7] - W[p + o6]));
    case 1: return c * ((W[p + o2] - W[p]) + (W[p + o3] - W[p + o1]) + (W[p + o6] - W[p + o4]) + (W[p + o7] - W[p + o5]));
    default: return c * ((W[p + o4] - W[p]) + (W[p + o5] - W[p + o1]) + (W[p + o6] - W[p + o2]) + (W[p + o7] - W[p + o3]));
    }
  };
#pragma omp simd reduction(+ : energy)
  for (int p = 0; p < end; ++p) {
    // G columns (i = 0, 1, 2), rows x, y, z: G_ri.
    const float g00 = column(UX, p, 0), g10 = column(UY, p, 0), g20 = column(UZ, p, 0);
    const float g01 = column(UX, p, 1), g11 = column(UY, p, 1), g21 = column(UZ, p, 1);
    const float g02 = column(UX, p, 2), g12 = column(UY, p, 2), g22 = column(UZ, p, 2);
    // F = I + G: columns a, b, d.
    const float ax = 1.0f + g00, ay = g10, az = g20;
    const float bx = g01, by = 1.0f + g11, bz = g21;
    const float dx = g02, dy = g12, dz = 1.0f + g22;
    const float c0x = by * dz - bz * dy, c0y = bz * dx - bx * dz, c0z = bx * dy - by * dx;
    const float c1x = dy * az - dz * ay, c1y = dz * ax - dx * az, c1z = dx * ay - dy * ax;
    const float c2x = ay * bz - az * by, c2y = az * bx - ax * bz, c2z = ax * by - ay * bx;
    // J − 1 = tr G + I₂(G) + det G
    const float trace = g00 + g11 + g22;
    const float second = (g00 * g11 - g01 * g10) + (g11 * g22 - g12 * g21) + (g00 * g22 - g02 * g20);
    const float det = g00 * (g11 * g22 - g12 * g21) - g01 * (g10 * g22 - g12 * g20) + g02 * (g10 * g21 - g11 * g20);
    const float j_minus_1 = trace + (second + det);
    const float J_rate = c0x * column(VX, p, 0) + c0y * column(VY, p, 0) + c0z * column(VZ, p, 0) +
                         c1x * column(VX, p, 1) + c1y * column(VY, p, 1) + c1z * column(VZ, p, 1) +
                         c2x * column(VX, p, 2) + c2y * column(VY, p, 2) + c2z * column(VZ, p, 2);
    const float pc = mask[p] * kappa_v0 * (j_minus_1 + tau * J_rate) * c;
    corner_forces(pc, c0x, c0y, c0z, c1x, c1y, c1z, c2x, c2y, c2z, Q + pad + p, stride);
    energy += 0.5f * kappa_v0 * mask[p] * j_minus_1 * j_minus_1;
  }
  return energy;
}

/// The volume term of the cells starting at lattice points [0, end) (mask 1 where a cell
/// exists): with c = 1/(4h) and the corner offsets o_a,
///   F = c Σ_a x_a ⊗ s_a,  Ḟ = c Σ_a v_a ⊗ s_a,  J = det F,  J̇ = Σ_i cof(F)_i · Ḟ_i,
///   P = κ V₀ ((J − 1) + τ J̇),  f_a = −P cof(F) g_a  (g_a = c s_a, s_a the corner signs),
/// the forces on corners 0..3 written to Q (corner_forces: 12 planes of `stride` entries, at
/// pad + p; corner 7 − a takes −f_a).
/// Returns the cells' energy Σ ½ κ V₀ (J − 1)² [J].
KERF_VECTOR_CLONES
double cell_volumes(int end, const int* corner, double c, double kappa_v0, double tau, const double* __restrict mask,
                    const double* __restrict X, const double* __restrict Y, const double* __restrict Z,
                    const double* __restrict VX, const double* __restrict VY, const double* __restrict VZ,
                    double* __restrict Q, int stride, int pad) {
  double energy = 0.0;
  const CellGradient cell{corner, c};
#pragma omp simd reduction(+ : energy)
  for (int p = 0; p < end; ++p) {
    const auto [ax, ay, az, c0x, c0y, c0z, c1x, c1y, c1z, c2x, c2y, c2z] = cell.cofactor(X, Y, Z, p);
    const double J = ax * c0x + ay * c0y + az * c0z;
    const double J_rate = c0x * cell.column(VX, p, 0) + c0y * cell.column(VY, p, 0) + c0z * cell.column(VZ, p, 0) +
                          c1x * cell.column(VX, p, 1) + c1y * cell.column(VY, p, 1) + c1z * cell.column(VZ, p, 1) +
                          c2x * cell.column(VX, p, 2) + c2y * cell.column(VY, p, 2) + c2z * cell.column(VZ, p, 2);
    // P c = κ V₀ ((J − 1) + τ J̇) c, masked to the cells that exist
    const double pc = mask[p] * kappa_v0 * ((J - 1.0) + tau * J_rate) * c;
    corner_forces(pc, c0x, c0y, c0z, c1x, c1y, c1z, c2x, c2y, c2z, Q + pad + p, stride);
    energy += 0.5 * kappa_v0 * mask[p] * (J - 1.0) * (J - 1.0);
  }
  return energy;
}

/// F_r[q] += Σ_a f_{a,r}[q − o_a] for lattice points q in [0, points), with the corner forces
/// of corner_forces (planes W_a = Q + 3 a stride + pad, f_{7−a} = −f_a): each point collects
/// the volume forces of the (up to 8) cells it is a corner of, in one pass per row r (8 reads,
/// one update of F_r per point).
template <class Real>
[[gnu::always_inline]] inline void cell_volume_forces_of(int points, const int* corner, const Real* __restrict Q, int stride, int pad,
                                                         Real* __restrict FX, Real* __restrict FY, Real* __restrict FZ) {
  Real* F[3] = {FX, FY, FZ};
  const int o1 = corner[1], o2 = corner[2], o3 = corner[3], o4 = corner[4], o5 = corner[5], o6 = corner[6], o7 = corner[7];
  for (int r = 0; r < 3; ++r) {
    const Real* __restrict W0 = Q + r * stride + pad;
    const Real* __restrict W1 = Q + (3 + r) * stride + pad;
    const Real* __restrict W2 = Q + (6 + r) * stride + pad;
    const Real* __restrict W3 = Q + (9 + r) * stride + pad;
    Real* __restrict Fr = F[r];
#pragma omp simd
    for (int q = 0; q < points; ++q)
      // corner a of the cell at q − o_a; corners 4..7 take −f_3, −f_2, −f_1, −f_0
      Fr[q] += ((W0[q] + W1[q - o1]) + (W2[q - o2] + W3[q - o3])) - ((W3[q - o4] + W2[q - o5]) + (W1[q - o6] + W0[q - o7]));
  }
}
KERF_VECTOR_CLONES
void cell_volume_forces(int points, const int* corner, const double* __restrict Q, int stride, int pad, double* __restrict FX,
                        double* __restrict FY, double* __restrict FZ) {
  cell_volume_forces_of(points, corner, Q, stride, pad, FX, FY, FZ);
}
KERF_VECTOR_CLONES
void cell_volume_forces_single(int points, const int* corner, const float* __restrict Q, int stride, int pad, float* __restrict FX,
                               float* __restrict FY, float* __restrict FZ) {
  cell_volume_forces_of(points, corner, Q, stride, pad, FX, FY, FZ);
}

/// Gershgorin row sums of one lattice direction's springs, p in [begin, end) to p + o:
///   r = 2 k max(1, |1 − L/l|)  (l = 0: the crushed limit, 2 k 10⁶),
/// added to R at the start point and stored in S for the end point.
KERF_VECTOR_CLONES
void direction_rows(int begin, int end, int o, double rest, const double* __restrict k, const double* __restrict X,
                    const double* __restrict Y, const double* __restrict Z, double* __restrict R, double* __restrict S) {
#pragma omp simd
  for (int p = begin; p < end; ++p) {
    const int q = p + o;
    const double ex = X[q] - X[p], ey = Y[q] - Y[p], ez = Z[q] - Z[p];
    const double l = std::sqrt(ex * ex + ey * ey + ez * ez);
    const double row = 2.0 * k[p] * std::max(1.0, l > 0.0 ? std::abs(1.0 - rest / l) : 1e6);
    R[p] += row;
    S[p] = row;
  }
}

/// R[p + o] += S[p] for p in [begin, end): the end points' share of one direction's rows.
KERF_VECTOR_CLONES
void direction_row_ends(int begin, int end, int o, const double* __restrict S, double* __restrict R) {
#pragma omp simd
  for (int p = begin; p < end; ++p) R[p + o] += S[p];
}

/// Gershgorin row sums of the cells' volume term (cells starting at [0, end), mask 1 where a
/// cell exists): with F = c Σ_a x_a ⊗ s_a (c = 1/(4h)), n_a = c |cof(F) s_a| = |∇_a J| and
/// T = Σ_b n_b, corner a of the cell takes κ h³ n_a T, written to plane a of N (8 planes of
/// `stride`, at pad + p).
KERF_VECTOR_CLONES
void cell_rows(int end, const int* corner, double c, double kappa_v0, const double* __restrict mask, const double* __restrict X,
               const double* __restrict Y, const double* __restrict Z, double* __restrict N, int stride, int pad) {
  const CellGradient cell{corner, c};
#pragma omp simd
  for (int p = 0; p < end; ++p) {
    // cof(F) s_a = Σ_i s_a[i] cof_i
    const auto [ax, ay, az, c0x, c0y, c0z, c1x, c1y, c1z, c2x, c2y, c2z] = cell.cofactor(X, Y, Z, p);
    double n[8];
    double total = 0.0;
    for (int a = 0; a < 8; ++a) {
      const double s0 = (a & 1) ? 1.0 : -1.0, s1 = (a & 2) ? 1.0 : -1.0, s2 = (a & 4) ? 1.0 : -1.0;
      const double gx = s0 * c0x + s1 * c1x + s2 * c2x, gy = s0 * c0y + s1 * c1y + s2 * c2y, gz = s0 * c0z + s1 * c1z + s2 * c2z;
      n[a] = c * std::sqrt(gx * gx + gy * gy + gz * gz);
      total += n[a];
    }
    for (int a = 0; a < 8; ++a) N[a * stride + pad + p] = mask[p] * kappa_v0 * n[a] * total;
  }
}

/// R[q] += Σ_a N_a[pad + q − o_a] for lattice points q in [0, points).
KERF_VECTOR_CLONES
void cell_row_ends(int points, const int* corner, const double* __restrict N, int stride, int pad, double* __restrict R) {
  const int o1 = corner[1], o2 = corner[2], o3 = corner[3], o4 = corner[4], o5 = corner[5], o6 = corner[6], o7 = corner[7];
  const double* __restrict N0 = N + pad;
  const double* __restrict N1 = N + stride + pad;
  const double* __restrict N2 = N + 2 * stride + pad;
  const double* __restrict N3 = N + 3 * stride + pad;
  const double* __restrict N4 = N + 4 * stride + pad;
  const double* __restrict N5 = N + 5 * stride + pad;
  const double* __restrict N6 = N + 6 * stride + pad;
  const double* __restrict N7 = N + 7 * stride + pad;
#pragma omp simd
  for (int q = 0; q < points; ++q)
    R[q] += ((N0[q] + N1[q - o1]) + (N2[q - o2] + N3[q - o3])) + ((N4[q - o4] + N5[q - o5]) + (N6[q - o6] + N7[q - o7]));
}

/// Symplectic Euler on the lattice planes, n entries: V += (h W) F, then X += (h U) V, with W
/// the inverse mass on free axes (else 0) and U 1 on free axes (else 0).
KERF_VECTOR_CLONES
void lattice_update(int n, double h, const double* __restrict W, const double* __restrict U, const double* __restrict F,
                    double* __restrict X, double* __restrict V) {
#pragma omp simd
  for (int e = 0; e < n; ++e) {
    // v ← v + h f / m;  x ← x + h v
    V[e] += h * W[e] * F[e];
    X[e] += h * U[e] * V[e];
  }
}

/// lattice_update with single-precision forces, fused with the single-precision copies of the
/// new state that the next sub-step's forces read: V += (h W) F, X += (h U) V (double), then
/// DX = X − R (the displacement from the rest position R) and VS = V in single precision.
KERF_VECTOR_CLONES
void lattice_update_single(int n, double h, const double* __restrict W, const double* __restrict U, const float* __restrict F,
                           const double* __restrict R, double* __restrict X, double* __restrict V, float* __restrict DX,
                           float* __restrict VS) {
#pragma omp simd
  for (int e = 0; e < n; ++e) {
    // v ← v + h f / m;  x ← x + h v
    V[e] += h * W[e] * static_cast<double>(F[e]);
    X[e] += h * U[e] * V[e];
    DX[e] = static_cast<float>(X[e] - R[e]);
    VS[e] = static_cast<float>(V[e]);
  }
}

/// One lattice direction's springs, start points p in [begin, end), in each precision's kernels:
/// the end points' share in the same loop where |o| is at least the widest SIMD width of the
/// precision (8 doubles, 16 floats: then no two lanes of one vector touch the same point), else
/// through G and direction_ends. Double: absolute positions X; single: displacements U from the
/// rest lattice with the direction's rest vector (ox, oy, oz) = h o_d. Returns the elastic energy.
double direction_forces(int begin, int end, int o, const std::array<double, 3>& /*offset*/, double rest, double tau, double tiny,
                        const double* k, const double* X, const double* V, double* F, double* G, int P) noexcept {
  if (std::abs(o) >= 8)
    return direction_springs_fused(begin, end, o, rest, tau, tiny, k, X, X + P, X + 2 * P, V, V + P, V + 2 * P, F, F + P, F + 2 * P);
  const double energy =
      direction_springs(begin, end, o, rest, tau, tiny, k, X, X + P, X + 2 * P, V, V + P, V + 2 * P, F, F + P, F + 2 * P, G, G + P, G + 2 * P);
  direction_ends(begin, end, o, G, G + P, G + 2 * P, F, F + P, F + 2 * P);
  return energy;
}
float direction_forces(int begin, int end, int o, const std::array<float, 3>& offset, float rest, float tau, float tiny, const float* k,
                       const float* U, const float* V, float* F, float* G, int P) noexcept {
  if (std::abs(o) >= 16)
    return direction_springs_single_fused(begin, end, o, offset[0], offset[1], offset[2], rest, tau, tiny, k, U, U + P, U + 2 * P, V,
                                          V + P, V + 2 * P, F, F + P, F + 2 * P);
  const float energy = direction_springs_single(begin, end, o, offset[0], offset[1], offset[2], rest, tau, tiny, k, U, U + P, U + 2 * P, V,
                                                V + P, V + 2 * P, F, F + P, F + 2 * P, G, G + P, G + 2 * P);
  direction_ends_single(begin, end, o, G, G + P, G + 2 * P, F, F + P, F + 2 * P);
  return energy;
}

/// The cells' volume term in each precision's kernels (cell_volumes, cell_volumes_single), then
/// each point's share of its cells' corner forces; returns the cells' energy.
double volume_forces(int P, int pad, const int* corner, double c, double kappa_v0, double tau, const double* cell, const double* X,
                     const double* V, double* Q, double* F) noexcept {
  const int stride = pad + P;
  const double energy = cell_volumes(P - pad, corner, c, kappa_v0, tau, cell, X, X + P, X + 2 * P, V, V + P, V + 2 * P, Q, stride, pad);
  cell_volume_forces(P, corner, Q, stride, pad, F, F + P, F + 2 * P);
  return energy;
}
float volume_forces(int P, int pad, const int* corner, float c, float kappa_v0, float tau, const float* cell, const float* U,
                    const float* V, float* Q, float* F) noexcept {
  const int stride = pad + P;
  const float energy =
      cell_volumes_single(P - pad, corner, c, kappa_v0, tau, cell, U, U + P, U + 2 * P, V, V + P, V + 2 * P, Q, stride, pad);
  cell_volume_forces_single(P, corner, Q, stride, pad, F, F + P, F + 2 * P);
  return energy;
}

} // namespace

LatticeForces::LatticeForces(const SpringNetwork& net) {
  // The lattice spans the box of the block's cells that are kept (a network's block is a cube
  // around the body; its pruned cells have no springs, so lattice points beyond the kept cells'
  // box would only add springs of zero constant to every loop): cells lo .. hi − 1.
  if (net.cell_count() == 0) return;
  Eigen::Vector3i lo = net.cell_index.front(), hi = net.cell_index.front();
  for (const Eigen::Vector3i& g : net.cell_index) lo = lo.cwiseMin(g), hi = hi.cwiseMax(g);
  hi += Eigen::Vector3i::Ones();
  const int px = hi.x() - lo.x() + 1, py = hi.y() - lo.y() + 1, pz = hi.z() - lo.z() + 1;
  m_points = px * py * pz;
  const auto linear = [px, py](int i, int j, int k) { return i + px * (j + py * k); };
  for (std::size_t d = 0; d < directions.size(); ++d) {
    const auto& e = directions[d];
    m_offset[d] = linear(e[0], e[1], e[2]);
    m_type[d] = std::abs(e[0]) + std::abs(e[1]) + std::abs(e[2]);
  }
  for (int a = 0; a < 8; ++a) m_corner[static_cast<std::size_t>(a)] = linear(a & 1, (a >> 1) & 1, (a >> 2) & 1);
  m_pad = m_corner[7];

  // Each node's lattice point; a network with two nodes on one point (a split vertex) or a cell
  // whose corners are not the lattice's is not a lattice: `applies` then stays false.
  const double h = net.block.cell_size;
  m_slot.assign(static_cast<std::size_t>(net.node_capacity()), -1);
  std::vector<int> node_at(static_cast<std::size_t>(m_points), -1);
  for (int p = 0; p < net.node_count; ++p) {
    const Eigen::Vector3i g = ((net.rest.col(p) - net.block.origin) / h).array().round().cast<int>() - lo.array();
    if ((g.array() < 0).any() || g.x() >= px || g.y() >= py || g.z() >= pz) return;
    const int s = linear(g.x(), g.y(), g.z());
    if (node_at[static_cast<std::size_t>(s)] >= 0) return;
    node_at[static_cast<std::size_t>(s)] = p;
    m_slot[static_cast<std::size_t>(p)] = s;
  }
  // Each cell spring, from corner a to corner b, as a lattice direction from one of its ends.
  for (std::size_t i = 0; i < cell_springs.size(); ++i) {
    const CellSpring& s = cell_springs[i];
    std::array<int, 3> e{((s.b & 1) - (s.a & 1)), ((s.b >> 1) & 1) - ((s.a >> 1) & 1), ((s.b >> 2) & 1) - ((s.a >> 2) & 1)};
    int start = s.a;
    const int first = e[0] != 0 ? e[0] : e[1] != 0 ? e[1] : e[2];
    if (first < 0) {
      for (int& component : e) component = -component;
      start = s.b;
    }
    m_spring_direction[i] = static_cast<int>(std::find(directions.begin(), directions.end(), e) - directions.begin());
    m_spring_start[i] = start;
  }
  m_cell_point.resize(static_cast<std::size_t>(net.cell_count()));
  for (int c = 0; c < net.cell_count(); ++c) {
    const Eigen::Vector3i g = net.cell_index[static_cast<std::size_t>(c)] - lo;
    m_cell_point[static_cast<std::size_t>(c)] = linear(g.x(), g.y(), g.z());
  }
  m_k.assign(13 * static_cast<std::size_t>(m_points), 0.0);
  m_cell.assign(static_cast<std::size_t>(m_points), 0.0);
  m_node_count = net.node_count; // (for on_lattice below)
  for (int c = 0; c < net.cell_count(); ++c) {
    if (!on_lattice(net, c)) {
      m_node_count = -1;
      return;
    }
    add_to_lattice(net, c, m_k, m_cell);
  }
  m_x.assign(3 * static_cast<std::size_t>(m_points), 0.0);
  m_v.assign(3 * static_cast<std::size_t>(m_points), 0.0);
  m_f.assign(3 * static_cast<std::size_t>(m_points), 0.0);
  m_g.assign(3 * static_cast<std::size_t>(m_points), 0.0);
  m_q.assign(12 * static_cast<std::size_t>(m_pad + m_points), 0.0);
  m_inverse_mass.assign(3 * static_cast<std::size_t>(m_points), 0.0);
  m_free.assign(3 * static_cast<std::size_t>(m_points), 0.0);
  m_bound_weight.assign(static_cast<std::size_t>(m_points), 0.0);
  m_row.assign(static_cast<std::size_t>(m_points), 0.0);
  m_rest.assign(3 * static_cast<std::size_t>(m_points), 0.0);
  m_u_single.assign(3 * static_cast<std::size_t>(m_points), 0.0f);
  m_v_single.assign(3 * static_cast<std::size_t>(m_points), 0.0f);
  m_f_single.assign(3 * static_cast<std::size_t>(m_points), 0.0f);
  m_g_single.assign(3 * static_cast<std::size_t>(m_points), 0.0f);
  m_q_single.assign(12 * static_cast<std::size_t>(m_pad + m_points), 0.0f);
  m_k_single.resize(m_k.size());
  for (std::size_t e = 0; e < m_k.size(); ++e) m_k_single[e] = static_cast<float>(m_k[e]);
  m_cell_single.resize(m_cell.size());
  for (std::size_t e = 0; e < m_cell.size(); ++e) m_cell_single[e] = static_cast<float>(m_cell[e]);
  for (int p = 0; p < net.node_count; ++p) {
    const auto s = static_cast<std::size_t>(m_slot[static_cast<std::size_t>(p)]);
    const std::uint8_t fixed = net.constraint[static_cast<std::size_t>(p)];
    const double inv_m = 1.0 / net.mass[static_cast<std::size_t>(p)];
    for (int r = 0; r < 3; ++r)
      if (!(fixed & (1u << r))) {
        m_inverse_mass[static_cast<std::size_t>(r * m_points) + s] = inv_m;
        m_free[static_cast<std::size_t>(r * m_points) + s] = 1.0;
      }
    if (fixed != fix_all) m_bound_weight[s] = inv_m;
  }
  // Lattice points without a node keep their rest position (their springs have k = 0).
  for (int k = 0; k < pz; ++k)
    for (int j = 0; j < py; ++j)
      for (int i = 0; i < px; ++i)
        for (int r = 0; r < 3; ++r)
          m_x[static_cast<std::size_t>(r * m_points + linear(i, j, k))] = m_rest[static_cast<std::size_t>(r * m_points + linear(i, j, k))] =
              net.block.origin[r] + h * (lo + Eigen::Vector3i(i, j, k))[r];
  m_k_torn.assign(m_k.size(), 0.0);
  m_cell_torn.assign(m_cell.size(), 0.0);
  m_exceptions.reserve(static_cast<std::size_t>(net.cell_count()));
  m_cell_count = net.cell_count();
  m_topology = net.topology;
}

bool LatticeForces::on_lattice(const SpringNetwork& net, int cell) const noexcept {
  const int base = m_cell_point[static_cast<std::size_t>(cell)];
  const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
  for (int a = 0; a < 8; ++a) {
    const int node = nodes[static_cast<std::size_t>(a)];
    if (node >= m_node_count || m_slot[static_cast<std::size_t>(node)] != base + m_corner[static_cast<std::size_t>(a)]) return false;
  }
  return true;
}

void LatticeForces::add_to_lattice(const SpringNetwork& net, int cell, std::vector<double>& k, std::vector<double>& mask) const noexcept {
  const int base = m_cell_point[static_cast<std::size_t>(cell)];
  mask[static_cast<std::size_t>(base)] = 1.0;
  for (std::size_t i = 0; i < cell_springs.size(); ++i)
    k[static_cast<std::size_t>(m_spring_direction[i]) * static_cast<std::size_t>(m_points) +
      static_cast<std::size_t>(base + m_corner[static_cast<std::size_t>(m_spring_start[i])])] += net.spring_constant(cell_springs[i].type);
}

void LatticeForces::find_exceptions(const SpringNetwork& net) noexcept {
  std::fill(m_k_torn.begin(), m_k_torn.end(), 0.0);
  std::fill(m_cell_torn.begin(), m_cell_torn.end(), 0.0);
  m_exceptions.clear();
  for (int c = 0; c < net.cell_count(); ++c) {
    if (on_lattice(net, c))
      add_to_lattice(net, c, m_k_torn, m_cell_torn);
    else
      m_exceptions.push_back(c); // within the capacity reserved at construction
  }
  m_torn_topology = net.topology;
}

bool LatticeForces::applies(const SpringNetwork& net) const noexcept {
  return m_node_count >= 0 && net.node_count == m_node_count && net.topology == m_topology;
}

bool LatticeForces::applies_torn(const SpringNetwork& net) const noexcept {
  return m_node_count >= 0 && net.node_count >= m_node_count && net.cell_count() == m_cell_count &&
         net.node_capacity() == static_cast<int>(m_slot.size());
}

void LatticeForces::gather(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept {
  gather_double(x, v);
  gather_single(x, v);
}

void LatticeForces::gather_double(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept {
  const int P = m_points;
  for (int p = 0; p < m_node_count; ++p) {
    const int s = m_slot[static_cast<std::size_t>(p)];
    for (int r = 0; r < 3; ++r) {
      const auto e = static_cast<std::size_t>(r * P + s);
      m_x[e] = x(r, p);
      m_v[e] = v(r, p);
    }
  }
}

void LatticeForces::gather_single(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept {
  const int P = m_points;
  for (int p = 0; p < m_node_count; ++p) {
    const int s = m_slot[static_cast<std::size_t>(p)];
    for (int r = 0; r < 3; ++r) {
      const auto e = static_cast<std::size_t>(r * P + s);
      m_u_single[e] = static_cast<float>(x(r, p) - m_rest[e]);
      m_v_single[e] = static_cast<float>(v(r, p));
    }
  }
}

void LatticeForces::place(int node, const Eigen::Vector3d& x, const Eigen::Vector3d& v) noexcept {
  const int s = m_slot[static_cast<std::size_t>(node)];
  for (int r = 0; r < 3; ++r) {
    const auto e = static_cast<std::size_t>(r * m_points + s);
    m_x[e] = x[r];
    m_v[e] = v[r];
    m_u_single[e] = static_cast<float>(x[r] - m_rest[e]);
    m_v_single[e] = static_cast<float>(v[r]);
  }
}

void LatticeForces::scatter(Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v) const noexcept {
  const int P = m_points;
  for (int p = 0; p < m_node_count; ++p) {
    const int s = m_slot[static_cast<std::size_t>(p)];
    for (int r = 0; r < 3; ++r) {
      x(r, p) = m_x[static_cast<std::size_t>(r * P + s)];
      v(r, p) = m_v[static_cast<std::size_t>(r * P + s)];
    }
  }
}

double LatticeForces::substep(const SpringNetwork& net, double h, ForcePrecision precision) noexcept {
  if (precision == ForcePrecision::single_precision) {
    const double energy = lattice_forces_single(net);
    lattice_update_single(3 * m_points, h, m_inverse_mass.data(), m_free.data(), m_f_single.data(), m_rest.data(), m_x.data(),
                          m_v.data(), m_u_single.data(), m_v_single.data());
    return energy;
  }
  const double energy = lattice_forces(net);
  lattice_update(3 * m_points, h, m_inverse_mass.data(), m_free.data(), m_f.data(), m_x.data(), m_v.data());
  return energy;
}

double LatticeForces::evaluate(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                               Eigen::Matrix3Xd& f, ForcePrecision precision) noexcept {
  if (!applies(net)) return applies_torn(net) ? evaluate_torn(net, x, v, f) : network_forces(net, x, v, f);
  const bool single = precision == ForcePrecision::single_precision;
  if (single)
    gather_single(x, v);
  else
    gather_double(x, v);
  const double energy = single ? lattice_forces_single(net) : lattice_forces(net);
  const int P = m_points;
  for (int p = 0; p < m_node_count; ++p) {
    const int s = m_slot[static_cast<std::size_t>(p)];
    for (int r = 0; r < 3; ++r)
      f(r, p) = single ? static_cast<double>(m_f_single[static_cast<std::size_t>(r * P + s)]) : m_f[static_cast<std::size_t>(r * P + s)];
  }
  return energy;
}

double LatticeForces::evaluate_torn(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                                    Eigen::Matrix3Xd& f) noexcept {
  if (net.topology != m_torn_topology) find_exceptions(net);
  // The lattice's own nodes (the first m_node_count: a split appends its copy) on the lattice,
  // with the constants and cells of the cells still there; a point whose node lost all its
  // cells to copies keeps its springs' zero constants.
  gather_double(x, v);
  double energy = lattice_forces_in<double>(net, true);
  const int P = m_points;
  for (int p = 0; p < m_node_count; ++p) {
    const int s = m_slot[static_cast<std::size_t>(p)];
    for (int r = 0; r < 3; ++r) f(r, p) = m_f[static_cast<std::size_t>(r * P + s)];
  }
  f.middleCols(m_node_count, net.node_count - m_node_count).setZero();
  // The exceptions: each cell's 28 springs and volume term on its own corners (cell_forces, the
  // same law; a spring it shares with a cell on the lattice is the sum of the two cells' shares,
  // as in the merged arrays).
  Eigen::Matrix<double, 3, 8> xc, vc, fc;
  for (const int c : m_exceptions) {
    const auto& nodes = net.cell_nodes[static_cast<std::size_t>(c)];
    for (int a = 0; a < 8; ++a) {
      xc.col(a) = x.col(nodes[static_cast<std::size_t>(a)]);
      vc.col(a) = v.col(nodes[static_cast<std::size_t>(a)]);
    }
    energy += cell_forces(net, c, xc, vc, fc);
    for (int a = 0; a < 8; ++a) f.col(nodes[static_cast<std::size_t>(a)]) += fc.col(a);
  }
  return energy;
}

double LatticeForces::evaluate_on_lattice(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept {
  gather_single(x, v);
  return lattice_forces_single(net);
}

double LatticeForces::gershgorin_bound(const SpringNetwork& net, const Eigen::Matrix3Xd& x) noexcept {
  const int P = m_points;
  double* X = m_x.data();
  for (int p = 0; p < m_node_count; ++p) {
    const int s = m_slot[static_cast<std::size_t>(p)];
    for (int r = 0; r < 3; ++r) X[r * P + s] = x(r, p);
  }
  double* R = m_row.data();
  std::fill(m_row.begin(), m_row.end(), 0.0);
  for (std::size_t d = 0; d < directions.size(); ++d) {
    const int o = m_offset[d];
    const int begin = std::max(0, -o), end = P - std::max(0, o);
    direction_rows(begin, end, o, net.rest_length(m_type[d]), m_k.data() + d * static_cast<std::size_t>(P), X, X + P, X + 2 * P, R,
                   m_g.data());
    direction_row_ends(begin, end, o, m_g.data(), R);
  }
  const double kappa = net.stiffness.volume_modulus;
  if (kappa > 0.0) {
    const double h = net.block.cell_size;
    const int stride = m_pad + P;
    cell_rows(P - m_pad, m_corner.data(), 1.0 / (4.0 * h), kappa * h * h * h, m_cell.data(), X, X + P, X + 2 * P, m_q.data(), stride,
              m_pad);
    cell_row_ends(P, m_corner.data(), m_q.data(), stride, m_pad, R);
  }
  // An anchor adds K I to its node's diagonal block: K to the row.
  for (int i = 0; i < net.anchors.count(); ++i)
    R[m_slot[static_cast<std::size_t>(net.anchors.node[static_cast<std::size_t>(i)])]] += net.anchors.stiffness[static_cast<std::size_t>(i)];
  double bound = 0.0;
  for (int p = 0; p < P; ++p) bound = std::max(bound, R[p] * m_bound_weight[static_cast<std::size_t>(p)]);
  return bound;
}

template <class Real>
double LatticeForces::lattice_forces_in(const SpringNetwork& net, bool torn) noexcept {
  constexpr bool single = std::is_same_v<Real, float>;
  // The state each precision reads (double: positions; single: displacements from the rest
  // lattice) and the planes it writes.
  const Real* X = nullptr;
  const Real* V = nullptr;
  const Real* K = nullptr;
  const Real* cell = nullptr;
  Real *F = nullptr, *G = nullptr, *Q = nullptr;
  if constexpr (single) {
    X = m_u_single.data(), V = m_v_single.data(), K = m_k_single.data(), cell = m_cell_single.data();
    F = m_f_single.data(), G = m_g_single.data(), Q = m_q_single.data();
    std::fill(m_f_single.begin(), m_f_single.end(), 0.0f);
  } else {
    X = m_x.data(), V = m_v.data(), K = torn ? m_k_torn.data() : m_k.data(), cell = torn ? m_cell_torn.data() : m_cell.data();
    F = m_f.data(), G = m_g.data(), Q = m_q.data();
    std::fill(m_f.begin(), m_f.end(), 0.0);
  }
  const int P = m_points;
  const double h = net.block.cell_size;
  const auto tau = static_cast<Real>(net.damping_time);
  const auto tiny = static_cast<Real>(1e-12 * h);
  double energy = 0.0;
  for (std::size_t d = 0; d < directions.size(); ++d) {
    const int o = m_offset[d];
    const int begin = std::max(0, -o), end = P - std::max(0, o);
    const std::array<Real, 3> offset{static_cast<Real>(h * directions[d][0]), static_cast<Real>(h * directions[d][1]),
                                     static_cast<Real>(h * directions[d][2])};
    energy += direction_forces(begin, end, o, offset, static_cast<Real>(net.rest_length(m_type[d])), tau, tiny,
                               K + d * static_cast<std::size_t>(P), X, V, F, G, P);
  }
  const double kappa = net.stiffness.volume_modulus;
  if (kappa > 0.0)
    energy += volume_forces(P, m_pad, m_corner.data(), static_cast<Real>(1.0 / (4.0 * h)), static_cast<Real>(kappa * h * h * h), tau,
                            cell, X, V, Q, F);
  // The anchors (a compliant grasp): f = K (a − x) + τ K (ȧ − v); in single precision a − x =
  // (a − X) − u from the displacement u, the difference taken in double.
  const NodeAnchors& anchors = net.anchors;
  for (int i = 0; i < anchors.count(); ++i) {
    const int s = m_slot[static_cast<std::size_t>(anchors.node[static_cast<std::size_t>(i)])];
    const double stiffness = anchors.stiffness[static_cast<std::size_t>(i)];
    for (int r = 0; r < 3; ++r) {
      const auto e = static_cast<std::size_t>(r * P + s);
      double gap = 0.0;
      if constexpr (single)
        gap = (anchors.position(r, i) - m_rest[e]) - static_cast<double>(X[e]);
      else
        gap = anchors.position(r, i) - X[e];
      F[e] += static_cast<Real>(stiffness * (gap + net.damping_time * (anchors.velocity(r, i) - static_cast<double>(V[e]))));
      energy += 0.5 * stiffness * gap * gap;
    }
  }
  return energy;
}

double LatticeForces::lattice_forces(const SpringNetwork& net) noexcept { return lattice_forces_in<double>(net); }

double LatticeForces::lattice_forces_single(const SpringNetwork& net) noexcept { return lattice_forces_in<float>(net); }

} // namespace kerf

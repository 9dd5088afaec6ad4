#include "realtime/springs/network_system.hpp"

#include "realtime/blas_threads.hpp"
#include "realtime/springs/cholmod_view.hpp"
#include "realtime/springs/lattice_dissection.hpp"
#include "realtime/springs/supernodal_cholesky.hpp"
#include "realtime/springs/vector_clones.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

namespace {

/// Rows of one panel of an inverted block (single-precision solve): the panel's rows rounded up
/// to a multiple of 16 (one AVX-512 vector of floats; the padding is zero), so that the solve's
/// loops run in whole vectors.
constexpr int panel_rows(int rows) { return (rows + 15) & ~15; }

/// Whether a supernode of `columns` columns keeps its whole inverted block [T⁻¹; −R T⁻¹] for the
/// single-precision solve (one dense product per solve direction) rather than T⁻¹ and R apart
/// (two): R T⁻¹ costs m nscol²/2 operations per factorisation (m rows below), as much as the
/// factorisation's own update for the wide separators, so only the narrow supernodes, where
/// the solve's per-supernode overhead counts most, keep it (docs/spring-network.md §2).
constexpr bool whole_inverted_block(int columns) { return columns <= 48; }

/// Floats of one panel (four columns from column c) of a supernode's blocks.
constexpr std::ptrdiff_t panel_floats(int nscol, int nsrow, int c) {
  return 4 * static_cast<std::ptrdiff_t>(whole_inverted_block(nscol) ? panel_rows(nsrow - c)
                                                                      : panel_rows(nscol - c) + panel_rows(nsrow - nscol));
}


/// The free degrees of freedom in natural order: those of the nodes (node order; an axis fixed
/// by NodeConstraint has none), then the shadows: with coupled shadows one per free dof of every
/// node, with decoupled ones one per free dof of every node alone at its lattice point (one that
/// has not split).
struct FreeDofs {
  std::vector<int> natural;        ///< per entry 3 n + i: the dof of node n's axis i, or −1
  std::vector<int> shadow_natural; ///< per entry 3 n + i: its shadow's dof, or −1
  int count = 0;                   ///< dofs and shadows
  int first_shadow = 0;            ///< the shadows are count − first_shadow dofs from here
};

FreeDofs number_free_dofs(const SpringNetwork& net, NetworkSystem::SplitRoom room, const std::vector<int>& node_at_point) {
  FreeDofs d;
  d.natural.assign(static_cast<std::size_t>(3 * net.node_capacity()), -1);
  d.shadow_natural.assign(d.natural.size(), -1);
  int n = 0;
  for (int p = 0; p < net.node_count; ++p)
    for (int i = 0; i < 3; ++i)
      if (!(net.constraint[static_cast<std::size_t>(p)] & (1u << i))) d.natural[static_cast<std::size_t>(3 * p + i)] = n++;
  d.first_shadow = n;
  // A node has a shadow when it is alone at its lattice point (node_at_point: −1 where a split
  // left two; every node of the untorn network that coupled shadows need).
  std::vector<std::uint8_t> alone(static_cast<std::size_t>(net.node_count), 0);
  for (const int p : node_at_point)
    if (p >= 0) alone[static_cast<std::size_t>(p)] = 1;
  if (room != NetworkSystem::SplitRoom::none)
    for (int p = 0; p < net.node_count; ++p)
      for (int i = 0; i < 3; ++i)
        if (alone[static_cast<std::size_t>(p)] && d.natural[static_cast<std::size_t>(3 * p + i)] >= 0)
          d.shadow_natural[static_cast<std::size_t>(3 * p + i)] = n++;
  d.count = n;
  return d;
}

/// Local dof a (3 corner + axis) of a cell: the node's dof and its shadow's, either may be −1.
std::array<int, 2> cell_dofs(const SpringNetwork& net, const std::vector<int>& map, const std::vector<int>& shadow, int cell, int a) {
  const auto k = static_cast<std::size_t>(3 * net.cell_nodes[static_cast<std::size_t>(cell)][static_cast<std::size_t>(a / 3)] + a % 3);
  return std::array<int, 2>{map[k], shadow[k]};
}

/// The lower triangle of the n x n cell-coupling pattern (every pair of dofs, or coupled
/// shadows, of nodes sharing a cell) with dofs numbered by `map` and `shadow`, and the diagonal
/// of decoupled shadows; entries 1. Built node by node: the dofs of the nodes sharing a cell
/// with node q, sorted once, are the rows of each of q's columns from that column down (every
/// column belongs to one node), so no entry is produced twice and nothing is sorted but those
/// short lists.
NetworkSystem::Matrix lower_pattern(const SpringNetwork& net, const std::vector<int>& map, const std::vector<int>& shadow, int n,
                                    NetworkSystem::SplitRoom room) {
  const bool coupled = room == NetworkSystem::SplitRoom::coupled_shadows;
  const int nodes = net.node_count;
  // Each node's cells, as compressed rows.
  std::vector<int> first_cell(static_cast<std::size_t>(nodes) + 1, 0), cells;
  for (const auto& corners : net.cell_nodes)
    for (const int p : corners) ++first_cell[static_cast<std::size_t>(p) + 1];
  for (int p = 0; p < nodes; ++p) first_cell[static_cast<std::size_t>(p) + 1] += first_cell[static_cast<std::size_t>(p)];
  cells.resize(static_cast<std::size_t>(first_cell.back()));
  {
    std::vector<int> next(first_cell.begin(), first_cell.end() - 1);
    for (int c = 0; c < net.cell_count(); ++c)
      for (const int p : net.cell_nodes[static_cast<std::size_t>(c)]) cells[static_cast<std::size_t>(next[static_cast<std::size_t>(p)]++)] = c;
  }
  // A node's dofs: its axes' and, with coupled shadows, their shadows'.
  const auto add_dofs = [&](int p, std::vector<int>& out) {
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(3 * p + i);
      if (map[k] >= 0) out.push_back(map[k]);
      if (coupled && shadow[k] >= 0) out.push_back(shadow[k]);
    }
  };
  // Per node, the sorted dofs of the nodes sharing a cell with it (itself included).
  std::vector<int> first_row(static_cast<std::size_t>(nodes) + 1, 0), rows, seen(static_cast<std::size_t>(nodes), -1), own;
  rows.reserve(static_cast<std::size_t>(nodes) * 81);
  for (int q = 0; q < nodes; ++q) {
    const auto begin = static_cast<std::ptrdiff_t>(rows.size());
    for (int k = first_cell[static_cast<std::size_t>(q)]; k < first_cell[static_cast<std::size_t>(q) + 1]; ++k)
      for (const int p : net.cell_nodes[static_cast<std::size_t>(cells[static_cast<std::size_t>(k)])])
        if (seen[static_cast<std::size_t>(p)] != q) {
          seen[static_cast<std::size_t>(p)] = q;
          add_dofs(p, rows);
        }
    std::sort(rows.begin() + begin, rows.end());
    first_row[static_cast<std::size_t>(q) + 1] = static_cast<int>(rows.size());
  }
  // Column c of node q: q's rows from c down; a decoupled shadow's column: its diagonal.
  std::vector<int> node_of_column(static_cast<std::size_t>(n), -1);
  for (int q = 0; q < nodes; ++q) {
    own.clear();
    add_dofs(q, own);
    for (const int c : own) node_of_column[static_cast<std::size_t>(c)] = q;
  }
  const bool decoupled = room == NetworkSystem::SplitRoom::decoupled_shadows;
  std::vector<std::uint8_t> shadow_column(static_cast<std::size_t>(n), 0);
  if (decoupled)
    for (const int d : shadow)
      if (d >= 0) shadow_column[static_cast<std::size_t>(d)] = 1;
  NetworkSystem::Matrix m(n, n);
  std::vector<int> outer(static_cast<std::size_t>(n) + 1, 0), inner;
  for (int c = 0; c < n; ++c) {
    if (const int q = node_of_column[static_cast<std::size_t>(c)]; q >= 0) {
      const int* begin = rows.data() + first_row[static_cast<std::size_t>(q)];
      const int* end = rows.data() + first_row[static_cast<std::size_t>(q) + 1];
      inner.insert(inner.end(), std::lower_bound(begin, end, c), end);
    }
    if (shadow_column[static_cast<std::size_t>(c)]) inner.push_back(c);
    outer[static_cast<std::size_t>(c) + 1] = static_cast<int>(inner.size());
  }
  m.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), m.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), m.innerIndexPtr());
  std::fill(m.valuePtr(), m.valuePtr() + inner.size(), 1.0);
  return m;
}

/// The same pattern from every cell's pairs of dofs, as triplets: the second method `rebuild`
/// checks the pattern above against where assertions are on (the sanitizer builds).
[[maybe_unused]] NetworkSystem::Matrix lower_pattern_by_triplets(const SpringNetwork& net, const std::vector<int>& map,
                                                                 const std::vector<int>& shadow, int n, NetworkSystem::SplitRoom room) {
  const bool coupled = room == NetworkSystem::SplitRoom::coupled_shadows;
  const std::vector<int> none(coupled ? 0 : shadow.size(), -1);
  const std::vector<int>& coupled_shadow = coupled ? shadow : none;
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(static_cast<std::size_t>(net.cell_count()) * (coupled ? 1200 : 300));
  for (int cell = 0; cell < net.cell_count(); ++cell)
    for (int a = 0; a < 24; ++a)
      for (const int r : cell_dofs(net, map, coupled_shadow, cell, a)) {
        if (r < 0) continue;
        for (int b = 0; b < 24; ++b)
          for (const int c : cell_dofs(net, map, coupled_shadow, cell, b))
            if (c >= 0 && r >= c) triplets.emplace_back(r, c, 1.0);
      }
  if (room == NetworkSystem::SplitRoom::decoupled_shadows)
    for (const int d : shadow)
      if (d >= 0) triplets.emplace_back(d, d, 1.0);
  NetworkSystem::Matrix m(n, n);
  m.setFromTriplets(triplets.begin(), triplets.end());
  m.makeCompressed();
  return m;
}

/// Whether a and b have the same entries (compressed, rows sorted in each column).
[[maybe_unused]] bool same_pattern(const NetworkSystem::Matrix& a, const NetworkSystem::Matrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a.nonZeros() == b.nonZeros() &&
         std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.cols() + 1, b.outerIndexPtr()) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr());
}

/// Fill-reducing ordering of the first `n` natural dofs (those in the factor): the lattice's
/// geometric nested dissection (lattice_dissection.hpp; a node and its coupled shadow take their
/// lattice point's rank, dofs of one point stay together), as the permutation given to CHOLMOD
/// (entry new = natural dof); empty when a node is off the block's lattice.
std::vector<int> lattice_ordering(const SpringNetwork& net, const FreeDofs& dofs, int n) {
  std::vector<int> given;
  const Eigen::Vector3i np = net.block.cells + Eigen::Vector3i::Ones();
  const std::vector<int> rank = lattice_nested_dissection(np);
  std::vector<std::int64_t> key(static_cast<std::size_t>(n), -1);
  bool on_lattice = net.block.cell_size > 0.0;
  for (int p = 0; p < net.node_count && on_lattice; ++p) {
    const Eigen::Vector3d g = (net.rest.col(p) - net.block.origin) / net.block.cell_size;
    const Eigen::Vector3i gi = g.array().round().cast<int>();
    if ((gi.array() < 0).any() || (gi.array() >= np.array()).any() || (g - gi.cast<double>()).norm() > 1e-6) {
      on_lattice = false;
      break;
    }
    const std::int64_t r = rank[static_cast<std::size_t>(gi.x() + np.x() * (gi.y() + np.y() * gi.z()))];
    for (int i = 0; i < 3; ++i)
      for (const int k : {dofs.natural[static_cast<std::size_t>(3 * p + i)], dofs.shadow_natural[static_cast<std::size_t>(3 * p + i)]})
        if (k >= 0 && k < n) key[static_cast<std::size_t>(k)] = r * (2 * static_cast<std::int64_t>(n)) + k;
  }
  if (on_lattice) {
    given.resize(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) given[static_cast<std::size_t>(k)] = k;
    std::sort(given.begin(), given.end(), [&key](int a, int b) { return key[static_cast<std::size_t>(a)] < key[static_cast<std::size_t>(b)]; });
  }
  return given;
}

/// CHOLMOD's symbolic analysis of the natural `pattern`'s leading n x n block (lower triangle;
/// the rest, decoupled shadows, stays out of the factor) for a supernodal factor: the lattice's
/// ordering `given` (if any) against AMD, CHOLMOD keeping the one with the smaller factor. Both
/// are deterministic; METIS (CHOLMOD's default tries it when AMD's fill is high) is not, so it is
/// never tried. `ordering` gets the one kept. The factor's numeric storage and Common's
/// workspace are allocated now rather than on the first factorisation.
cholmod_factor* analyse_pattern(cholmod_common& common, NetworkSystem::Matrix& pattern, int n, std::vector<int>& given,
                                NetworkSystem::FillOrdering& ordering) {
  cholmod_sparse view = cholmod_view(pattern, -1);
  // The leading block: its columns' rows are all below n (nothing couples a decoupled shadow).
  view.nrow = view.ncol = static_cast<std::size_t>(n);
  view.nzmax = static_cast<std::size_t>(pattern.outerIndexPtr()[n]);
  common.nmethods = given.empty() ? 1 : 2;
  common.method[0].ordering = given.empty() ? CHOLMOD_AMD : CHOLMOD_GIVEN;
  common.method[1].ordering = CHOLMOD_AMD;
  cholmod_factor* factor = cholmod_analyze_p(&view, given.empty() ? nullptr : given.data(), nullptr, 0, &common);
  ordering = given.empty() || common.selected == 1 ? NetworkSystem::FillOrdering::amd : NetworkSystem::FillOrdering::lattice_nested_dissection;
  if (!factor || common.status < CHOLMOD_OK)
    throw std::runtime_error("NetworkSystem: CHOLMOD analysis failed (status " + std::to_string(common.status) + ")");
  cholmod_change_factor(CHOLMOD_REAL, 1, 1, 1, 1, factor, &common);
  cholmod_allocate_work(view.nrow, 2 * view.nrow + 5 * factor->nsuper, 0, &common);
  if (common.status < CHOLMOD_OK) throw std::runtime_error("NetworkSystem: CHOLMOD workspace allocation failed");
  return factor;
}

/// The dofs and shadows renumbered in the factor's order (perm[new] = natural for the first
/// `factored` ones; the decoupled shadows after them keep their natural numbers); a shadow is
/// unused (`in_use` 0) until a copy takes it.
void number_in_factor_order(const FreeDofs& dofs, const int* perm, int factored, std::vector<int>& dof_of, std::vector<int>& shadow_of,
                            std::vector<std::uint8_t>& in_use) {
  const int n = dofs.count;
  std::vector<int> new_of_natural(static_cast<std::size_t>(n));
  for (int k = 0; k < factored; ++k) new_of_natural[static_cast<std::size_t>(perm[k])] = k;
  for (int k = factored; k < n; ++k) new_of_natural[static_cast<std::size_t>(k)] = k;
  dof_of.assign(dofs.natural.size(), -1);
  for (std::size_t k = 0; k < dofs.natural.size(); ++k) {
    if (dofs.natural[k] >= 0) dof_of[k] = new_of_natural[static_cast<std::size_t>(dofs.natural[k])];
    if (dofs.shadow_natural[k] >= 0) shadow_of[k] = new_of_natural[static_cast<std::size_t>(dofs.shadow_natural[k])];
  }
  for (int k = dofs.first_shadow; k < n; ++k) in_use[static_cast<std::size_t>(new_of_natural[static_cast<std::size_t>(k)])] = 0;
}

/// The node at each lattice point (−1 if none), for finding the original of a copy (same rest
/// position); throws if a node is off the block's lattice, or if two share a point (a torn
/// network) unless `torn` allows it: then the point holds −1 (its node has split once already).
std::vector<int> node_at_lattice_point(const SpringNetwork& net, bool torn) {
  const Eigen::Vector3i np = net.block.cells + Eigen::Vector3i::Ones();
  std::vector<int> node_at(static_cast<std::size_t>(np.prod()), -1);
  std::vector<std::uint8_t> taken(node_at.size(), 0);
  for (int p = 0; p < net.node_count; ++p) {
    const Eigen::Vector3i g = ((net.rest.col(p) - net.block.origin) / net.block.cell_size).array().round().cast<int>();
    if ((g.array() < 0).any() || (g.array() >= np.array()).any()) throw std::invalid_argument("NetworkSystem: a node off the block's lattice");
    const auto k = static_cast<std::size_t>(g.x() + np.x() * (g.y() + np.y() * g.z()));
    if (taken[k] && !torn) throw std::invalid_argument("NetworkSystem: a tear-ready pattern needs an untorn network");
    node_at[k] = taken[k] ? -1 : p;
    taken[k] = 1;
  }
  return node_at;
}

} // namespace

NetworkSystem::NetworkSystem(SolvePrecision precision) : m_precision(precision) {
  find_blas_thread_calls();
  m_common = new cholmod_common;
  cholmod_start(m_common);
  m_common->supernodal = CHOLMOD_SUPERNODAL;
  m_common->print = 0;
  // The ordering is chosen in `rebuild`: never METIS, whose random number state is shared
  // between threads (a study's parallel jobs ordered differently from a serial run and its
  // springs rows differed by 10⁻⁶, StudyRunner.ParallelRunsGiveTheSerialTablesApartFromCosts).
}

NetworkSystem::NetworkSystem(const SpringNetwork& net, SolvePrecision precision) : NetworkSystem(precision) { rebuild(net); }

NetworkSystem::~NetworkSystem() {
  release();
  cholmod_finish(m_common);
  delete m_common;
}

void NetworkSystem::release() noexcept {
  if (m_factor) cholmod_free_factor(&m_factor, m_common);
}

int NetworkSystem::supernode_count() const {
  return (m_factor ? static_cast<int>(m_factor->nsuper) : 0) + (dof_count() - m_factor_dofs);
}

int NetworkSystem::supernode_start(int s) const {
  const int nsuper = m_factor ? static_cast<int>(m_factor->nsuper) : 0;
  return s < nsuper ? static_cast<const int*>(m_factor->super)[s] : m_factor_dofs + (s - nsuper);
}

double NetworkSystem::factor_entries() const {
  if (!m_factor) return 0.0;
  return (m_factor->is_super ? static_cast<double>(m_factor->xsize) : static_cast<double>(m_factor->nzmax)) + (dof_count() - m_factor_dofs);
}

void NetworkSystem::rebuild(const SpringNetwork& net, SplitRoom room, bool check_mass) {
  release();
  m_factorized = false;
  m_room = room;
  m_bound_decoupled = false;
  m_node_at_point.clear();
  if (room != SplitRoom::none) m_node_at_point = node_at_lattice_point(net, room == SplitRoom::decoupled_shadows);
  const FreeDofs dofs = number_free_dofs(net, room, m_node_at_point);
  const int n = dofs.count;
  m_factor_dofs = room == SplitRoom::decoupled_shadows ? dofs.first_shadow : n;
  m_matrix = lower_pattern(net, dofs.natural, dofs.shadow_natural, n, room);
  assert(same_pattern(m_matrix, lower_pattern_by_triplets(net, dofs.natural, dofs.shadow_natural, n, room)));
  m_bound_cells = net.cell_nodes;
  m_bound_nodes = net.node_count;
  m_shadow_of.assign(dofs.natural.size(), -1);
  m_dof_in_use.assign(static_cast<std::size_t>(n), 1);
  if (m_factor_dofs == 0) {
    m_dof_of.assign(dofs.natural.size(), -1);
    m_entry.assign(static_cast<std::size_t>(net.cell_count()) * 576, -1);
    m_diagonal.clear();
    return;
  }

  // Ordering and symbolic analysis by CHOLMOD on the natural pattern (the factor's part).
  std::vector<int> given = lattice_ordering(net, dofs, m_factor_dofs);
  m_factor = analyse_pattern(*m_common, m_matrix, m_factor_dofs, given, m_ordering);
  number_in_factor_order(dofs, static_cast<const int*>(m_factor->Perm), m_factor_dofs, m_dof_of, m_shadow_of, m_dof_in_use);

  // Lower-triangular pattern in the factor's order, and each cell entry's place in it.
  m_matrix = lower_pattern(net, m_dof_of, m_shadow_of, n, room);
  assert(same_pattern(m_matrix, lower_pattern_by_triplets(net, m_dof_of, m_shadow_of, n, room)));
  m_entry.assign(static_cast<std::size_t>(net.cell_count()) * 576, -1);
  for (int cell = 0; cell < net.cell_count(); ++cell) bind_cell(net, cell);
  m_diagonal.assign(static_cast<std::size_t>(n), -1);
  for (int k = 0; k < n; ++k) m_diagonal[static_cast<std::size_t>(k)] = value_index(k, k);

  size_solve_workspaces();
  if (!check_mass) return;
  // One factorisation of the mass matrix, which must succeed (positive lumped masses).
  assemble(net, net.rest, 1.0, 0.0);
  if (!factorize()) throw std::runtime_error("NetworkSystem: the lumped mass matrix did not factorise");
  m_factorized = false;
}

void NetworkSystem::size_solve_workspaces() {
  // The solve's workspaces: the rows below the tallest supernode, the widest supernode's dots;
  // single precision: the inverted blocks' panels (four columns each, rows from the panel's
  // first column down) and one column of a block in double.
  if (!m_factor->is_super) throw std::runtime_error("NetworkSystem: CHOLMOD did not choose a supernodal factor");
  const auto n = static_cast<std::size_t>(m_matrix.rows());
  m_numeric.analyse(supernodal_structure(*m_factor));
  const int* pi = static_cast<const int*>(m_factor->pi);
  const int* super = static_cast<const int*>(m_factor->super);
  const bool single = m_precision == SolvePrecision::single_precision;
  std::size_t tallest = 1, widest = 4;
  std::ptrdiff_t panels = 0;
  m_inverse_block_at.assign(single ? m_factor->nsuper + 1 : 0, 0);
  for (std::size_t sn = 0; sn < m_factor->nsuper; ++sn) {
    const int nsrow = pi[sn + 1] - pi[sn], nscol = super[sn + 1] - super[sn];
    tallest = std::max(tallest, static_cast<std::size_t>(nsrow));
    widest = std::max(widest, static_cast<std::size_t>(nscol));
    if (single) {
      m_inverse_block_at[sn] = panels;
      for (int c = 0; c < nscol; c += 4) panels += panel_floats(nscol, nsrow, c);
    }
  }
  if (single) m_inverse_block_at[m_factor->nsuper] = panels;
  // 16 more for a 64-byte aligned start (whole panels are multiples of 16 floats).
  m_inverse_blocks.assign(static_cast<std::size_t>(panels) + (single ? 16 : 0), 0.0f);
  m_inverse_align = single ? static_cast<int>((64 - reinterpret_cast<std::uintptr_t>(m_inverse_blocks.data()) % 64) % 64 / sizeof(float)) : 0;
  m_inverse_column.assign(single ? 4 * tallest : 0, 0.0);
  m_below.assign(tallest, 0.0);
  m_dots.assign(widest, 0.0);
  m_inverse_diagonal.assign(n, 0.0);
  m_solution_single.assign(single ? n : 0, 0.0f);
  m_shadow_inverse_root.assign(n - static_cast<std::size_t>(m_factor_dofs), 0.0);
  m_rows_single.assign(single ? widest + tallest + 32 : 0, 0.0f);
  m_rows_split = static_cast<int>(widest) + 16;
}

void NetworkSystem::assemble(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double mass_weight,
                             double stiffness_weight, CellTangent tangent) noexcept {
  double* values = m_matrix.valuePtr();
  std::fill(values, values + m_matrix.nonZeros(), 0.0);
  Eigen::Matrix<double, 3, 8> xc;
  Eigen::Matrix<double, 24, 24> K;
  if (stiffness_weight != 0.0)
    for (int cell = 0; cell < net.cell_count(); ++cell) {
      const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
      for (int a = 0; a < 8; ++a) xc.col(a) = x.col(nodes[static_cast<std::size_t>(a)]);
      cell_stiffness_matrix(net, cell, xc, K, tangent);
      const int* entry = m_entry.data() + static_cast<std::size_t>(cell) * 576;
      for (int a = 0; a < 24; ++a)
        for (int b = 0; b < 24; ++b)
          if (const int e = entry[24 * a + b]; e >= 0) values[e] += stiffness_weight * K(a, b);
    }
  for (int p = 0; p < net.node_count; ++p)
    for (int i = 0; i < 3; ++i)
      if (const int d = m_dof_of[static_cast<std::size_t>(3 * p + i)]; d >= 0)
        values[m_diagonal[static_cast<std::size_t>(d)]] += mass_weight * net.mass[static_cast<std::size_t>(p)];
  // The anchors of a compliant grasp: K I on the node's diagonal block (their dashpots τ K take
  // the springs' weight, 1 + τ/h for backward Euler).
  for (int a = 0; a < net.anchors.count(); ++a) {
    const int p = net.anchors.node[static_cast<std::size_t>(a)];
    for (int i = 0; i < 3; ++i)
      if (const int d = m_dof_of[static_cast<std::size_t>(3 * p + i)]; d >= 0)
        values[m_diagonal[static_cast<std::size_t>(d)]] += stiffness_weight * net.anchors.stiffness[static_cast<std::size_t>(a)];
  }
  // An unused shadow: decoupled (solution 0), with half its node's diagonal (see the header).
  for (std::size_t k = 0; k < m_shadow_of.size(); ++k)
    if (const int d = m_shadow_of[k]; d >= 0 && !m_dof_in_use[static_cast<std::size_t>(d)])
      values[m_diagonal[static_cast<std::size_t>(d)]] =
          std::max(0.5 * values[m_diagonal[static_cast<std::size_t>(m_dof_of[k])]], 1e-300);
}

int NetworkSystem::value_index(int r, int c) const noexcept {
  const int* rows = m_matrix.innerIndexPtr();
  const int begin = m_matrix.outerIndexPtr()[c], end = m_matrix.outerIndexPtr()[c + 1];
  const int* at = std::lower_bound(rows + begin, rows + end, r);
  return at != rows + end && *at == r ? static_cast<int>(at - rows) : -1;
}

bool NetworkSystem::bind_cell(const SpringNetwork& net, int cell) noexcept {
  const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
  int* entry = m_entry.data() + static_cast<std::size_t>(cell) * 576;
  bool ok = true;
  for (int a = 0; a < 24; ++a) {
    const int r = m_dof_of[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(a / 3)] + a % 3)];
    for (int b = 0; b < 24; ++b) {
      const int c = m_dof_of[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(b / 3)] + b % 3)];
      int& e = entry[24 * a + b];
      e = r >= 0 && c >= 0 && r >= c ? value_index(r, c) : -1;
      if (r >= 0 && c >= 0 && r >= c && e < 0) ok = false; // not in the analysed pattern
    }
  }
  return ok;
}

bool NetworkSystem::bind_split_vertices(const SpringNetwork& net) noexcept {
  if (m_node_at_point.empty() || net.node_count < m_bound_nodes || net.cell_count() != static_cast<int>(m_bound_cells.size()))
    return false;
  const Eigen::Vector3i np = net.block.cells + Eigen::Vector3i::Ones();
  for (int copy = m_bound_nodes; copy < net.node_count; ++copy) {
    const Eigen::Vector3i g = ((net.rest.col(copy) - net.block.origin) / net.block.cell_size).array().round().cast<int>();
    if ((g.array() < 0).any() || (g.array() >= np.array()).any()) return false;
    const int original = m_node_at_point[static_cast<std::size_t>(g.x() + np.x() * (g.y() + np.y() * g.z()))];
    if (original < 0) return false;
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(3 * original + i);
      const bool free = !(net.constraint[static_cast<std::size_t>(copy)] & (1u << i));
      if (free != (m_shadow_of[k] >= 0) || (free && m_dof_in_use[static_cast<std::size_t>(m_shadow_of[k])])) return false;
      m_dof_of[static_cast<std::size_t>(3 * copy + i)] = free ? m_shadow_of[k] : -1;
      if (free) m_dof_in_use[static_cast<std::size_t>(m_shadow_of[k])] = 1;
    }
  }
  m_bound_nodes = net.node_count;
  if (m_room == SplitRoom::decoupled_shadows) {
    // No entry to re-place: the matrix stays the one before the splits (the kept factor's).
    m_bound_decoupled = true;
    m_factorized = false;
    return true;
  }
  // Re-place the entries of the cells whose corners changed.
  for (int cell = 0; cell < net.cell_count(); ++cell)
    if (net.cell_nodes[static_cast<std::size_t>(cell)] != m_bound_cells[static_cast<std::size_t>(cell)]) {
      if (!bind_cell(net, cell)) return false;
      m_bound_cells[static_cast<std::size_t>(cell)] = net.cell_nodes[static_cast<std::size_t>(cell)];
    }
  m_factorized = false;
  return true;
}

namespace {

/// The supernodes' blocks for the single-precision solve, from a supernodal L (values `lx`,
/// 1 / L_kk in `inverse_diagonal`): for supernode s with diagonal triangle T (nscol x nscol) and
/// the rows R below it, T⁻¹ and R. Column j of T⁻¹ is the triangle's forward substitution
/// applied to the unit vector e_j,
///   u = e_j;  for k = j … nscol−1:  u_k ← u_k / L_kk,  u_i ← u_i − L_ik u_k (k < i < nscol),
/// computed in double four columns at a time (`column`: room for four of the tallest
/// supernode's columns); R is L's own rows. Stored in single precision in panels of four
/// columns, panel c at blocks + at[s] + Σ_{c' < c} panel_floats(nscol, nsrow, c'): its column t
/// (= c + t, zero past nscol) at offset t (pt(c) + pb) holds T⁻¹'s rows c … nscol−1, then R's
/// rows, each part zero-padded (pt(c) = panel_rows(nscol − c), pb = panel_rows(nsrow − nscol)).
/// A narrow supernode (whole_inverted_block) keeps instead the whole inverted block
/// W = [T⁻¹; −R T⁻¹], the same substitution carried through all nsrow rows: its column t at
/// offset t panel_rows(nsrow − c) holds W's rows c … nsrow−1, zero-padded.
KERF_VECTOR_CLONES
void invert_supernode_blocks(const cholmod_factor& L, const double* lx, const double* inverse_diagonal, const std::ptrdiff_t* at,
                             double* column, float* blocks) noexcept {
  const int* super = static_cast<const int*>(L.super);
  const int* pi = static_cast<const int*>(L.pi);
  const int* px = static_cast<const int*>(L.px);
  for (std::size_t s = 0; s < L.nsuper; ++s) {
    const int k1 = super[s], nscol = super[s + 1] - k1, nsrow = pi[s + 1] - pi[s], m = nsrow - nscol;
    const int pb = panel_rows(m);
    const double* block = lx + px[s];
    float* panel = blocks + at[s];
    const bool whole = whole_inverted_block(nscol);
    // rows of the substitution: all (whole block) or the triangle's
    const int rows = whole ? nsrow : nscol;
    for (int c = 0; c < nscol; c += 4) {
      const int top = nscol - c, pt = panel_rows(top);
      // The panel's four columns together (u_t = e_{c+t}; a column past nscol stays zero), so
      // that each column of L is read once per panel. Rows above c + t of u_t stay zero, so
      // the updates of k < c + t leave u_t unchanged.
      double* __restrict u0 = column;
      double* __restrict u1 = u0 + rows;
      double* __restrict u2 = u1 + rows;
      double* __restrict u3 = u2 + rows;
      std::fill(column, column + 4 * static_cast<std::ptrdiff_t>(rows), 0.0);
      u0[c] = 1.0;
      if (c + 1 < nscol) u1[c + 1] = 1.0;
      if (c + 2 < nscol) u2[c + 2] = 1.0;
      if (c + 3 < nscol) u3[c + 3] = 1.0;
      for (int k = c; k < nscol; ++k) {
        // u_k ← u_k / L_kk;  u_i ← u_i − L_ik u_k for the triangle's rows below k
        const double d = inverse_diagonal[k1 + k];
        const double v0 = u0[k] *= d, v1 = u1[k] *= d, v2 = u2[k] *= d, v3 = u3[k] *= d;
        const double* __restrict lk = block + static_cast<std::ptrdiff_t>(k) * nsrow;
#pragma omp simd
        for (int i = k + 1; i < rows; ++i) {
          u0[i] -= lk[i] * v0;
          u1[i] -= lk[i] * v1;
          u2[i] -= lk[i] * v2;
          u3[i] -= lk[i] * v3;
        }
      }
      const double* u[4] = {u0, u1, u2, u3};
      if (whole) {
        // [T⁻¹; −R T⁻¹]: the substitution's rows c … nsrow−1, zero-padded
        const int length = nsrow - c, padded = panel_rows(length);
        for (int t = 0; t < 4; ++t) {
          float* __restrict out = panel + static_cast<std::ptrdiff_t>(t) * padded;
          for (int i = 0; i < length; ++i) out[i] = static_cast<float>(u[t][c + i]);
          std::fill(out + length, out + padded, 0.0f);
        }
        panel += 4 * static_cast<std::ptrdiff_t>(padded);
        continue;
      }
      for (int t = 0; t < 4; ++t) {
        float* __restrict out = panel + static_cast<std::ptrdiff_t>(t) * (pt + pb);
        for (int i = 0; i < top; ++i) out[i] = static_cast<float>(u[t][c + i]);
        std::fill(out + top, out + pt, 0.0f);
        float* __restrict below = out + pt;
        if (c + t < nscol) {
          const double* __restrict r = block + static_cast<std::ptrdiff_t>(c + t) * nsrow + nscol;
          for (int i = 0; i < m; ++i) below[i] = static_cast<float>(r[i]);
        } else {
          std::fill(below, below + m, 0.0f);
        }
        std::fill(below + m, below + pb, 0.0f);
      }
      panel += 4 * static_cast<std::ptrdiff_t>(pt + pb);
    }
  }
}

/// r[0, n) += a0 x0 + a1 x1 + a2 x2 + a3 x3 over whole 16-float vectors (n a multiple of 16).
[[gnu::always_inline]] inline void panel_product(const float* __restrict a0, const float* __restrict a1, const float* __restrict a2,
                                                 const float* __restrict a3, float x0, float x1, float x2, float x3, int n,
                                                 float* __restrict r) noexcept {
  for (int b = 0; b < n; b += 16) {
#pragma omp simd
    for (int i = b; i < b + 16; ++i) r[i] += (a0[i] * x0 + a1[i] * x1) + (a2[i] * x2 + a3[i] * x3);
  }
}

/// d_t = a_t[0, n) · z[0, n) for the four columns t (n a multiple of 16): sixteen partial sums
/// per column, added up after the pass.
[[gnu::always_inline]] inline void panel_dots(const float* __restrict a0, const float* __restrict a1, const float* __restrict a2,
                                              const float* __restrict a3, const float* __restrict z, int n, float* d) noexcept {
  float d0[16] = {}, d1[16] = {}, d2[16] = {}, d3[16] = {};
  for (int b = 0; b < n; b += 16) {
#pragma omp simd
    for (int t = 0; t < 16; ++t) {
      const float zi = z[b + t];
      d0[t] += a0[b + t] * zi;
      d1[t] += a1[b + t] * zi;
      d2[t] += a2[b + t] * zi;
      d3[t] += a3[b + t] * zi;
    }
  }
  float e0 = 0.0f, e1 = 0.0f, e2 = 0.0f, e3 = 0.0f;
#pragma omp simd reduction(+ : e0, e1, e2, e3)
  for (int t = 0; t < 16; ++t) e0 += d0[t], e1 += d1[t], e2 += d2[t], e3 += d3[t];
  d[0] = e0, d[1] = e1, d[2] = e2, d[3] = e3;
}

/// L y = b then Lᵀ x = y in place on x (single precision) with the blocks of
/// `invert_supernode_blocks` (64-byte aligned): per supernode (columns k1 …, rows ls[psi …])
/// forward
///   y_s ← T⁻¹ y_s,  y_b −= R y_s,
/// then backward, supernodes in reverse,
///   x_s ← T⁻ᵀ (x_s − Rᵀ x_b),
/// each a dense product of independent columns over whole 16-float vectors: four columns per
/// pass for T⁻¹ y_s and R y_s, four dot products per pass for the transposed ones; a narrow
/// supernode with its whole inverted block W = [T⁻¹; −R T⁻¹] in one product each way,
///   r = W y_s, y_s ← r_top, y_b += r_below;   x_s ← Wᵀ [x_s; x_b].
/// `top` has room for the widest supernode and 16 more, `bottom` for the tallest and 16 more.
KERF_VECTOR_CLONES
void inverse_block_forward(const cholmod_factor& L, const float* blocks, const std::ptrdiff_t* at, float* x, float* top,
                           float* bottom, bool skip_zero) noexcept {
  const int* super = static_cast<const int*>(L.super);
  const int* pi = static_cast<const int*>(L.pi);
  const int* ls = static_cast<const int*>(L.s);
  const auto nsuper = static_cast<int>(L.nsuper);
  const auto column = [](const float* p, int t, int stride) { return p + static_cast<std::ptrdiff_t>(t) * stride; };
  // Forward: L y = b.
  for (int s = 0; s < nsuper; ++s) {
    const int k1 = super[s], nscol = super[s + 1] - k1, psi = pi[s], m = pi[s + 1] - psi - nscol;
    const int pb = panel_rows(m);
    float* xs = x + k1;
    if (skip_zero && std::all_of(xs, xs + nscol, [](float v) { return v == 0.0f; })) continue; // nothing to carry down
    // x_s's entry j, zero past the supernode's last column (a panel pass takes four columns)
    const auto xj = [xs, nscol](int j) { return j < nscol ? xs[j] : 0.0f; };
    if (whole_inverted_block(nscol)) {
      // r = W x_s,  x_s ← r_top,  x_b += r_below  (W's lower part is −R T⁻¹)
      const int nsrow = nscol + m;
      float* r = bottom;
      std::fill(r, r + nsrow + 16, 0.0f);
      const float* panel = blocks + at[s];
      for (int c = 0; c < nscol; c += 4) {
        const int padded = panel_rows(nsrow - c);
        panel_product(panel, column(panel, 1, padded), column(panel, 2, padded), column(panel, 3, padded), xs[c], xj(c + 1),
                      xj(c + 2), xj(c + 3), padded, r + c);
        panel += 4 * static_cast<std::ptrdiff_t>(padded);
      }
      for (int j = 0; j < nscol; ++j) xs[j] = r[j];
      const int* __restrict below = ls + psi + nscol;
#pragma omp simd
      for (int i = 0; i < m; ++i) x[below[i]] += r[nscol + i];
      continue;
    }
    // x_s ← T⁻¹ x_s (past the supernode's last column the panel is zero: its x is not read)
    std::fill(top, top + nscol + 16, 0.0f);
    const float* panel = blocks + at[s];
    for (int c = 0; c < nscol; c += 4) {
      const int pt = panel_rows(nscol - c), stride = pt + pb;
      panel_product(panel, column(panel, 1, stride), column(panel, 2, stride), column(panel, 3, stride), xs[c], xj(c + 1),
                    xj(c + 2), xj(c + 3), pt, top + c);
      panel += 4 * static_cast<std::ptrdiff_t>(stride);
    }
    for (int j = 0; j < nscol; ++j) xs[j] = top[j];
    if (m == 0) continue;
    // x_b −= R x_s
    std::fill(bottom, bottom + pb, 0.0f);
    panel = blocks + at[s];
    for (int c = 0; c < nscol; c += 4) {
      const int pt = panel_rows(nscol - c), stride = pt + pb;
      panel_product(panel + pt, column(panel, 1, stride) + pt, column(panel, 2, stride) + pt, column(panel, 3, stride) + pt, xs[c],
                    xj(c + 1), xj(c + 2), xj(c + 3), pb, bottom);
      panel += 4 * static_cast<std::ptrdiff_t>(stride);
    }
    const int* __restrict below = ls + psi + nscol;
    // the rows below are distinct: the scatter vectorises
#pragma omp simd
    for (int i = 0; i < m; ++i) x[below[i]] -= bottom[i];
  }
}

/// The backward half of inverse_block_solve: Lᵀ x = y in place.
KERF_VECTOR_CLONES
void inverse_block_backward(const cholmod_factor& L, const float* blocks, const std::ptrdiff_t* at, float* x, float* top,
                            float* bottom) noexcept {
  const int* super = static_cast<const int*>(L.super);
  const int* pi = static_cast<const int*>(L.pi);
  const int* ls = static_cast<const int*>(L.s);
  const auto nsuper = static_cast<int>(L.nsuper);
  const auto column = [](const float* p, int t, int stride) { return p + static_cast<std::ptrdiff_t>(t) * stride; };
  // Backward: Lᵀ x = y.
  float d[4];
  for (int s = nsuper - 1; s >= 0; --s) {
    const int k1 = super[s], nscol = super[s + 1] - k1, psi = pi[s], m = pi[s + 1] - psi - nscol;
    const int pb = panel_rows(m);
    float* xs = x + k1;
    if (whole_inverted_block(nscol)) {
      // x_s ← Wᵀ [x_s; x_b]
      const int nsrow = nscol + m;
      float* z = bottom;
      for (int j = 0; j < nscol; ++j) z[j] = xs[j];
      const int* __restrict below = ls + psi + nscol;
#pragma omp simd
      for (int i = 0; i < m; ++i) z[nscol + i] = x[below[i]];
      std::fill(z + nsrow, z + nsrow + 16, 0.0f);
      const float* panel = blocks + at[s];
      for (int c = 0; c < nscol; c += 4) {
        const int padded = panel_rows(nsrow - c);
        panel_dots(panel, column(panel, 1, padded), column(panel, 2, padded), column(panel, 3, padded), z + c, padded, d);
        for (int t = 0; t < 4 && c + t < nscol; ++t) xs[c + t] = d[t];
        panel += 4 * static_cast<std::ptrdiff_t>(padded);
      }
      continue;
    }
    // u = x_s − Rᵀ x_b into top
    for (int j = 0; j < nscol; ++j) top[j] = xs[j];
    std::fill(top + nscol, top + nscol + 16, 0.0f);
    const float* panel = blocks + at[s];
    if (m > 0) {
      const int* __restrict below = ls + psi + nscol;
#pragma omp simd
      for (int i = 0; i < m; ++i) bottom[i] = x[below[i]];
      std::fill(bottom + m, bottom + pb, 0.0f);
      for (int c = 0; c < nscol; c += 4) {
        const int pt = panel_rows(nscol - c), stride = pt + pb;
        panel_dots(panel + pt, column(panel, 1, stride) + pt, column(panel, 2, stride) + pt, column(panel, 3, stride) + pt, bottom, pb, d);
        for (int t = 0; t < 4 && c + t < nscol; ++t) top[c + t] -= d[t];
        panel += 4 * static_cast<std::ptrdiff_t>(stride);
      }
    }
    // x_s ← T⁻ᵀ u
    panel = blocks + at[s];
    for (int c = 0; c < nscol; c += 4) {
      const int pt = panel_rows(nscol - c), stride = pt + pb;
      panel_dots(panel, column(panel, 1, stride), column(panel, 2, stride), column(panel, 3, stride), top + c, pt, d);
      for (int t = 0; t < 4 && c + t < nscol; ++t) xs[c + t] = d[t];
      panel += 4 * static_cast<std::ptrdiff_t>(stride);
    }
  }
}

/// L y = b then Lᵀ x = y in place on x (single precision): inverse_block_forward, then
/// inverse_block_backward.
void inverse_block_solve(const cholmod_factor& L, const float* blocks, const std::ptrdiff_t* at, float* x, float* top,
                         float* bottom) noexcept {
  inverse_block_forward(L, blocks, at, x, top, bottom, false);
  inverse_block_backward(L, blocks, at, x, top, bottom);
}

} // namespace

bool NetworkSystem::factorize() noexcept {
  if (m_bound_decoupled) return m_factorized = false; // the matrix is not the torn network's: rebuild
  if (!m_factor) return m_factorized = dof_count() == 0;
  {
    // OpenBLAS's pool would allocate per call and put its threads on the servo's critical path.
    const SingleThreadedBlas single;
    // LLᵀ = A, A already in the factor's order.
    m_factorized = m_numeric.factorize(supernodal_structure(*m_factor), {m_matrix.outerIndexPtr(), m_matrix.innerIndexPtr(), m_matrix.valuePtr()},
                                       static_cast<double*>(m_factor->x));
  }
  if (m_factorized) {
    const double* lx = static_cast<const double*>(m_factor->x);
    // 1 / L_kk for the solves, from the double-precision diagonal.
    const int* super = static_cast<const int*>(m_factor->super);
    const int* pi = static_cast<const int*>(m_factor->pi);
    const int* px = static_cast<const int*>(m_factor->px);
    for (std::size_t sn = 0; sn < m_factor->nsuper; ++sn) {
      const int nsrow = pi[sn + 1] - pi[sn];
      for (int j = 0; j < super[sn + 1] - super[sn]; ++j)
        m_inverse_diagonal[static_cast<std::size_t>(super[sn] + j)] = 1.0 / lx[px[sn] + static_cast<std::ptrdiff_t>(j) * (nsrow + 1)];
    }
    if (m_precision == SolvePrecision::single_precision)
      invert_supernode_blocks(*m_factor, lx, m_inverse_diagonal.data(), m_inverse_block_at.data(), m_inverse_column.data(),
                              m_inverse_blocks.data() + m_inverse_align);
    // The decoupled shadows' block: L = √A_dd there.
    const double* values = m_matrix.valuePtr();
    for (int d = m_factor_dofs; d < dof_count(); ++d) {
      const double a = values[m_diagonal[static_cast<std::size_t>(d)]];
      if (!(a > 0.0) || !std::isfinite(a)) return m_factorized = false;
      m_shadow_inverse_root[static_cast<std::size_t>(d - m_factor_dofs)] = 1.0 / std::sqrt(a);
    }
  }
  return m_factorized;
}

namespace {

/// y[0, m) −= Σ_{c < n} cols[c][0, m) x[c] (cols[c] = cols[0] + c stride): a block of L's
/// columns times the solved part of x, four columns per pass so that y is read and written
/// once per four columns.
template <class Value, class Real>
[[gnu::always_inline]] inline void subtract_block_product(const Value* cols, std::ptrdiff_t stride, const Real* x, int n, int m,
                                                          Real* __restrict y) noexcept {
  int c = 0;
  for (; c + 4 <= n; c += 4) {
    const Value* __restrict a0 = cols + c * stride;
    const Value* __restrict a1 = a0 + stride;
    const Value* __restrict a2 = a1 + stride;
    const Value* __restrict a3 = a2 + stride;
    const Real x0 = x[c], x1 = x[c + 1], x2 = x[c + 2], x3 = x[c + 3];
#pragma omp simd
    for (int i = 0; i < m; ++i)
      y[i] -= (static_cast<Real>(a0[i]) * x0 + static_cast<Real>(a1[i]) * x1) +
              (static_cast<Real>(a2[i]) * x2 + static_cast<Real>(a3[i]) * x3);
  }
  for (; c < n; ++c) {
    const Value* __restrict a0 = cols + c * stride;
    const Real x0 = x[c];
#pragma omp simd
    for (int i = 0; i < m; ++i) y[i] -= static_cast<Real>(a0[i]) * x0;
  }
}

/// out[c] = cols[c][0, m) · y[0, m) for c < n: the transposed product, four dot products per
/// pass over y (one horizontal sum per column, the loads of y shared).
template <class Value, class Real>
[[gnu::always_inline]] inline void transposed_block_product(const Value* cols, std::ptrdiff_t stride, const Real* __restrict y,
                                                            int n, int m, Real* out) noexcept {
  int c = 0;
  for (; c + 4 <= n; c += 4) {
    const Value* __restrict a0 = cols + c * stride;
    const Value* __restrict a1 = a0 + stride;
    const Value* __restrict a2 = a1 + stride;
    const Value* __restrict a3 = a2 + stride;
    Real d0 = 0, d1 = 0, d2 = 0, d3 = 0;
#pragma omp simd reduction(+ : d0, d1, d2, d3)
    for (int i = 0; i < m; ++i) {
      const Real yi = y[i];
      d0 += static_cast<Real>(a0[i]) * yi;
      d1 += static_cast<Real>(a1[i]) * yi;
      d2 += static_cast<Real>(a2[i]) * yi;
      d3 += static_cast<Real>(a3[i]) * yi;
    }
    out[c] = d0, out[c + 1] = d1, out[c + 2] = d2, out[c + 3] = d3;
  }
  for (; c < n; ++c) {
    const Value* __restrict a0 = cols + c * stride;
    Real d0 = 0;
#pragma omp simd reduction(+ : d0)
    for (int i = 0; i < m; ++i) d0 += static_cast<Real>(a0[i]) * y[i];
    out[c] = d0;
  }
}

/// L y = b then Lᵀ x = y in place on x, on a supernodal L whose values are `lx`, in the
/// arithmetic of `Real` (used in double on CHOLMOD's factor: the quasi-static integrator's solve;
/// the single-precision solve is inverse_block_solve).
/// Supernode s has columns [k1, k2) and a dense column-major block of nsrow rows (row indices
/// ls[psi ..]): the first nscol rows are its diagonal triangle, the rest the rows below it. `inverse_diagonal` holds 1 / L_kk (no division
/// on the solve's path); `below` has room for the tallest supernode, `dots` for the widest.
///
/// Both off-diagonal products (L_bs x_s forward, L_bsᵀ x_b backward) take four columns per pass,
/// and the diagonal triangles are solved four columns at a time: forward, the 4 x 4 triangle and
/// then one pass updating the rows below it; backward, one pass of the four columns' dot
/// products with the part of x already solved, then the 4 x 4 triangle.
template <class Value, class Real>
[[gnu::always_inline]] inline void supernodal_solve(const cholmod_factor& L, const Value* lx, const Real* inverse_diagonal,
                                                    Real* x, Real* below, Real* dots) noexcept {
  const int* super = static_cast<const int*>(L.super);
  const int* pi = static_cast<const int*>(L.pi);
  const int* px = static_cast<const int*>(L.px);
  const int* ls = static_cast<const int*>(L.s);
  const auto nsuper = static_cast<int>(L.nsuper);
  // Forward: L y = b.
  for (int s = 0; s < nsuper; ++s) {
    const int k1 = super[s], nscol = super[s + 1] - k1, psi = pi[s], nsrow = pi[s + 1] - psi;
    const Value* block = lx + px[s];
    Real* __restrict xs = x + k1;
    // The diagonal triangle, columns [j0, j1) at a time: their 4 x 4 triangle, then the rows
    // below it in the supernode updated by the four solved values at once.
    for (int j0 = 0; j0 < nscol;) {
      const int j1 = std::min(nscol, j0 + 4);
      for (int j = j0; j < j1; ++j) {
        const Value* col = block + static_cast<std::ptrdiff_t>(j) * nsrow;
        const Real xj = xs[j] *= inverse_diagonal[k1 + j];
        for (int i = j + 1; i < j1; ++i) xs[i] -= static_cast<Real>(col[i]) * xj;
      }
      subtract_block_product(block + static_cast<std::ptrdiff_t>(j0) * nsrow + j1, nsrow, xs + j0, j1 - j0, nscol - j1, xs + j1);
      j0 = j1;
    }
    const int m = nsrow - nscol;
    if (m == 0) continue;
    std::fill(below, below + m, Real(0));
    subtract_block_product(block + nscol, nsrow, xs, nscol, m, below);
    for (int i = 0; i < m; ++i) x[ls[psi + nscol + i]] += below[i];
  }
  // Backward: Lᵀ x = y.
  for (int s = nsuper - 1; s >= 0; --s) {
    const int k1 = super[s], nscol = super[s + 1] - k1, psi = pi[s], nsrow = pi[s + 1] - psi;
    const Value* block = lx + px[s];
    Real* __restrict xs = x + k1;
    const int m = nsrow - nscol;
    if (m > 0) {
      for (int i = 0; i < m; ++i) below[i] = x[ls[psi + nscol + i]];
      transposed_block_product(block + nscol, nsrow, below, nscol, m, dots);
      for (int j = 0; j < nscol; ++j) xs[j] -= dots[j];
    }
    // The diagonal triangle, columns [j0, j1) at a time from the last.
    for (int j1 = nscol; j1 > 0;) {
      const int j0 = std::max(0, j1 - 4);
      transposed_block_product(block + static_cast<std::ptrdiff_t>(j0) * nsrow + j1, nsrow, xs + j1, j1 - j0, nscol - j1, dots);
      for (int j = j1 - 1; j >= j0; --j) {
        const Value* col = block + static_cast<std::ptrdiff_t>(j) * nsrow;
        Real dot = dots[j - j0];
        for (int i = j + 1; i < j1; ++i) dot += static_cast<Real>(col[i]) * xs[i];
        xs[j] = (xs[j] - dot) * inverse_diagonal[k1 + j];
      }
      j1 = j0;
    }
  }
}

KERF_VECTOR_CLONES
void supernodal_solve_double(const cholmod_factor& L, const double* lx, const double* inverse_diagonal, double* x, double* below,
                             double* dots) noexcept {
  supernodal_solve(L, lx, inverse_diagonal, x, below, dots);
}
} // namespace

template <class Value>
void NetworkSystem::scale_decoupled_shadows(Value* v, int power) const noexcept {
  for (int d = m_factor_dofs; d < dof_count(); ++d) {
    const double r = m_shadow_inverse_root[static_cast<std::size_t>(d - m_factor_dofs)];
    v[d] = static_cast<Value>(static_cast<double>(v[d]) * (power == 2 ? r * r : r));
  }
}

void NetworkSystem::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out) noexcept {
  const int n = dof_count();
  if (n == 0) return;
  // The system is in the factor's order already: no permutation.
  if (m_precision == SolvePrecision::double_precision) {
    std::copy(rhs.data(), rhs.data() + n, out.data());
    supernodal_solve_double(*m_factor, static_cast<const double*>(m_factor->x), m_inverse_diagonal.data(), out.data(), m_below.data(),
                            m_dots.data());
    scale_decoupled_shadows(out.data(), 2);
    return;
  }
  for (int k = 0; k < n; ++k) m_solution_single[static_cast<std::size_t>(k)] = static_cast<float>(rhs[k]);
  solve_in_place();
  for (int k = 0; k < n; ++k) out[k] = static_cast<double>(m_solution_single[static_cast<std::size_t>(k)]);
}

bool NetworkSystem::forward_solve_in_place(float* y) noexcept {
  if (m_precision != SolvePrecision::single_precision) return false;
  if (dof_count() == 0) return true;
  inverse_block_forward(*m_factor, m_inverse_blocks.data() + m_inverse_align, m_inverse_block_at.data(), y, m_rows_single.data(),
                        m_rows_single.data() + m_rows_split, true);
  scale_decoupled_shadows(y, 1);
  return true;
}

bool NetworkSystem::backward_solve_in_place(float* x) noexcept {
  if (m_precision != SolvePrecision::single_precision) return false;
  if (dof_count() == 0) return true;
  inverse_block_backward(*m_factor, m_inverse_blocks.data() + m_inverse_align, m_inverse_block_at.data(), x, m_rows_single.data(),
                         m_rows_single.data() + m_rows_split);
  scale_decoupled_shadows(x, 1);
  return true;
}

bool NetworkSystem::solve_in_place() noexcept {
  if (m_precision != SolvePrecision::single_precision) return false;
  if (dof_count() == 0) return true;
  inverse_block_solve(*m_factor, m_inverse_blocks.data() + m_inverse_align, m_inverse_block_at.data(), m_solution_single.data(),
                      m_rows_single.data(), m_rows_single.data() + m_rows_split);
  scale_decoupled_shadows(m_solution_single.data(), 2);
  return true;
}

} // namespace kerf

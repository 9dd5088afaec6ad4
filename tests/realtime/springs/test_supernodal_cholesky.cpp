// SupernodalCholesky (realtime/springs/supernodal_cholesky.hpp) against two independent checks:
// CHOLMOD's own numeric supernodal factorisation on the same symbolic structure (a second
// implementation of the same algorithm: the factor is unique, so the values must agree to
// round-off), and the defining identity L Lᵀ = P A Pᵀ applied to vectors.

#include "realtime/springs/cholmod_view.hpp"
#include "realtime/springs/supernodal_cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/SparseCore>

#include <random>
#include <vector>

using namespace kerf;

namespace {

using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// A symmetric positive definite test matrix with a 3D structure like the networks': the 27-point
/// stencil on an m³ grid, 3 unknowns per point coupled in full (as the 28-spring cells couple a
/// node's axes), random off-diagonal weights, diagonal dominance by `shift`.
Sparse grid_matrix(int m, double shift, unsigned seed) {
  const int points = m * m * m, n = 3 * points;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> weight(-1.0, 0.0);
  std::vector<Eigen::Triplet<double, int>> entries;
  std::vector<double> row_sum(static_cast<std::size_t>(n), 0.0);
  const auto at = [m](int x, int y, int z) { return x + m * (y + m * z); };
  for (int z = 0; z < m; ++z)
    for (int y = 0; y < m; ++y)
      for (int x = 0; x < m; ++x)
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int X = x + dx, Y = y + dy, Z = z + dz;
              if (X < 0 || Y < 0 || Z < 0 || X >= m || Y >= m || Z >= m) continue;
              const int p = at(x, y, z), q = at(X, Y, Z);
              if (q >= p) continue; // each pair once
              for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                  const double w = weight(random);
                  entries.emplace_back(3 * p + i, 3 * q + j, w);
                  entries.emplace_back(3 * q + j, 3 * p + i, w);
                  row_sum[static_cast<std::size_t>(3 * p + i)] += -w;
                  row_sum[static_cast<std::size_t>(3 * q + j)] += -w;
                }
            }
  for (int k = 0; k < n; ++k) entries.emplace_back(k, k, row_sum[static_cast<std::size_t>(k)] + shift);
  Sparse a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();
  return a;
}

/// A supernodal analysis of A (AMD ordering) kept with its CHOLMOD workspace.
class Analysis {
public:
  explicit Analysis(Sparse& lower) {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_AMD;
    common.print = 0;
    cholmod_sparse a = cholmod_view(lower, -1);
    factor = cholmod_analyze(&a, &common);
  }
  ~Analysis() {
    cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
  Analysis(const Analysis&) = delete;
  Analysis& operator=(const Analysis&) = delete;
  [[nodiscard]] SupernodalStructure structure() const { return supernodal_structure(*factor); }
  [[nodiscard]] const int* permutation() const { return static_cast<const int*>(factor->Perm); }
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
};

/// The lower triangle of P A Pᵀ (row k of the result is row perm[k] of A).
Sparse permuted_lower(const Sparse& full, const int* perm) {
  const int n = static_cast<int>(full.rows());
  std::vector<int> inverse(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) inverse[static_cast<std::size_t>(perm[k])] = k;
  std::vector<Eigen::Triplet<double, int>> entries;
  for (int c = 0; c < n; ++c)
    for (Sparse::InnerIterator it(full, c); it; ++it) {
      const int r = inverse[static_cast<std::size_t>(it.row())], cc = inverse[static_cast<std::size_t>(c)];
      if (r >= cc) entries.emplace_back(r, cc, it.value());
    }
  Sparse lower(n, n);
  lower.setFromTriplets(entries.begin(), entries.end());
  lower.makeCompressed();
  return lower;
}

/// The lower triangle of `full`, compressed.
Sparse lower_triangle(const Sparse& full) {
  Sparse lower = full.triangularView<Eigen::Lower>();
  lower.makeCompressed();
  return lower;
}

/// SupernodalCholesky on `lower` (in the factor's order) with fresh workspaces for `analysis`.
bool factorize_fresh(const Analysis& analysis, Sparse& lower, SupernodalCholesky& cholesky) {
  cholesky.analyse(analysis.structure());
  std::vector<double> lx(analysis.factor->xsize);
  return cholesky.factorize(analysis.structure(), {lower.outerIndexPtr(), lower.innerIndexPtr(), lower.valuePtr()}, lx.data());
}

/// y = L x, or y = Lᵀ x (`transposed`), for a supernodal L stored as `s` says, values `lx`.
Eigen::VectorXd apply_factor(const SupernodalStructure& s, const std::vector<double>& lx, const Eigen::VectorXd& x, bool transposed) {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(x.size());
  for (int sn = 0; sn < s.supernodes; ++sn) {
    const int nsrow = s.row_start[sn + 1] - s.row_start[sn];
    for (int j = s.super[sn]; j < s.super[sn + 1]; ++j) {
      const double* column = lx.data() + s.value_start[sn] + static_cast<std::ptrdiff_t>(j - s.super[sn]) * nsrow;
      for (int k = j - s.super[sn]; k < nsrow; ++k) {
        const int i = s.rows[s.row_start[sn] + k]; // L_ij = column[k]
        if (transposed)
          y[j] += column[k] * x[i];
        else
          y[i] += column[k] * x[j];
      }
    }
  }
  return y;
}
/// L Lᵀ x.
Eigen::VectorXd apply_llt(const SupernodalStructure& s, const std::vector<double>& lx, const Eigen::VectorXd& x) {
  return apply_factor(s, lx, apply_factor(s, lx, x, true), false);
}

} // namespace

TEST(SupernodalCholesky, AgreesWithCholmodAndReproducesTheMatrix) {
  // 6³ points x 3 = 648 unknowns: supernodes from 1 to ~100 columns, many descendants each.
  Sparse full = grid_matrix(6, 0.5, 7u);
  Sparse lower = lower_triangle(full);
  Analysis analysis(lower);
  ASSERT_NE(analysis.factor, nullptr);
  ASSERT_TRUE(analysis.factor->is_super);
  const SupernodalStructure s = analysis.structure();
  ASSERT_GT(s.supernodes, 10);

  // CHOLMOD's numeric factorisation, as the reference.
  cholmod_sparse a = cholmod_view(lower, -1);
  ASSERT_TRUE(cholmod_factorize(&a, analysis.factor, &analysis.common));
  ASSERT_EQ(analysis.common.status, CHOLMOD_OK);
  const auto* cholmod_x = static_cast<const double*>(analysis.factor->x);

  // kerf's, on P A Pᵀ.
  Sparse permuted = permuted_lower(full, analysis.permutation());
  SupernodalCholesky cholesky;
  cholesky.analyse(s);
  std::vector<double> lx(analysis.factor->xsize, -1.0);
  ASSERT_TRUE(cholesky.factorize(s, {permuted.outerIndexPtr(), permuted.innerIndexPtr(), permuted.valuePtr()}, lx.data()));
  EXPECT_EQ(cholesky.failed_column(), -1);

  // Every entry of L, including the structural zeros of the dense blocks, against CHOLMOD's.
  double largest = 0.0, difference = 0.0;
  for (std::size_t k = 0; k < lx.size(); ++k) {
    largest = std::max(largest, std::abs(cholmod_x[k]));
    difference = std::max(difference, std::abs(lx[k] - cholmod_x[k]));
  }
  EXPECT_LT(difference, 1e-13 * largest) << "largest |L_ij| " << largest;

  // L (Lᵀ x) = P A Pᵀ x for random x.
  std::mt19937 random(11u);
  std::normal_distribution<double> normal;
  Sparse permuted_full = permuted.selfadjointView<Eigen::Lower>();
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd x(s.n);
    for (int k = 0; k < s.n; ++k) x[k] = normal(random);
    const Eigen::VectorXd ax = permuted_full * x;
    const Eigen::VectorXd llx = apply_llt(s, lx, x);
    EXPECT_LT((llx - ax).norm(), 1e-13 * ax.norm());
  }

  // The same object factorises a second matrix on the same structure (workspaces reused).
  Sparse full2 = grid_matrix(6, 2.0, 8u);
  Sparse permuted2 = permuted_lower(full2, analysis.permutation());
  ASSERT_TRUE(cholesky.factorize(s, {permuted2.outerIndexPtr(), permuted2.innerIndexPtr(), permuted2.valuePtr()}, lx.data()));
  Eigen::VectorXd x = Eigen::VectorXd::Ones(s.n);
  Sparse permuted2_full = permuted2.selfadjointView<Eigen::Lower>();
  EXPECT_LT((apply_llt(s, lx, x) - permuted2_full * x).norm(), 1e-13 * (permuted2_full * x).norm());
}

TEST(SupernodalCholesky, RefusesAnIndefiniteMatrixAndNamesTheColumn) {
  Sparse full = grid_matrix(4, 0.5, 3u);
  Sparse lower = lower_triangle(full);
  Analysis analysis(lower);
  Sparse permuted = permuted_lower(full, analysis.permutation());
  // A negative diagonal entry in the last column: positive definite leading minors up to n − 1,
  // then a negative pivot (the Schur complement of a positive definite A is positive, so
  // lowering A_nn by more than A_nn itself makes the last pivot negative).
  const int last = static_cast<int>(full.rows()) - 1;
  permuted.coeffRef(last, last) = -permuted.coeff(last, last);
  SupernodalCholesky cholesky;
  EXPECT_FALSE(factorize_fresh(analysis, permuted, cholesky));
  EXPECT_EQ(cholesky.failed_column(), last);
}

TEST(SupernodalCholesky, RefusesAnEntryOutsideTheAnalysedPattern) {
  Sparse full = grid_matrix(4, 0.5, 5u);
  Sparse lower = lower_triangle(full);
  Analysis analysis(lower);
  const SupernodalStructure s = analysis.structure();
  // Find a (row, column) pair outside L's pattern and put an entry of A there.
  std::vector<std::vector<char>> in_l(static_cast<std::size_t>(s.n), std::vector<char>(static_cast<std::size_t>(s.n), 0));
  for (int sn = 0; sn < s.supernodes; ++sn)
    for (int j = s.super[sn]; j < s.super[sn + 1]; ++j)
      for (int k = s.row_start[sn]; k < s.row_start[sn + 1]; ++k) in_l[static_cast<std::size_t>(s.rows[k])][static_cast<std::size_t>(j)] = 1;
  int row = -1, column = -1;
  for (int j = 0; j < s.n && row < 0; ++j)
    for (int i = s.n - 1; i > j && row < 0; --i)
      if (!in_l[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]) row = i, column = j;
  ASSERT_GE(row, 0) << "the factor of this grid is not dense";
  Sparse permuted = permuted_lower(full, analysis.permutation());
  permuted.coeffRef(row, column) = 1e-3;
  permuted.makeCompressed();
  SupernodalCholesky cholesky;
  EXPECT_FALSE(factorize_fresh(analysis, permuted, cholesky));
}

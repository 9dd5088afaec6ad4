// SparseDirect (reference/sparse_direct.hpp): Cholesky for a symmetric positive definite matrix,
// LU for a symmetric indefinite and for an unsymmetric one, each checked against the exact
// solution of a system built from it (b = A x* for a chosen x*), and the symbolic analysis reused
// over new values of the same pattern.

#include "reference/sparse_direct.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace kerf::reference {
namespace {

// The 1-D Laplacian-like tridiagonal pattern of size n, each row's diagonal first (deal.II's order).
struct Tridiagonal {
  std::size_t n;
  std::vector<std::int64_t> row_start{0}, columns;
  explicit Tridiagonal(std::size_t size) : n(size) {
    for (std::size_t r = 0; r < n; ++r) {
      columns.push_back(static_cast<std::int64_t>(r));
      if (r > 0) columns.push_back(static_cast<std::int64_t>(r - 1));
      if (r + 1 < n) columns.push_back(static_cast<std::int64_t>(r + 1));
      row_start.push_back(static_cast<std::int64_t>(columns.size()));
    }
  }
  // Values: diagonal d(r), below l(r), above u(r).
  template <class D, class L, class U> std::vector<double> values(D d, L l, U u) const {
    std::vector<double> v;
    for (std::size_t r = 0; r < n; ++r) {
      v.push_back(d(r));
      if (r > 0) v.push_back(l(r));
      if (r + 1 < n) v.push_back(u(r));
    }
    return v;
  }
  std::vector<double> multiply(const std::vector<double>& v, const std::vector<double>& x) const {
    std::vector<double> b(n, 0.0);
    for (std::size_t r = 0; r < n; ++r)
      for (auto e = row_start[r]; e < row_start[r + 1]; ++e)
        b[r] += v[static_cast<std::size_t>(e)] * x[static_cast<std::size_t>(columns[static_cast<std::size_t>(e)])];
    return b;
  }
};

double solve_error(SparseDirect& solver, const Tridiagonal& t, const std::vector<double>& values) {
  std::vector<double> exact(t.n);
  for (std::size_t i = 0; i < t.n; ++i) exact[i] = std::sin(0.3 * static_cast<double>(i)) + 1.0;
  const std::vector<double> b = t.multiply(values, exact);
  solver.factorize(values);
  std::vector<double> x(t.n);
  solver.solve(b.data(), x.data());
  double error = 0.0;
  for (std::size_t i = 0; i < t.n; ++i) error = std::max(error, std::abs(x[i] - exact[i]));
  return error;
}

TEST(SparseDirect, CholeskyWhenSymmetricPositiveDefiniteLuOtherwise) {
  const Tridiagonal t(200);
  SparseDirect solver(t.n, t.row_start, t.columns);
  // SPD: 2 on the diagonal, -1 beside it.
  const auto spd = t.values([](std::size_t) { return 2.0; }, [](std::size_t) { return -1.0; }, [](std::size_t) { return -1.0; });
  EXPECT_LT(solve_error(solver, t, spd), 1e-9);
  EXPECT_EQ(solver.last_method(), "cholmod");
  // Symmetric indefinite: the diagonal changes sign half-way (Cholesky meets a negative pivot).
  const auto indefinite = t.values([&](std::size_t r) { return r < t.n / 2 ? 3.0 : -3.0; },
                                   [](std::size_t) { return 1.0; }, [](std::size_t) { return 1.0; });
  EXPECT_LT(solve_error(solver, t, indefinite), 1e-9);
  EXPECT_EQ(solver.last_method(), "umfpack");
  EXPECT_EQ(solver.counters().not_positive_definite, 1);
  // Unsymmetric: LU directly (no Cholesky attempt).
  const auto unsymmetric = t.values([](std::size_t) { return 4.0; }, [](std::size_t) { return -1.0; }, [](std::size_t) { return -2.0; });
  EXPECT_LT(solve_error(solver, t, unsymmetric), 1e-9);
  EXPECT_EQ(solver.last_method(), "umfpack");
  EXPECT_EQ(solver.counters().not_positive_definite, 1);
  // The same SPD matrix again: Cholesky, the analysis of the first call reused (same answer).
  EXPECT_LT(solve_error(solver, t, spd), 1e-9);
  EXPECT_EQ(solver.last_method(), "cholmod");
  EXPECT_EQ(solver.counters().cholesky, 2);
  EXPECT_EQ(solver.counters().lu, 2);
}

// The predicted factor size against closed forms: a tridiagonal matrix's Cholesky factor has no
// fill under an ordering that eliminates a path from its ends (minimum degree does), so L holds
// the n diagonal and n − 1 subdiagonal entries; a dense matrix's L is its whole lower triangle,
// n (n + 1)/2 entries. Values follow, and the analysis is kept: a factorisation then works.
TEST(SparseDirect, PredictsTheCholeskyFactorsEntries) {
  const Tridiagonal t(300);
  SparseDirect tridiagonal(t.n, t.row_start, t.columns);
  EXPECT_EQ(tridiagonal.cholesky_factor_entries(), 2.0 * 300 - 1);
  const auto spd = t.values([](std::size_t) { return 2.0; }, [](std::size_t) { return -1.0; }, [](std::size_t) { return -1.0; });
  EXPECT_LT(solve_error(tridiagonal, t, spd), 1e-9);
  EXPECT_EQ(tridiagonal.counters().cholesky, 1);

  const std::size_t n = 40;
  std::vector<std::int64_t> row_start{0}, columns;
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t c = 0; c < n; ++c) columns.push_back(static_cast<std::int64_t>(c));
    row_start.push_back(static_cast<std::int64_t>(columns.size()));
  }
  SparseDirect dense(n, row_start, columns);
  EXPECT_EQ(dense.cholesky_factor_entries(), static_cast<double>(n * (n + 1) / 2));
  // Without a solver (the distributed automatic choice's prediction): the same closed forms.
  EXPECT_EQ(SparseDirect::predict_cholesky_factor_entries(t.n, t.row_start, t.columns), 2.0 * 300 - 1);
  EXPECT_EQ(SparseDirect::predict_cholesky_factor_entries(n, row_start, columns), static_cast<double>(n * (n + 1) / 2));
}

// The prediction without a solver is the solver's own (one analysis of one lower triangle), on a
// pattern with fill: the 7-point stencil of a 12 × 12 × 12 grid, each row's diagonal first.
TEST(SparseDirect, PredictionWithoutASolverIsTheSolversOwn) {
  const int m = 12;
  const auto index = [&](int i, int j, int k) { return static_cast<std::int64_t>((k * m + j) * m + i); };
  std::vector<std::int64_t> row_start{0}, columns;
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        columns.push_back(index(i, j, k));
        for (const auto& [di, dj, dk] : {std::array{-1, 0, 0}, std::array{1, 0, 0}, std::array{0, -1, 0}, std::array{0, 1, 0},
                                         std::array{0, 0, -1}, std::array{0, 0, 1}})
          if (i + di >= 0 && i + di < m && j + dj >= 0 && j + dj < m && k + dk >= 0 && k + dk < m)
            columns.push_back(index(i + di, j + dj, k + dk));
        row_start.push_back(static_cast<std::int64_t>(columns.size()));
      }
  const std::size_t n = static_cast<std::size_t>(m * m * m);
  SparseDirect solver(n, row_start, columns);
  const double entries = solver.cholesky_factor_entries();
  EXPECT_GT(entries, static_cast<double>(columns.size() + n) / 2.0); // fill: more than the lower triangle
  EXPECT_EQ(SparseDirect::predict_cholesky_factor_entries(n, row_start, columns), entries);
}

TEST(SparseDirect, RefusesValuesThatDoNotMatchThePattern) {
  const Tridiagonal t(5);
  SparseDirect solver(t.n, t.row_start, t.columns);
  EXPECT_THROW(solver.factorize(std::vector<double>(3, 1.0)), std::invalid_argument);
  EXPECT_THROW(SparseDirect(4, t.row_start, t.columns), std::invalid_argument);
}

} // namespace
} // namespace kerf::reference

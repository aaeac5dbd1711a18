// SparseCholesky's dense path for small systems (runtime/dense_cholesky.h) against its
// CHOLMOD path on the same matrices: solutions, errors for indefinite and non-finite
// matrices, which systems take which path, and the float copy of large factors. Its
// factorisation (dgtex/kernels/dense_cholesky_factor.h) and triangular solves
// (dgtex/kernels/dense_cholesky_solve.h, with the factor in double and in float) are
// bitwise their references on every path the machine supports, and Eigen's LLT and solves
// to round-off (double) or to float's rounding of L.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "dgtex/kernels/dense_cholesky_factor.h"
#include "dgtex/kernels/dense_cholesky_solve.h"
#include "dgtex/sparse_cholesky.h"
#include "vector_path_support.h"
#include "thread_count_support.h"

namespace {

struct LowerCsc {
  int n = 0;
  std::vector<int> column_start, row_index;
  std::vector<double> values;
};

// The lower triangle of `a`, entries with |a_ij| > 0 (and the diagonal) kept.
LowerCsc lower_csc(const Eigen::MatrixXd& a) {
  LowerCsc m;
  m.n = static_cast<int>(a.rows());
  for (int j = 0; j < m.n; ++j) {
    m.column_start.push_back(static_cast<int>(m.row_index.size()));
    for (int i = j; i < m.n; ++i)
      if (i == j || a(i, j) != 0) m.row_index.push_back(i), m.values.push_back(a(i, j));
  }
  m.column_start.push_back(static_cast<int>(m.row_index.size()));
  return m;
}

Eigen::MatrixXd random_spd(int n, int bandwidth, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = j + 1; i < std::min(n, j + 1 + bandwidth); ++i) a(i, j) = a(j, i) = u(rng);
  for (int i = 0; i < n; ++i) a(i, i) = a.row(i).cwiseAbs().sum() + 1.0;  // diagonally dominant
  return a;
}

std::vector<double> solve_with(int dense_max, const LowerCsc& m, const std::vector<double>& b, bool* dense) {
  dgtex::SparseCholesky c(dense_max);
  c.analyze(m.n, m.column_start, m.row_index);
  c.factorize(m.values);
  if (dense) *dense = c.dense();
  std::vector<double> x;
  c.solve(b, x);
  return x;
}

double relative_difference(const std::vector<double>& x, const std::vector<double>& y) {
  double d = 0, s = 0;
  for (std::size_t i = 0; i < x.size(); ++i) d += (x[i] - y[i]) * (x[i] - y[i]), s += y[i] * y[i];
  return std::sqrt(d / s);
}

}  // namespace

TEST(DenseCholesky, SolvesLikeCholmodOnSmallSystems) {
  // A cut single element (39 unknowns, dense), a small banded system, an accordion-sized one.
  for (auto [n, band] : {std::pair{39, 39}, std::pair{120, 6}, std::pair{441, 441}}) {
    const LowerCsc m = lower_csc(random_spd(n, band, 7u + n));
    std::vector<double> b(n);
    for (int i = 0; i < n; ++i) b[i] = std::sin(0.3 * i) + 0.1;
    bool dense = false, cholmod_dense = true;
    const std::vector<double> x = solve_with(512, m, b, &dense);
    const std::vector<double> reference = solve_with(0, m, b, &cholmod_dense);
    EXPECT_TRUE(dense) << n;
    EXPECT_FALSE(cholmod_dense) << n;
    EXPECT_LT(relative_difference(x, reference), 1e-12) << n;
  }
}

TEST(DenseCholesky, DoesNotDependOnTheThreadCount) {
  // The factor (kernels::dense_cholesky_factor, serial) must not depend on the OpenMP
  // thread count.
  const LowerCsc m = lower_csc(random_spd(441, 441, 19u));
  std::vector<double> b(441);
  for (int i = 0; i < 441; ++i) b[i] = std::cos(0.7 * i);
  std::vector<std::vector<double>> x;
  for (int threads : {1, 2, 4}) {
    const dgtex::test::ThreadCountGuard set_threads(threads);
    bool dense = false;
    x.push_back(solve_with(512, m, b, &dense));
    EXPECT_TRUE(dense);
  }
  EXPECT_EQ(x[0], x[1]);
  EXPECT_EQ(x[0], x[2]);
}

TEST(DenseCholesky, LargeOrSparseSystemsStayWithCholmod) {
  bool dense = true;
  const LowerCsc sparse = lower_csc(random_spd(400, 3, 3u));  // 400 unknowns, < 1/4 of the triangle
  solve_with(512, sparse, std::vector<double>(400, 1.0), &dense);
  EXPECT_FALSE(dense);
  const LowerCsc large = lower_csc(random_spd(600, 600, 5u));
  solve_with(512, large, std::vector<double>(600, 1.0), &dense);
  EXPECT_FALSE(dense);
}

TEST(DenseCholesky, SinglePrecisionSolveIsTheDoubleSolveBelow256Unknowns) {
  const LowerCsc m = lower_csc(random_spd(60, 60, 11u));
  dgtex::SparseCholesky c;
  c.analyze(m.n, m.column_start, m.row_index);
  c.factorize(m.values);
  c.copy_factor_to_single_precision();
  std::vector<double> b(60, 1.0), x, y;
  c.solve(b, x);
  c.solve_single_precision(b, y);
  EXPECT_EQ(x, y);
  EXPECT_EQ(c.factor_nonzeros(), 60 * 61 / 2);
}

TEST(DenseCholesky, LargeFactorsPreconditionWithAFloatCopyOfTheCurrentFactor) {
  // 300 unknowns, fully coupled: dense, and at least 256 unknowns, so a float copy is made.
  const int n = 300;
  const Eigen::MatrixXd a = random_spd(n, n, 23u);
  const LowerCsc m = lower_csc(a);
  dgtex::SparseCholesky c;
  c.analyze(m.n, m.column_start, m.row_index);
  ASSERT_TRUE(c.dense());
  c.factorize(m.values);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> b(n), x, y;
  for (double& v : b) v = u(rng);
  c.solve(b, x);
  c.copy_factor_to_single_precision();
  c.solve_single_precision(b, y);
  double largest = 0, difference = 0;
  for (int i = 0; i < n; ++i) {
    largest = std::max(largest, std::abs(x[i]));
    difference = std::max(difference, std::abs(y[i] - x[i]));
  }
  EXPECT_NE(x, y);  // the float copy is used
  EXPECT_LE(difference, 1e-6 * largest);  // float's rounding of L (a well-conditioned matrix)
  // A new factorisation drops the copy: until the next copy, the double factor is used.
  c.factorize(m.values);
  c.solve_single_precision(b, y);
  EXPECT_EQ(x, y);
}

TEST(DenseCholesky, TriangularSolvesAreBitwiseTheReferenceOnEveryPath) {
  // Sizes around the 8 lanes, the vector widths and the forward sweep's blocks of 8
  // columns, and the accordion's 447.
  for (int n : {1, 2, 3, 7, 8, 9, 15, 16, 17, 23, 33, 130, 447}) {
    const Eigen::MatrixXd a = random_spd(n, n, 41u + n);
    const Eigen::MatrixXd L = a.llt().matrixL();
    std::mt19937 rng(n);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> b(n);
    for (double& v : b) v = u(rng);
    std::vector<double> expected = b;
    dgtex::kernels::dense_cholesky_solve_reference(n, n, L.data(), expected.data());
    const Eigen::VectorXd eigen = a.llt().solve(Eigen::Map<const Eigen::VectorXd>(b.data(), n));
    for (int i = 0; i < n; ++i)
      EXPECT_NEAR(expected[i], eigen[i], 1e-11 * eigen.cwiseAbs().maxCoeff()) << "n = " << n << ", entry " << i;
    // The float factor: L rounded, every other operation as in double.
    const std::vector<float> single(L.data(), L.data() + static_cast<std::size_t>(n) * n);
    std::vector<double> expected_single = b;
    dgtex::kernels::dense_cholesky_solve_reference(n, n, single.data(), expected_single.data());
    for (int i = 0; i < n; ++i)
      EXPECT_NEAR(expected_single[i], eigen[i], 1e-5 * eigen.cwiseAbs().maxCoeff()) << "n = " << n << ", entry " << i;
    for (dgtex::kernels::VectorPath path : dgtex::testing_support::supported_vector_paths()) {
      std::vector<double> x = b;
      dgtex::kernels::dense_cholesky_solve(n, n, L.data(), x.data(), path);
      EXPECT_EQ(x, expected) << "n = " << n << ", path " << static_cast<int>(path);
      x = b;
      dgtex::kernels::dense_cholesky_solve(n, n, single.data(), x.data(), path);
      EXPECT_EQ(x, expected_single) << "float factor, n = " << n << ", path " << static_cast<int>(path);
    }
  }
}

TEST(DenseCholesky, FactorIsBitwiseTheReferenceOnEveryPathAndEigensToRoundOff) {
  // Sizes around the panels of 4 columns, the vector widths (2, 4, 8 rows) and the passes of
  // 2 vectors, and the scenes' 36-168 and 450. The scratch (upper triangle, padding rows)
  // holds arbitrary finite values: the lower triangle must not depend on them.
  for (int n : {1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 23, 31, 33, 36, 48, 126, 168, 450}) {
    const Eigen::MatrixXd a = random_spd(n, n, 7u + n);
    const int ld = dgtex::kernels::dense_cholesky_padded_rows(n);
    ASSERT_GE(ld, n);
    std::mt19937 rng(n);
    std::uniform_real_distribution<double> u(-1e3, 1e3);
    std::vector<double> input(static_cast<std::size_t>(ld) * n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < ld; ++i) input[static_cast<std::size_t>(j) * ld + i] = i >= j && i < n ? a(i, j) : u(rng);
    const auto lower = [&](const std::vector<double>& factor) {
      Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
      for (int j = 0; j < n; ++j)
        for (int i = j; i < n; ++i) l(i, j) = factor[static_cast<std::size_t>(j) * ld + i];
      return l;
    };
    std::vector<double> reference = input;
    ASSERT_EQ(dgtex::kernels::dense_cholesky_factor_reference(n, ld, reference.data()), -1) << n;
    const Eigen::MatrixXd expected = lower(reference), eigen = a.llt().matrixL();
    EXPECT_LE((expected - eigen).cwiseAbs().maxCoeff(), 1e-13 * eigen.cwiseAbs().maxCoeff()) << "n = " << n;
    for (dgtex::kernels::VectorPath path : dgtex::testing_support::supported_vector_paths()) {
      std::vector<double> factor = input;
      ASSERT_EQ(dgtex::kernels::dense_cholesky_factor(n, ld, factor.data(), path), -1) << n;
      const Eigen::MatrixXd l = lower(factor);
      EXPECT_EQ(std::memcmp(l.data(), expected.data(), sizeof(double) * n * n), 0)
          << "n = " << n << ", path " << static_cast<int>(path) << ": largest difference "
          << (l - expected).cwiseAbs().maxCoeff();
    }
  }
}

TEST(DenseCholesky, FactorStopsAtTheFirstUnusablePivotOnEveryPath) {
  // Column `bad` repeats column 3 in the leading block with its diagonal one lower (pivot
  // -1), or holds a NaN or infinite diagonal: every path and the reference name that
  // column, wherever it falls in a panel of 4.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (int n : {9, 50, 131}) {
    for (int bad : {4, 5, 6, 7}) {
      for (double diagonal : {-1.0, nan, inf}) {
        Eigen::MatrixXd a = random_spd(n, n, 29u);
        if (diagonal == -1.0) {
          a.row(bad).head(bad) = a.row(3).head(bad);
          a.col(bad).head(bad) = a.col(3).head(bad);
          a(bad, bad) = a(3, 3) - 1;
        } else {
          a(bad, bad) = diagonal;
        }
        const int ld = dgtex::kernels::dense_cholesky_padded_rows(n);
        std::vector<double> input(static_cast<std::size_t>(ld) * n, 0.0);
        for (int j = 0; j < n; ++j)
          for (int i = j; i < n; ++i) input[static_cast<std::size_t>(j) * ld + i] = a(i, j);
        std::vector<double> reference = input;
        EXPECT_EQ(dgtex::kernels::dense_cholesky_factor_reference(n, ld, reference.data()), bad)
            << "n = " << n << ", diagonal " << diagonal;
        for (dgtex::kernels::VectorPath path : dgtex::testing_support::supported_vector_paths()) {
          std::vector<double> factor = input;
          EXPECT_EQ(dgtex::kernels::dense_cholesky_factor(n, ld, factor.data(), path), bad)
              << "n = " << n << ", diagonal " << diagonal << ", path " << static_cast<int>(path);
        }
      }
    }
  }
}

TEST(DenseCholesky, ReportsTheFirstNonPositivePivot) {
  for (int n : {50, 200}) {
    Eigen::MatrixXd a = random_spd(n, n, 13u);
    // Row and column 17 copy row and column 3 in the leading 18 x 18 block, with the
    // diagonal one lower: the pivot at column 17 is -1 (the leading 17 x 17 block stays
    // definite).
    a.row(17).head(17) = a.row(3).head(17);
    a.col(17).head(17) = a.col(3).head(17);
    a(17, 17) = a(3, 3) - 1;
    const LowerCsc m = lower_csc(a);
    dgtex::SparseCholesky c;
    c.analyze(m.n, m.column_start, m.row_index);
    ASSERT_TRUE(c.dense());
    try {
      c.factorize(m.values);
      FAIL() << "an indefinite matrix was factored, n = " << n;
    } catch (const dgtex::NotPositiveDefinite& e) {
      EXPECT_EQ(e.column(), 17) << n;
      const std::string where = "column 17 of " + std::to_string(n);
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  }
}

TEST(DenseCholesky, RejectsNonFiniteValuesAndWrongCounts) {
  for (int n : {20, 160}) {
    LowerCsc m = lower_csc(random_spd(n, n, 17u));
    dgtex::SparseCholesky c;
    c.analyze(m.n, m.column_start, m.row_index);
    ASSERT_TRUE(c.dense());
    m.values[m.column_start[5]] = std::numeric_limits<double>::quiet_NaN();  // diagonal of column 5
    try {
      c.factorize(m.values);
      FAIL() << "a NaN pivot was factored, n = " << n;
    } catch (const dgtex::NotPositiveDefinite& e) {
      EXPECT_EQ(e.column(), 5) << n;
    }
    m.values.pop_back();
    EXPECT_THROW(c.factorize(m.values), std::invalid_argument);
  }
}

// SparseCholesky's supernodal factorisation: it hands CHOLMOD the lower triangle of P A P^T,
// built once with the analysis, instead of letting cholmod_factorize transpose the
// lower-stored A twice at every call. Its factor (seen through the solve) must be bitwise
// the one of CHOLMOD's own analyse-factorise-solve on the same matrix, also when the values
// change, and a matrix that is not positive definite must still be reported.
#include <gtest/gtest.h>

#include <cholmod.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstring>
#include <vector>

#include "cholmod_lock.h"  // internal (runtime/)
#include "dgtex/sparse_cholesky.h"
#include "enrichment_test_support.h"
#include "shifted_laplacian_support.h"

using namespace dgtex;
using dgtex::testing_support::bitwise_equal;
using dgtex::testing_support::ShiftedLaplacian;

namespace {

// CHOLMOD alone: analyse (supernodal, default orderings), factorise, solve.
std::vector<double> cholmod_solution(const ShiftedLaplacian& A, const std::vector<double>& b) {
  const auto lock = detail::lock_cholmod();
  cholmod_common common;
  cholmod_start(&common);
  common.supernodal = CHOLMOD_SUPERNODAL;
  cholmod_sparse* matrix = cholmod_allocate_sparse(A.size, A.size, A.values.size(), 1, 1, -1, CHOLMOD_REAL, &common);
  std::memcpy(matrix->p, A.column_start.data(), sizeof(int) * A.column_start.size());
  std::memcpy(matrix->i, A.row_index.data(), sizeof(int) * A.row_index.size());
  std::memcpy(matrix->x, A.values.data(), sizeof(double) * A.values.size());
  cholmod_factor* factor = cholmod_analyze(matrix, &common);
  cholmod_factorize(matrix, factor, &common);
  cholmod_dense* rhs = cholmod_allocate_dense(A.size, 1, A.size, CHOLMOD_REAL, &common);
  std::memcpy(rhs->x, b.data(), sizeof(double) * b.size());
  cholmod_dense* solution = cholmod_solve(CHOLMOD_A, factor, rhs, &common);
  std::vector<double> x(static_cast<const double*>(solution->x), static_cast<const double*>(solution->x) + A.size);
  cholmod_free_dense(&solution, &common);
  cholmod_free_dense(&rhs, &common);
  cholmod_free_factor(&factor, &common);
  cholmod_free_sparse(&matrix, &common);
  cholmod_finish(&common);
  return x;
}

}  // namespace

TEST(SparseCholesky, FactorIsCholmodsOwnBitwiseAlsoWithNewValues) {
  ShiftedLaplacian A(48, 0.05);  // 2304 unknowns: sparse, not factored densely
  ASSERT_FALSE(SparseCholesky::factors_densely(A.size, static_cast<std::int64_t>(A.values.size())));
  std::vector<double> b(A.size);
  for (int k = 0; k < A.size; ++k) b[k] = std::sin(0.37 * k) + 0.5 * std::cos(0.011 * k * k);
  SparseCholesky cholesky;
  cholesky.analyze(A.size, A.column_start, A.row_index);
  for (double scale : {1.0, 2.5}) {
    ShiftedLaplacian scaled = A;  // new values, same pattern: every third diagonal entry scaled
    for (int j = 0; j < A.size; j += 3) scaled.values[scaled.column_start[j]] *= scale;
    cholesky.factorize(scaled.values);
    std::vector<double> x;
    cholesky.solve(b, x);
    const std::vector<double> expected = cholmod_solution(scaled, b);
    EXPECT_TRUE(bitwise_equal(x, expected)) << "scale " << scale;
    // And it solves: A x = b to round-off.
    double residual = 0, norm = 0;
    std::vector<double> Ax(A.size, 0.0);
    for (int j = 0; j < A.size; ++j)
      for (int t = scaled.column_start[j]; t < scaled.column_start[j + 1]; ++t) {
        const int i = scaled.row_index[t];
        Ax[i] += scaled.values[t] * x[j];
        if (i != j) Ax[j] += scaled.values[t] * x[i];
      }
    for (int k = 0; k < A.size; ++k) residual += (Ax[k] - b[k]) * (Ax[k] - b[k]), norm += b[k] * b[k];
    EXPECT_LT(std::sqrt(residual / norm), 1e-12) << "scale " << scale;
  }
}

TEST(SparseCholesky, ReportsAMatrixThatIsNotPositiveDefinite) {
  ShiftedLaplacian A(48, 0.05);
  A.values[A.column_start[1000]] = -1.0;  // a negative diagonal entry
  SparseCholesky cholesky;
  cholesky.analyze(A.size, A.column_start, A.row_index);
  try {
    cholesky.factorize(A.values);
    FAIL() << "no NotPositiveDefinite";
  } catch (const NotPositiveDefinite& e) {
    EXPECT_GE(e.column(), 0);
    EXPECT_LT(e.column(), A.size);
  }
  // The same instance factorises a positive definite matrix of the pattern afterwards, and
  // that factor is the one CHOLMOD gives alone (nothing of the failed one is left).
  const ShiftedLaplacian good(48, 0.05);
  ASSERT_NO_THROW(cholesky.factorize(good.values));
  std::vector<double> b(good.size), x;
  for (int k = 0; k < good.size; ++k) b[k] = std::cos(0.21 * k);
  cholesky.solve(b, x);
  EXPECT_TRUE(bitwise_equal(x, cholmod_solution(good, b)));
}

// pivots(): L_jj^2 in the matrix's own column order, for the CHOLMOD and the dense path.
// Their product is det(A) whatever the fill-reducing order; a column coupled to nothing has
// its own diagonal entry as pivot in any order, so it shows the order is undone.
TEST(SparseCholesky, PivotsAreInTheMatrixsOwnOrderAndMultiplyToItsDeterminant) {
  for (int side : {20, 6}) {  // 400 unknowns through CHOLMOD, 36 densely
    SCOPED_TRACE(side);
    ShiftedLaplacian A(side, 0.05);
    const int isolated = A.size / 2 + 1;
    for (int j = 0; j < A.size; ++j)
      for (int t = A.column_start[j]; t < A.column_start[j + 1]; ++t)
        if ((j == isolated) != (A.row_index[t] == isolated)) A.values[t] = 0;  // its couplings
    A.values[A.column_start[isolated]] = 1e-3;
    SparseCholesky cholesky;
    cholesky.analyze(A.size, A.column_start, A.row_index);
    EXPECT_EQ(cholesky.dense(), side == 6);
    cholesky.factorize(A.values);
    const std::vector<double> pivots = cholesky.pivots();
    ASSERT_EQ(static_cast<int>(pivots.size()), A.size);
    EXPECT_NEAR(pivots[isolated], 1e-3, 1e-18);

    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(A.size, A.size);
    for (int j = 0; j < A.size; ++j)
      for (int t = A.column_start[j]; t < A.column_start[j + 1]; ++t)
        dense(A.row_index[t], j) = dense(j, A.row_index[t]) = A.values[t];
    const Eigen::LLT<Eigen::MatrixXd> llt(dense);
    const double log_det = 2 * llt.matrixLLT().diagonal().array().log().sum();
    double log_product = 0;
    for (double p : pivots) log_product += std::log(p);
    EXPECT_NEAR(log_product, log_det, 1e-10 * std::abs(log_det));
  }
}

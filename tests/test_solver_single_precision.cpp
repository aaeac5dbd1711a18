// The single-precision solve with a CHOLMOD supernodal factor (SparseCholesky::
// solve_single_precision), the PCG preconditioner of the corotated steps: it agrees with
// the double-precision solve to float accuracy times the conditioning, and its parallel
// schedule over the elimination tree gives bitwise the same result for any thread count.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "dgtex/sparse_cholesky.h"
#include "shifted_laplacian_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using dgtex::testing_support::ShiftedLaplacian;

namespace {

TEST(SinglePrecisionSolve, AgreesWithTheDoubleSolveToFloatAccuracy) {
  const double shift = 0.1;
  ShiftedLaplacian A(64, shift);  // 4096 unknowns: above the size that solves in parallel
  SparseCholesky cholesky;
  cholesky.analyze(A.size, A.column_start, A.row_index);
  cholesky.factorize(A.values);
  cholesky.copy_factor_to_single_precision();
  std::vector<double> b(A.size), x_double, x_single;
  for (int k = 0; k < A.size; ++k) b[k] = std::sin(0.37 * k) + 0.5 * std::cos(0.011 * k * k);
  cholesky.solve(b, x_double);
  cholesky.solve_single_precision(b, x_single);
  double diff = 0, norm = 0;
  for (int k = 0; k < A.size; ++k) {
    diff += (x_single[k] - x_double[k]) * (x_single[k] - x_double[k]);
    norm += x_double[k] * x_double[k];
  }
  const double relative = std::sqrt(diff / norm);
  const double condition = (8 + shift) / shift;
  std::printf("|x_single - x_double| / |x_double| = %.2e (condition number <= %.0f)\n", relative, condition);
  // Float rounding (6e-8) times the condition number, with a factor 10 for the growth of
  // rounding over the elimination; a wrong schedule (a missed or doubled update) is O(1).
  EXPECT_LE(relative, 10 * 6e-8 * condition);
  EXPECT_GT(relative, 0.0);  // it really ran in float
}

TEST(SinglePrecisionSolve, IsBitwiseIndependentOfThreadCount) {
  ShiftedLaplacian A(80, 0.01);
  SparseCholesky cholesky;
  cholesky.analyze(A.size, A.column_start, A.row_index);
  cholesky.factorize(A.values);
  cholesky.copy_factor_to_single_precision();
  std::vector<double> b(A.size), reference, x;
  for (int k = 0; k < A.size; ++k) b[k] = std::cos(0.05 * k);
  for (int threads : {1, 2, 3, 4}) {
    const test::ThreadCountGuard set_threads(threads);
    cholesky.solve_single_precision(b, threads == 1 ? reference : x);
    if (threads > 1) {
      EXPECT_EQ(x, reference) << threads << " threads";
    }
  }
}

}  // namespace

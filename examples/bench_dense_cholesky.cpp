// Google Benchmark cases of the dense factorisation of small systems (SparseCholesky's
// dense path, runtime/dense_cholesky.h): a fully coupled SPD matrix of n unknowns, the
// sizes of the cut single-element scenes (spiral1 ~48, chad 126, spiral6 168, accordion
// 441, slinky 498), factorised through SparseCholesky (kernels::dense_cholesky_factor,
// with the copy into its padded layout) and, for the ratios in the same run, by Eigen's
// LLT and LAPACK's dpotrf alone; and the solve with the factor
// (kernels::dense_cholesky_solve) against Eigen's solves.
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <vector>

#include "dgtex/sparse_cholesky.h"

extern "C" {
// LAPACK's Cholesky factorisation (the trailing argument: the hidden length of uplo).
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t uplo_length);
}

namespace {

// The lower triangle (compressed columns) of a random SPD n x n matrix.
struct LowerPattern {
  Eigen::MatrixXd matrix;
  std::vector<int> column_start, row_index;
  std::vector<double> values;
  explicit LowerPattern(int n) {
    const Eigen::MatrixXd r = Eigen::MatrixXd::Random(n, n);
    matrix = r * r.transpose() + n * Eigen::MatrixXd::Identity(n, n);
    column_start.push_back(0);
    for (int j = 0; j < n; ++j) {
      for (int i = j; i < n; ++i) row_index.push_back(i), values.push_back(matrix(i, j));
      column_start.push_back(static_cast<int>(row_index.size()));
    }
  }
};

void sparse_cholesky_dense_path(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const LowerPattern a(n);
  dgtex::SparseCholesky cholesky;
  cholesky.analyze(n, a.column_start, a.row_index);
  if (!cholesky.dense()) state.SkipWithError("not the dense path");
  for (auto _ : state) cholesky.factorize(a.values);
}

void eigen_llt(benchmark::State& state) {
  const LowerPattern a(static_cast<int>(state.range(0)));
  Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt;
  for (auto _ : state) {
    llt.compute(a.matrix);
    benchmark::DoNotOptimize(llt.matrixLLT().data());
  }
}

void lapack_dpotrf(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const LowerPattern a(n);
  Eigen::MatrixXd factor;
  for (auto _ : state) {
    factor = a.matrix;  // dpotrf works in place: the copy is part of each case
    int info = 0;
    dpotrf_("L", &n, factor.data(), &n, &info, 1);
    if (info != 0) state.SkipWithError("dpotrf failed");
    benchmark::DoNotOptimize(factor.data());
  }
}

void dense_solve(benchmark::State& state) {
  const LowerPattern a(static_cast<int>(state.range(0)));
  dgtex::SparseCholesky cholesky;
  cholesky.analyze(static_cast<int>(state.range(0)), a.column_start, a.row_index);
  cholesky.factorize(a.values);
  const std::vector<double> b(state.range(0), 1.0);
  std::vector<double> x;
  for (auto _ : state) {
    cholesky.solve(b, x);
    benchmark::DoNotOptimize(x.data());
  }
}

void eigen_solve(benchmark::State& state) {
  const LowerPattern a(static_cast<int>(state.range(0)));
  const Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(a.matrix);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(state.range(0));
  Eigen::VectorXd x;
  for (auto _ : state) {
    x = llt.solve(b);
    benchmark::DoNotOptimize(x.data());
  }
}

}  // namespace

BENCHMARK(sparse_cholesky_dense_path)->Arg(48)->Arg(126)->Arg(168)->Arg(441)->Arg(498)->Unit(benchmark::kMicrosecond);
BENCHMARK(eigen_llt)->Arg(48)->Arg(126)->Arg(168)->Arg(441)->Arg(498)->Unit(benchmark::kMicrosecond);
BENCHMARK(lapack_dpotrf)->Arg(48)->Arg(126)->Arg(168)->Arg(441)->Arg(498)->Unit(benchmark::kMicrosecond);

BENCHMARK(dense_solve)->Arg(48)->Arg(168)->Arg(447)->Unit(benchmark::kMicrosecond);
BENCHMARK(eigen_solve)->Arg(48)->Arg(168)->Arg(447)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();

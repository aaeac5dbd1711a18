// CHOLMOD's own OpenMP teams: CHOLMOD 3 (SuiteSparse 5.12) opens num_threads(4) regions
// in its supernodal factorisation whatever the program's thread count, thousands of them
// per factor, which on 2 cores made a top-level factorisation 3-4x slower. dgtex's CHOLMOD
// lock keeps the holder's parallel regions on the holder alone (cholmod_lock.h); these
// tests check that, that it touches no other thread, and that SparseCholesky's
// factorisation therefore starts no OpenMP threads of its own.
#include <gtest/gtest.h>
#include <omp.h>

#include <filesystem>
#include <thread>
#include <vector>

#include "cholmod_lock.h"  // internal (runtime/)
#include "dgtex/sparse_cholesky.h"
#include "thread_count_support.h"

namespace {

int team_size(int requested) {
  int size = 0;
#pragma omp parallel num_threads(requested)
  {
#pragma omp single
    size = omp_get_num_threads();
  }
  return size;
}

int process_threads() {
  int count = 0;
  for ([[maybe_unused]] const auto& task : std::filesystem::directory_iterator("/proc/self/task")) ++count;
  return count;
}

}  // namespace

TEST(CholmodLock, KeepsTheHoldersParallelRegionsOnOneThreadAndRestoresItsSetting) {
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(3);
  {
    const auto lock = dgtex::detail::lock_cholmod();
    EXPECT_EQ(team_size(4), 1);
    // Another thread, meanwhile, opens its teams as before.
    int other = 0;
    std::thread([&] { other = team_size(2); }).join();
    EXPECT_EQ(other, 2);
  }
  EXPECT_EQ(omp_get_max_active_levels(), 3);
  EXPECT_EQ(team_size(2), 2);
  omp_set_max_active_levels(levels);
}

TEST(CholmodLock, SupernodalFactorisationStartsNoOpenMpThreads) {
  // A 5-point Laplacian on 120 x 120 nodes plus the identity: CHOLMOD's supernodes reach
  // hundreds of columns, where it would open its teams. One OpenMP thread for dgtex's own
  // loops, so any thread that appears is CHOLMOD's.
  const dgtex::test::ThreadCountGuard set_threads(1);
  const int side = 120, n = side * side;
  std::vector<int> column_start{0}, row_index;
  std::vector<double> values;
  for (int j = 0; j < n; ++j) {
    const int x = j % side, y = j / side;
    row_index.push_back(j), values.push_back(5.0);
    if (x + 1 < side) row_index.push_back(j + 1), values.push_back(-1.0);
    if (y + 1 < side) row_index.push_back(j + side), values.push_back(-1.0);
    column_start.push_back(static_cast<int>(row_index.size()));
  }
  dgtex::SparseCholesky cholesky;
  cholesky.analyze(n, column_start, row_index);
  ASSERT_FALSE(cholesky.dense());
  const int threads_before = process_threads();
  cholesky.factorize(values);
  EXPECT_EQ(process_threads(), threads_before);
  // The factor is used: A x = b solved.
  std::vector<double> b(n, 1.0), x;
  cholesky.solve(b, x);
  for (int j : {0, n / 2 + side / 2, n - 1}) {
    const int px = j % side, py = j / side;
    double ax = 5.0 * x[j];
    if (px > 0) ax -= x[j - 1];
    if (px + 1 < side) ax -= x[j + 1];
    if (py > 0) ax -= x[j - side];
    if (py + 1 < side) ax -= x[j + side];
    EXPECT_NEAR(ax, 1.0, 1e-12);
  }
}

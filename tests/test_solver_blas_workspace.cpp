// Debian's OpenBLAS takes a 128 MiB workspace at its first call and retries forever when
// malloc refuses it: the cylinder under `ulimit -v 300000` spun at 100 % of a core in its
// first factorisation. The first supernodal factorisation in a process now checks the
// address space left and has OpenBLAS take its workspace at once (cholmod_lock.h,
// reserve_blas_workspace). One test in its own executable: a process whose BLAS has run
// before holds its workspace already.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "address_space_support.h"
#include "dgtex/sparse_cholesky.h"

namespace {

using namespace dgtex;

// The 1-D Laplacian of n unknowns plus the identity, lower triangle by columns.
struct Tridiagonal {
  int n;
  std::vector<int> column_start, row_index;
  std::vector<double> values;
  explicit Tridiagonal(int size) : n(size) {
    for (int j = 0; j < n; ++j) {
      column_start.push_back(static_cast<int>(row_index.size()));
      row_index.push_back(j);
      values.push_back(3.0);
      if (j + 1 < n) {
        row_index.push_back(j + 1);
        values.push_back(-1.0);
      }
    }
    column_start.push_back(static_cast<int>(row_index.size()));
  }
};

TEST(BlasWorkspace, ATightAddressSpaceIsRefusedInsteadOfSpinningInOpenBlas) {
  const Tridiagonal system(300);
  SparseCholesky cholesky(0);  // always CHOLMOD, supernodal: its factorisation calls dpotrf
  cholesky.analyze(system.n, system.column_start, system.row_index);
  ASSERT_FALSE(cholesky.dense());
  test::ScopedAddressSpaceLimit limit(std::int64_t{96} << 20);  // below the workspace's 128 MiB
  if (!limit.why_not().empty()) GTEST_SKIP() << limit.why_not();
  ::alarm(120);  // a regression spins in OpenBLAS for ever: end the process instead
  std::string message;
  try {
    cholesky.factorize(system.values);
  } catch (const std::runtime_error& error) {
    message = error.what();
  }
  limit.restore();  // before any assertion can fail
  for (const char* part : {"OpenBLAS needs 192 MiB of address space", "(ulimit -v)", "raise the limit by"})
    EXPECT_NE(message.find(part), std::string::npos) << part << " not in: '" << message << "'";

  // With the limit lifted the same factorisation runs, and solves.
  cholesky.factorize(system.values);
  ::alarm(0);
  std::vector<double> b(system.n, 1.0), x;
  cholesky.solve(b, x);
  ASSERT_EQ(x.size(), b.size());
  for (int i = 0; i < system.n; ++i) {
    double product = 3.0 * x[i];
    if (i > 0) product -= x[i - 1];
    if (i + 1 < system.n) product -= x[i + 1];
    EXPECT_NEAR(product, 1.0, 1e-12) << i;
  }
}

}  // namespace

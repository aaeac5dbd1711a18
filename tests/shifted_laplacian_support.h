#pragma once
// A sparse SPD test matrix shared by the solver tests: the lower triangle (CSC) of the
// shifted 5-point Laplacian on an n x n grid, 4 + shift on the diagonal, -1 to each
// neighbour; eigenvalues in [shift, 8 + shift]. From n = 23 on (over 512 unknowns)
// SparseCholesky hands it to CHOLMOD, which orders it to reduce fill (AMD).
#include <vector>

namespace dgtex::testing_support {

struct ShiftedLaplacian {
  int size = 0;
  std::vector<int> column_start{0}, row_index;
  std::vector<double> values;
  ShiftedLaplacian(int n, double shift) : size(n * n) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int c = j * n + i;
        row_index.push_back(c);
        values.push_back(4 + shift);
        if (i + 1 < n) row_index.push_back(c + 1), values.push_back(-1);
        if (j + 1 < n) row_index.push_back(c + n), values.push_back(-1);
        column_start.push_back(static_cast<int>(row_index.size()));
      }
  }
};

}  // namespace dgtex::testing_support

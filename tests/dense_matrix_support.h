#pragma once
// Dense free-DOF matrices of a shell model, for spectra of small test meshes.
#include <Eigen/Dense>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/shell_model.h"

namespace dgtex::testing_support {

// Dense free-DOF stiffness (linear) and mass (small meshes only); unknown[d] = row or -1.
inline void dense_free_matrices(const ShellModel& model, const std::vector<char>& fixed, Eigen::MatrixXd& K, Eigen::MatrixXd& M,
                                std::vector<int>& unknown) {
  std::vector<double> blocks;
  model.assemble_stiffness(nullptr, blocks, nullptr);
  const BlockAssembly& p = model.pattern();
  unknown.assign(model.num_dofs(), -1);
  int count = 0;
  for (int d = 0; d < model.num_dofs(); ++d)
    if (!fixed[d]) unknown[d] = count++;
  K = Eigen::MatrixXd::Zero(count, count);
  M = Eigen::MatrixXd::Zero(count, count);
  for (int r = 0; r < p.num_nodes(); ++r)
    for (std::int64_t k = p.row_start()[r]; k < p.row_start()[r + 1]; ++k)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const int a = unknown[3 * r + i], b = unknown[3 * p.column()[k] + j];
          if (a < 0 || b < 0) continue;
          K(a, b) = blocks[k * 9 + i * 3 + j];
          M(a, b) = model.mass_blocks()[k * 9 + i * 3 + j];
        }
}

}  // namespace dgtex::testing_support

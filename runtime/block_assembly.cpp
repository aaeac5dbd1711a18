#include "dgtex/block_assembly.h"

#include <algorithm>
#include <tuple>

#include "dgtex/kernels/forall.h"

namespace dgtex {

using kernels::Execution;
using kernels::forall;

BlockAssembly::BlockAssembly(int num_nodes, const std::vector<BlockSourceFamily>& families) : num_nodes_(num_nodes) {
  // Every (row, col, family, local) contribution, sorted into a fixed order.
  std::vector<std::tuple<int, int, int, std::int64_t>> entries;
  std::vector<std::tuple<int, int, std::int64_t>> vector_entries;
  for (int f = 0; f < static_cast<int>(families.size()); ++f) {
    const BlockSourceFamily& fam = families[f];
    for (int s = 0; s < fam.count; ++s) {
      const int* g = fam.global_nodes.data() + static_cast<std::int64_t>(s) * fam.width;
      for (int a = 0; a < fam.width; ++a) {
        if (g[a] < 0) continue;
        vector_entries.emplace_back(g[a], f, static_cast<std::int64_t>(s) * fam.width + a);
        for (int b = 0; b < fam.width; ++b)
          if (g[b] >= 0) entries.emplace_back(g[a], g[b], f, (static_cast<std::int64_t>(s) * fam.width + a) * fam.width + b);
      }
    }
  }
  std::sort(entries.begin(), entries.end());
  std::sort(vector_entries.begin(), vector_entries.end());

  row_start_.assign(num_nodes + 1, 0);
  contribution_start_.push_back(0);
  for (size_t i = 0; i < entries.size(); ++i) {
    const auto& [row, col, fam, local] = entries[i];
    const bool new_block = i == 0 || row != std::get<0>(entries[i - 1]) || col != std::get<1>(entries[i - 1]);
    if (new_block) {
      if (i > 0) contribution_start_.push_back(static_cast<std::int64_t>(contribution_family_.size()));
      column_.push_back(col);
      row_start_[row + 1]++;
    }
    contribution_family_.push_back(fam);
    contribution_local_.push_back(local);
  }
  contribution_start_.push_back(static_cast<std::int64_t>(contribution_family_.size()));
  if (entries.empty()) contribution_start_.assign(1, 0);
  for (int r = 0; r < num_nodes; ++r) row_start_[r + 1] += row_start_[r];

  vector_start_.assign(num_nodes + 1, 0);
  for (const auto& [node, fam, local] : vector_entries) {
    vector_start_[node + 1]++;
    vector_family_.push_back(fam);
    vector_local_.push_back(local);
  }
  for (int r = 0; r < num_nodes; ++r) vector_start_[r + 1] += vector_start_[r];
}

void BlockAssembly::assemble_matrix(const std::vector<const double*>& locals, double* values, bool parallel) const {
  forall(
      num_blocks(),
      [&](std::int64_t blk) {
        double sum[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
        for (std::int64_t c = contribution_start_[blk]; c < contribution_start_[blk + 1]; ++c) {
          const double* src = locals[contribution_family_[c]];
          if (!src) continue;
          src += contribution_local_[c] * 9;
          for (int k = 0; k < 9; ++k) sum[k] += src[k];
        }
        for (int k = 0; k < 9; ++k) values[blk * 9 + k] = sum[k];
      },
      parallel ? Execution::parallel : Execution::serial);
}

void BlockAssembly::assemble_vector(const std::vector<const double*>& locals, double* out, bool parallel) const {
  forall(
      num_nodes_,
      [&](std::int64_t node) {
        double sum[3] = {0, 0, 0};
        for (std::int64_t c = vector_start_[node]; c < vector_start_[node + 1]; ++c) {
          const double* src = locals[vector_family_[c]];
          if (!src) continue;
          src += vector_local_[c] * 3;
          for (int k = 0; k < 3; ++k) sum[k] += src[k];
        }
        for (int k = 0; k < 3; ++k) out[node * 3 + k] = sum[k];
      },
      parallel ? Execution::parallel : Execution::serial);
}

std::int64_t BlockAssembly::find(int row, int col) const {
  const auto begin = column_.begin() + row_start_[row];
  const auto end = column_.begin() + row_start_[row + 1];
  const auto it = std::lower_bound(begin, end, col);
  return (it != end && *it == col) ? it - column_.begin() : -1;
}

}  // namespace dgtex

#include "dgtex/block_assembly.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <tuple>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/low_rank_block.h"

namespace dgtex {

using kernels::Execution;
using kernels::forall;

BlockAssembly::BlockAssembly(int num_nodes, const std::vector<BlockSourceFamily>& families) : num_nodes_(num_nodes) {
  for (const BlockSourceFamily& f : families) family_width_.push_back(f.width);
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

  // assemble_symmetric_matrix's walk, from the sorted contributions: per row, the upper
  // blocks' contributions regrouped by (family, source, a), each group in column order.
  mirror_.resize(column_.size());
  row_entry_start_.assign(1, 0);
  entry_target_start_.assign(1, 0);
  {
    std::vector<std::tuple<int, std::int64_t, int, std::int64_t>> row_entries;  // family, local, b, block
    for (int row = 0; row < num_nodes; ++row) {
      row_entries.clear();
      for (std::int64_t k = row_start_[row]; k < row_start_[row + 1]; ++k) {
        mirror_[k] = find(column_[k], row);
        if (mirror_[k] < 0) structurally_symmetric_ = false;
        if (column_[k] < row) continue;
        for (std::int64_t c = contribution_start_[k]; c < contribution_start_[k + 1]; ++c) {
          const std::int64_t width = families[contribution_family_[c]].width;
          row_entries.emplace_back(contribution_family_[c], contribution_local_[c], static_cast<int>(contribution_local_[c] % width), k);
        }
      }
      std::sort(row_entries.begin(), row_entries.end());
      for (size_t i = 0; i < row_entries.size(); ++i) {
        const auto& [family, local, b, block] = row_entries[i];
        const std::int64_t width = families[family].width;
        const std::int64_t left = local / width;  // s * width + a
        if (i == 0 || family != std::get<0>(row_entries[i - 1]) || left != std::get<1>(row_entries[i - 1]) / width) {
          if (i > 0) entry_target_start_.push_back(static_cast<std::int64_t>(target_block_.size()));
          entry_family_.push_back(family);
          entry_source_.push_back(left / width * width);
          entry_function_.push_back(static_cast<int>(left % width));
        }
        target_function_.push_back(b);
        target_block_.push_back(block);
      }
      if (!row_entries.empty()) entry_target_start_.push_back(static_cast<std::int64_t>(target_block_.size()));
      row_entry_start_.push_back(static_cast<std::int64_t>(entry_family_.size()));
    }
  }

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

namespace {

// sum[t] += low_rank_block(L, R of function b_t) for the targets of one row entry. Compiled
// for AVX2 and baseline x86-64 (this file has -ffp-contract=off: both round the same).
__attribute__((target_clones("avx2", "default")))
void add_low_rank_blocks(int rank, const double* L, const double* right_base, std::int64_t stride,
                         const int* functions, const std::int64_t* blocks, std::int64_t count, double* values) {
  for (std::int64_t t = 0; t < count; ++t) {
    double blk[9];
    kernels::low_rank_block(rank, L, right_base + functions[t] * stride, blk);
    double* sum = values + blocks[t] * 9;
    for (int i = 0; i < 9; ++i) sum[i] += blk[i];
  }
}

}  // namespace

void BlockAssembly::assemble_symmetric_matrix(const std::vector<LocalMatrices>& locals, double* values,
                                              bool parallel) const {
  if (!structurally_symmetric_)
    throw std::logic_error("BlockAssembly::assemble_symmetric_matrix: the pattern is not symmetric (a block (i, j) "
                           "without its (j, i)); use assemble_matrix");
  if (locals.size() != family_width_.size())
    throw std::invalid_argument("BlockAssembly::assemble_symmetric_matrix: " + std::to_string(locals.size()) +
                                " local families given, the pattern has " + std::to_string(family_width_.size()));
  // One row per work item: its upper blocks are summed in place, each source's local row
  // (contiguous in memory) read once, then mirrored below the diagonal (blocks no other
  // row writes).
  forall(
      num_nodes_,
      [&](std::int64_t row) {
        for (std::int64_t k = row_start_[row]; k < row_start_[row + 1]; ++k)
          if (column_[k] >= row)
            for (int i = 0; i < 9; ++i) values[k * 9 + i] = 0;
        for (std::int64_t entry = row_entry_start_[row]; entry < row_entry_start_[row + 1]; ++entry) {
          const LocalMatrices& family = locals[entry_family_[entry]];
          if (!family.values) continue;
          const std::int64_t width = family_width_[entry_family_[entry]];
          const std::int64_t left = entry_source_[entry] + entry_function_[entry];
          const int rank = family.factor_rank;
          const std::int64_t first = entry_target_start_[entry], count = entry_target_start_[entry + 1] - first;
          if (rank == 0) {
            for (std::int64_t t = first; t < first + count; ++t) {
              const double* src = family.values + (left * width + target_function_[t]) * 9;
              double* sum = values + target_block_[t] * 9;
              for (int i = 0; i < 9; ++i) sum[i] += src[i];
            }
          } else {
            const std::int64_t stride = 2 * rank * 3;
            add_low_rank_blocks(rank, family.values + left * stride,
                                family.values + entry_source_[entry] * stride + rank * 3, stride,
                                target_function_.data() + first, target_block_.data() + first, count, values);
          }
        }
        for (std::int64_t k = row_start_[row]; k < row_start_[row + 1]; ++k) {
          if (column_[k] < row) continue;
          double* v = values + k * 9;
          if (column_[k] == row) {  // a diagonal block: its upper triangle, mirrored
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < i; ++j) v[i * 3 + j] = v[j * 3 + i];
          } else {
            double* m = values + mirror_[k] * 9;
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) m[j * 3 + i] = v[i * 3 + j];
          }
        }
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

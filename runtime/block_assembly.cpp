#include "dgtex/block_assembly.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/low_rank_block.h"

namespace dgtex {

using kernels::Execution;
using kernels::forall;

BlockAssembly::BlockAssembly(int num_nodes, const std::vector<BlockSourceFamily>& families) : num_nodes_(num_nodes) {
  for (const BlockSourceFamily& f : families) {
    family_width_.push_back(f.width);
    const std::size_t expected = f.widths.empty() ? static_cast<std::size_t>(f.count) * f.width
                                                  : std::accumulate(f.widths.begin(), f.widths.end(), std::size_t{0});
    if (!f.widths.empty() && f.widths.size() != static_cast<std::size_t>(f.count))
      throw std::invalid_argument("BlockAssembly: a family of " + std::to_string(f.count) + " sources has " +
                                  std::to_string(f.widths.size()) + " widths");
    if (f.global_nodes.size() != expected)
      throw std::invalid_argument("BlockAssembly: a family's global_nodes has " + std::to_string(f.global_nodes.size()) +
                                  " entries, its sources take " + std::to_string(expected));
    uniform_widths_ = uniform_widths_ && f.widths.empty();
  }
  // Every contribution (row, col, family, local) is visited in (family, local) order, so
  // stable bucketing by row and then by column gives the (row, col, family, local) order
  // of a full sort in linear time (a sort of the slinky's ~0.5M contributions took 4 ms of
  // every basis change). visit(family, source's global nodes, its width, its first local
  // function and first local block in the family's arrays).
  auto for_each_source = [&](auto&& visit) {
    for (int f = 0; f < static_cast<int>(families.size()); ++f) {
      const BlockSourceFamily& fam = families[f];
      std::int64_t first_function = 0, first_block = 0;
      for (int s = 0; s < fam.count; ++s) {
        const int width = fam.widths.empty() ? fam.width : fam.widths[s];
        visit(f, fam.global_nodes.data() + first_function, width, first_function, first_block);
        first_function += width;
        first_block += static_cast<std::int64_t>(width) * width;
      }
    }
  };
  std::vector<std::int64_t> row_offset(static_cast<size_t>(num_nodes) + 1, 0);
  vector_start_.assign(static_cast<size_t>(num_nodes) + 1, 0);
  for_each_source([&](int, const int* g, int width, std::int64_t, std::int64_t) {
    std::int64_t used = 0;
    for (int b = 0; b < width; ++b) used += g[b] >= 0;
    for (int a = 0; a < width; ++a)
      if (g[a] >= 0) row_offset[g[a] + 1] += used, vector_start_[g[a] + 1]++;
  });
  for (int r = 0; r < num_nodes; ++r) {
    row_offset[r + 1] += row_offset[r];
    vector_start_[r + 1] += vector_start_[r];
  }
  // Per row, its contributions in (family, local) order.
  const std::int64_t total = row_offset[num_nodes];
  std::vector<int> row_column(total), row_family(total);
  std::vector<std::int64_t> row_local(total);
  vector_family_.resize(vector_start_[num_nodes]);
  vector_local_.resize(vector_start_[num_nodes]);
  {
    std::vector<std::int64_t> next(row_offset.begin(), row_offset.end() - 1);
    std::vector<std::int64_t> next_vector(vector_start_.begin(), vector_start_.end() - 1);
    for_each_source([&](int f, const int* g, int width, std::int64_t first_function, std::int64_t first_block) {
      for (int a = 0; a < width; ++a) {
        if (g[a] < 0) continue;
        vector_family_[next_vector[g[a]]] = f;
        vector_local_[next_vector[g[a]]++] = first_function + a;
        for (int b = 0; b < width; ++b) {
          if (g[b] < 0) continue;
          const std::int64_t i = next[g[a]]++;
          row_column[i] = g[b];
          row_family[i] = f;
          row_local[i] = first_block + static_cast<std::int64_t>(a) * width + b;
        }
      }
    });
  }

  // Per row: its blocks in column order, each block's contributions in (family, local)
  // order; and assemble_symmetric_matrix's walk: the upper blocks' contributions grouped by
  // (family, source, a), each group in column order (the row's (family, local) order).
  row_start_.assign(static_cast<size_t>(num_nodes) + 1, 0);
  contribution_start_.assign(1, 0);
  contribution_family_.resize(total);
  contribution_local_.resize(total);
  row_entry_start_.assign(1, 0);
  entry_target_start_.assign(1, 0);
  std::vector<std::int64_t> block_of_column(num_nodes, -1);  // this row's block per column
  std::vector<int> columns;
  std::vector<std::int64_t> next;
  for (int row = 0; row < num_nodes; ++row) {
    const std::int64_t begin = row_offset[row], end = row_offset[row + 1];
    columns.clear();
    for (std::int64_t i = begin; i < end; ++i)
      if (block_of_column[row_column[i]] < 0) block_of_column[row_column[i]] = 0, columns.push_back(row_column[i]);
    std::sort(columns.begin(), columns.end());
    const std::int64_t first_block = static_cast<std::int64_t>(column_.size());
    next.assign(columns.size(), 0);
    for (size_t k = 0; k < columns.size(); ++k) block_of_column[columns[k]] = first_block + static_cast<std::int64_t>(k);
    for (std::int64_t i = begin; i < end; ++i) next[block_of_column[row_column[i]] - first_block]++;
    for (std::int64_t k = 0, position = begin; k < static_cast<std::int64_t>(columns.size()); ++k) {
      const std::int64_t count = next[k];
      next[k] = position;
      position += count;
      column_.push_back(columns[k]);
      contribution_start_.push_back(position);
    }
    row_start_[row + 1] = static_cast<std::int64_t>(column_.size());
    for (std::int64_t i = begin; i < end; ++i) {
      const std::int64_t block = block_of_column[row_column[i]];
      const std::int64_t c = next[block - first_block]++;
      contribution_family_[c] = row_family[i];
      contribution_local_[c] = row_local[i];
      if (row_column[i] < row || !uniform_widths_) continue;
      const std::int64_t width = families[row_family[i]].width;
      const std::int64_t left = row_local[i] / width;  // s * width + a
      const bool new_entry = entry_family_.size() == static_cast<size_t>(row_entry_start_.back()) ||
                             entry_family_.back() != row_family[i] || entry_source_.back() + entry_function_.back() != left;
      if (new_entry) {
        if (entry_family_.size() > static_cast<size_t>(row_entry_start_.back()))
          entry_target_start_.push_back(static_cast<std::int64_t>(target_block_.size()));
        entry_family_.push_back(row_family[i]);
        entry_source_.push_back(left / width * width);
        entry_function_.push_back(static_cast<int>(left % width));
      }
      target_function_.push_back(static_cast<int>(row_local[i] % width));
      target_block_.push_back(block);
    }
    if (entry_family_.size() > static_cast<size_t>(row_entry_start_.back()))
      entry_target_start_.push_back(static_cast<std::int64_t>(target_block_.size()));
    row_entry_start_.push_back(static_cast<std::int64_t>(entry_family_.size()));
    for (int col : columns) block_of_column[col] = -1;
  }
  mirror_.resize(column_.size());
  for (int row = 0; row < num_nodes; ++row)
    for (std::int64_t k = row_start_[row]; k < row_start_[row + 1]; ++k) {
      mirror_[k] = find(column_[k], row);
      if (mirror_[k] < 0) structurally_symmetric_ = false;
    }
}

namespace {

// out[target] (Width entries) = the sum of the target's contributions (family, local index)
// in their fixed order, from the families' local arrays (a null family skipped): a block of
// assemble_matrix (Width 9) or a node of assemble_vector (Width 3).
template <int Width>
inline void sum_contributions(std::int64_t target, const std::vector<std::int64_t>& start,
                              const std::vector<int>& family, const std::vector<std::int64_t>& local,
                              const std::vector<const double*>& locals, double* out) {
  double sum[Width] = {};
  for (std::int64_t c = start[target]; c < start[target + 1]; ++c) {
    const double* src = locals[family[c]];
    if (!src) continue;
    src += local[c] * Width;
    for (int k = 0; k < Width; ++k) sum[k] += src[k];
  }
  for (int k = 0; k < Width; ++k) out[target * Width + k] = sum[k];
}

}  // namespace

void BlockAssembly::assemble_matrix(const std::vector<const double*>& locals, double* values, bool parallel,
                                    const AssembledProducts* products) const {
  const auto sum_block = [&](std::int64_t blk) {
    sum_contributions<9>(blk, contribution_start_, contribution_family_, contribution_local_, locals, values);
  };
  const Execution execution = parallel ? Execution::parallel : Execution::serial;
  if (!products) {
    forall(num_blocks(), sum_block, execution);
    return;
  }
  // Ranges of rows instead of single blocks, each multiplied once summed. Rows are
  // independent in both, so any split gives the same bits; 8 rows keep the threads' shares
  // even on a small dense pattern (the accordion's 150 rows: 10 and 9 ranges).
  constexpr std::int64_t rows_per_range = 8;
  forall(
      (num_nodes_ + rows_per_range - 1) / rows_per_range,
      [&](std::int64_t range) {
        const std::int64_t first = range * rows_per_range;
        const std::int64_t last = std::min<std::int64_t>(first + rows_per_range, num_nodes_);
        for (std::int64_t blk = row_start_[first]; blk < row_start_[last]; ++blk) sum_block(blk);
        products->multiply_rows(rows(), first, last, values);
      },
      execution);
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
  if (!uniform_widths_)
    throw std::logic_error("BlockAssembly::assemble_symmetric_matrix: a family has sources of different widths; use "
                           "assemble_matrix");
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
        sum_contributions<3>(node, vector_start_, vector_family_, vector_local_, locals, out);
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

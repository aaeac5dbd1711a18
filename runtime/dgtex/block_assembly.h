#pragma once
// Deterministic assembly of local 3x3-block matrices into a global block-sparse matrix.
//
// Local contributions come from "sources" (elements, edges), each with a list of the global
// node of every local basis function. The pattern is built once; then every global block
// sums its contributions in a fixed order (by source, then local position), in parallel
// over global blocks, so the result is bitwise identical for any thread count.
// BlockAssembly owns its pattern (index arrays only, no references to the sources or to
// the values). Const, so one instance may assemble from several threads; each call with
// parallel = true uses all OpenMP threads. Values carry whatever units the caller's do.
#include <cstdint>
#include <vector>

#include "dgtex/kernels/block_product.h"
#include "dgtex/kernels/forall.h"

namespace dgtex {

// One family of sources whose local matrices are stored back to back:
// local block (a, b) of source s at ((s * width + a) * width + b) * 9, its local vector rows
// (assemble_vector) at (s * width + a) * 3.
// Sources of different widths (widths not empty): source s has widths[s] local functions,
// global_nodes holds each source's widths[s] nodes back to back, and its local block (a, b)
// lies at (B_s + a * widths[s] + b) * 9, its vector row a at (F_s + a) * 3, with B_s and F_s
// the sums of widths[t]^2 and of widths[t] over the sources t < s (no padding to the
// widest: enriched edges, whose widths vary with their elements' enrichments).
struct BlockSourceFamily {
  int count = 0;                  // number of sources
  int width = 0;                  // local basis functions per source (widths empty)
  std::vector<int> global_nodes;  // count x width (or sum of widths); -1 marks an unused local slot
  std::vector<int> widths;        // per source, or empty: `width` each
};

// One family's local matrices for assemble_symmetric_matrix: stored blocks (layout of
// BlockSourceFamily), or low-rank factors: local block (a, b) of source s is
// kernels::low_rank_block(factor_rank, L, R) with L at (s * width + a) * 2 * factor_rank * 3
// and R = L's position + factor_rank * 3 doubles for the source's local function b
// (the layout of kernels::shell_edge_factors).
struct LocalMatrices {
  const double* values = nullptr;  // null: skip the family
  int factor_rank = 0;             // 0: stored blocks; > 0 (even): factors of this rank
};

// Products of a matrix being assembled with one or two vectors, for assemble_matrix: y1 = A x1
// and, where spread2 is given, y2 = A x2 (#nodes x 3 each), the x given spread
// (kernels::spread_block_vector). Each range of rows is multiplied right after its blocks are
// summed, by the kernels of kernels/block_product.h: bitwise block_multiply's results, without
// a second pass over A (whose rows are then still in the cache of the thread that summed them).
struct AssembledProducts {
  const double* spread1 = nullptr;
  const double* spread2 = nullptr;  // null: y1 only
  double* y1 = nullptr;
  double* y2 = nullptr;

  // Rows [first, last) of the products with the block matrix `values` (pattern `rows`).
  void multiply_rows(kernels::BlockRows rows, std::int64_t first, std::int64_t last, const double* values) const {
    if (spread2)
      kernels::block_rows_product_pair(rows, first, last, values, spread1, spread2, y1, y2);
    else
      kernels::block_rows_product(rows, first, last, values, spread1, y1);
  }
};

class BlockAssembly {
 public:
  BlockAssembly() = default;
  BlockAssembly(int num_nodes, const std::vector<BlockSourceFamily>& families);

  int num_nodes() const { return num_nodes_; }
  std::int64_t num_blocks() const { return static_cast<std::int64_t>(column_.size()); }
  const std::vector<std::int64_t>& row_start() const { return row_start_; }
  const std::vector<int>& column() const { return column_; }
  // The pattern's rows for the block product kernels (kernels/block_product.h).
  kernels::BlockRows rows() const { return {row_start_.data(), column_.data()}; }

  // values: num_blocks x 9. locals[f] points to family f's local blocks, or is null to skip it.
  // products (optional): also the products of the assembled matrix (AssembledProducts).
  void assemble_matrix(const std::vector<const double*>& locals, double* values, bool parallel = true,
                       const AssembledProducts* products = nullptr) const;
  // The same sum for a symmetric global matrix (every family's local matrices symmetric):
  // only blocks with column >= row are summed (same fixed order as assemble_matrix, so
  // bitwise its values there, up to the diagonal blocks' lower triangles); each entry
  // below the diagonal is its mirror's value, so the result is exactly symmetric. Half the work of assemble_matrix, and
  // factored families are never expanded into memory. Throws std::logic_error if the
  // pattern is not structurally symmetric or has a family of sources of different widths,
  // std::invalid_argument for a wrong family count.
  void assemble_symmetric_matrix(const std::vector<LocalMatrices>& locals, double* values, bool parallel = true) const;
  // Node vectors (#nodes x 3) from local vectors (source x width x 3), same order rules.
  void assemble_vector(const std::vector<const double*>& locals, double* out, bool parallel = true) const;

  // Block index of (row, col), or -1 if not in the pattern.
  std::int64_t find(int row, int col) const;

 private:
  int num_nodes_ = 0;
  std::vector<std::int64_t> row_start_;  // CSR over node rows
  std::vector<int> column_;
  // For each global block: its contributions, as (family, flat local block index).
  std::vector<std::int64_t> contribution_start_;
  std::vector<int> contribution_family_;
  std::vector<std::int64_t> contribution_local_;
  // assemble_symmetric_matrix's walk: per node row, its entries (family, source s, local
  // function a with global node = row) in (family, s, a) order, each with the blocks it
  // adds to in this row's upper part (local function b, block index); and per block the
  // index of its mirror (col, row). Same summation order per block as assemble_matrix.
  std::vector<int> family_width_;
  bool structurally_symmetric_ = true;
  bool uniform_widths_ = true;  // no family of sources of different widths (else no walk)
  std::vector<std::int64_t> row_entry_start_, mirror_;
  std::vector<int> entry_family_, entry_function_;           // family, a
  std::vector<std::int64_t> entry_source_, entry_target_start_;  // s * width, CSR over targets
  std::vector<int> target_function_;                         // b
  std::vector<std::int64_t> target_block_;
  // For each node: contributions to vectors.
  std::vector<std::int64_t> vector_start_;
  std::vector<int> vector_family_;
  std::vector<std::int64_t> vector_local_;
};

// Whether every 3x3 block of `blocks` (9 values each, row-major) is m I: an isotropic mass,
// whose products and factorisations can work on one scalar a block.
inline bool blocks_are_isotropic(const std::vector<double>& blocks) {
  for (std::size_t k = 0; k + 9 <= blocks.size(); k += 9) {
    const double* m = blocks.data() + k;
    if (m[1] != 0 || m[2] != 0 || m[3] != 0 || m[5] != 0 || m[6] != 0 || m[7] != 0 || m[4] != m[0] || m[8] != m[0])
      return false;
  }
  return true;
}

// How a product of a block matrix in this pattern with vectors should run: serially below
// 32768 blocks. Waking the OpenMP team costs more than such a product (a cut single element
// has 64-21609 blocks: spiral1's K u took 40 us on 2 threads against 3 us serially, and the
// solver's PCG multiplies every iteration). The accordion's fully coupled 147 nodes (21609
// blocks, 1.6 MB) still gain: its solve took 1.14-1.20 ms a step on 2 threads against
// 0.77-0.86 ms serially (200 steps, 3 runs each). Fracture (41k blocks) and the cylinder
// (120k) were the same either way. Rows are independent, so either way gives the same bits.
inline kernels::Execution block_product_execution(const BlockAssembly& pattern) {
  constexpr std::int64_t min_parallel_blocks = 1 << 15;
  return pattern.num_blocks() >= min_parallel_blocks ? kernels::Execution::parallel : kernels::Execution::serial;
}

// Calls body(first, last) over ranges of the pattern's node rows that together cover them
// once: all rows at once where block_product_execution says serial, else chunks of rows over
// the OpenMP threads. For products whose rows are independent (the same bits either way).
template <class Body>
void for_row_ranges(const BlockAssembly& pattern, Body&& body) {
  const std::int64_t rows = pattern.num_nodes();
  if (block_product_execution(pattern) == kernels::Execution::serial) {
    body(std::int64_t{0}, rows);
    return;
  }
  constexpr std::int64_t chunk = 32;
  kernels::forall((rows + chunk - 1) / chunk,
                  [&](std::int64_t c) { body(c * chunk, c * chunk + chunk < rows ? c * chunk + chunk : rows); });
}

}  // namespace dgtex

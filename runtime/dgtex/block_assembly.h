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

namespace dgtex {

// One family of sources whose local matrices are stored back to back:
// local block (a, b) of source s at ((s * width + a) * width + b) * 9.
struct BlockSourceFamily {
  int count = 0;                  // number of sources
  int width = 0;                  // local basis functions per source
  std::vector<int> global_nodes;  // count x width; -1 marks an unused local slot
};

class BlockAssembly {
 public:
  BlockAssembly() = default;
  BlockAssembly(int num_nodes, const std::vector<BlockSourceFamily>& families);

  int num_nodes() const { return num_nodes_; }
  std::int64_t num_blocks() const { return static_cast<std::int64_t>(column_.size()); }
  const std::vector<std::int64_t>& row_start() const { return row_start_; }
  const std::vector<int>& column() const { return column_; }

  // values: num_blocks x 9. locals[f] points to family f's local blocks, or is null to skip it.
  void assemble_matrix(const std::vector<const double*>& locals, double* values, bool parallel = true) const;
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
  // For each node: contributions to vectors.
  std::vector<std::int64_t> vector_start_;
  std::vector<int> vector_family_;
  std::vector<std::int64_t> vector_local_;
};

}  // namespace dgtex

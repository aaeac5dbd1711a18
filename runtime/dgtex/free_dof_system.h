#pragma once
// The linear system over the free DOFs of a block-sparse matrix: fixed DOFs (held at zero
// displacement) are eliminated, and the lower triangle is laid out in compressed-column
// form for CHOLMOD. The map from block entries to column slots is built once; each slot
// is written by exactly one block entry, so filling is deterministic in parallel.
// FreeDofSystem owns its index maps only (no reference to the pattern after construction);
// const functions are thread-safe, gather uses all OpenMP threads. Values keep the caller's units.
#include <cstdint>
#include <vector>

#include "dgtex/block_assembly.h"

namespace dgtex {

class FreeDofSystem {
 public:
  FreeDofSystem() = default;
  // fixed: #dofs flags (3 per node). kept_blocks (optional, #blocks of pattern): only the
  // blocks flagged non-zero enter the system (a sparser approximation, e.g. for a
  // preconditioner); gather still reads values in the layout of the whole pattern.
  FreeDofSystem(const BlockAssembly& pattern, const std::vector<char>& fixed,
                const std::vector<char>* kept_blocks = nullptr);

  int size() const { return static_cast<int>(dof_of_unknown_.size()); }
  int num_dofs() const { return static_cast<int>(unknown_of_dof_.size()); }  // free and fixed
  int dof_of_unknown(int unknown) const { return dof_of_unknown_.at(static_cast<std::size_t>(unknown)); }
  std::int64_t nonzeros() const { return static_cast<std::int64_t>(row_index_.size()); }
  const std::vector<int>& column_start() const { return column_start_; }
  const std::vector<int>& row_index() const { return row_index_; }

  // values = sa * A + sb * B (B may be null), A and B block matrices in the pattern.
  void gather(const double* a, double sa, const double* b, double sb, std::vector<double>& values) const;
  void restrict_vector(const std::vector<double>& full, std::vector<double>& reduced) const;
  // full[free dofs] = reduced; fixed DOFs set to zero.
  void expand_vector(const std::vector<double>& reduced, std::vector<double>& full) const;

 private:
  std::vector<int> dof_of_unknown_;
  std::vector<int> unknown_of_dof_;
  std::vector<int> column_start_, row_index_;
  std::vector<std::int64_t> slot_source_;  // per CSC slot: block entry (block * 9 + r * 3 + c)
};

}  // namespace dgtex

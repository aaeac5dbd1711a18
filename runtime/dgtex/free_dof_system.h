#pragma once
// The linear system over the free DOFs of a block-sparse matrix: fixed DOFs (held at zero
// displacement) are eliminated, and the lower triangle is laid out in compressed-column
// form for CHOLMOD. The map from block entries to column slots is built once; each slot
// is written by exactly one block entry, so filling is deterministic in parallel.
// With dependent nodes (dependent_node.h), x = T x_free: their DOFs are eliminated too, the
// system is T^T A T (a slot then sums several block entries with coefficients, in a fixed
// order), restrict_vector applies T^T (moments and forces of dependent DOFs go to their
// sources) and expand_vector T.
// FreeDofSystem owns its index maps only (no reference to the pattern after construction);
// const functions are thread-safe, gather uses all OpenMP threads. Values keep the caller's units.
#include <cstdint>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/dependent_node.h"

namespace dgtex {

class FreeDofSystem {
 public:
  FreeDofSystem() = default;
  // fixed: #dofs flags (3 per node). kept_blocks (optional, #blocks of pattern): only the
  // blocks flagged non-zero enter the system (a sparser approximation, e.g. for a
  // preconditioner); gather still reads values in the layout of the whole pattern.
  // dependents (optional): nodes whose DOFs follow others' (std::invalid_argument for a node
  // or source out of range, a node dependent twice, a dependent source, a source twice).
  FreeDofSystem(const BlockAssembly& pattern, const std::vector<char>& fixed,
                const std::vector<char>* kept_blocks = nullptr, const std::vector<DependentNode>* dependents = nullptr);

  int size() const { return static_cast<int>(dof_of_unknown_.size()); }
  int num_dofs() const { return static_cast<int>(unknown_of_dof_.size()); }  // free and fixed
  int dof_of_unknown(int unknown) const { return dof_of_unknown_.at(static_cast<std::size_t>(unknown)); }
  // Whether DOF d is an unknown of the system (neither fixed nor dependent).
  bool is_unknown(int dof) const { return unknown_of_dof_.at(static_cast<std::size_t>(dof)) >= 0; }
  bool has_dependents() const { return !dependent_dof_.empty(); }
  // Whether DOF d follows others (a DOF of a dependent node, not fixed).
  bool is_dependent(int dof) const;
  std::int64_t nonzeros() const { return static_cast<std::int64_t>(row_index_.size()); }
  const std::vector<int>& column_start() const { return column_start_; }
  const std::vector<int>& row_index() const { return row_index_; }

  // values = sa * A + sb * B (B may be null), A and B block matrices in the pattern.
  void gather(const double* a, double sa, const double* b, double sb, std::vector<double>& values) const;
  // reduced = T^T full: full's free entries, plus those of dependent DOFs times their
  // coefficients (a force or moment there acts through the DOFs it follows).
  void restrict_vector(const std::vector<double>& full, std::vector<double>& reduced) const;
  // full = T reduced: full[free dofs] = reduced, fixed DOFs zero, dependent ones from their sources.
  void expand_vector(const std::vector<double>& reduced, std::vector<double>& full) const;
  // In place, over all DOFs: adds each dependent DOF's entry, times its coefficients, to its
  // sources' and zeroes it (T^T on a vector of forces; fixed entries are left as they are).
  void collect(std::vector<double>& full) const;
  // In place: each dependent DOF's entry from its sources' (T on a vector of displacements).
  void distribute(std::vector<double>& full) const;

 private:
  void lay_out_plain(const BlockAssembly& pattern, const std::vector<char>* kept_blocks);
  void lay_out_dependent(const BlockAssembly& pattern, const std::vector<char>& fixed,
                         const std::vector<char>* kept_blocks, const std::vector<DependentNode>& dependents);

  std::vector<int> dof_of_unknown_;
  std::vector<int> unknown_of_dof_;
  std::vector<int> column_start_, row_index_;
  std::vector<std::int64_t> slot_source_;  // per CSC slot: block entry (block * 9 + r * 3 + c)
  // With dependent nodes instead: slot s sums coefficient[t] * entry source[t] for t in
  // [slot_term_start_[s], slot_term_start_[s + 1]).
  std::vector<std::int64_t> slot_term_start_, term_source_;
  std::vector<double> term_coefficient_;
  // Per dependent DOF (not fixed): its index and its sources' terms in
  // [dependent_term_start_[i], dependent_term_start_[i + 1]) (source DOF, coefficient; fixed
  // sources left out).
  std::vector<int> dependent_dof_, dependent_term_start_, dependent_source_dof_;
  std::vector<double> dependent_coefficient_;
};

}  // namespace dgtex

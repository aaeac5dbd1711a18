#include "dgtex/free_dof_system.h"

#include <stdexcept>
#include <string>

#include "dgtex/kernels/forall.h"

namespace dgtex {

FreeDofSystem::FreeDofSystem(const BlockAssembly& pattern, const std::vector<char>& fixed,
                             const std::vector<char>* kept_blocks) {
  if (kept_blocks && static_cast<std::int64_t>(kept_blocks->size()) != pattern.num_blocks())
    throw std::invalid_argument("FreeDofSystem: kept_blocks has " + std::to_string(kept_blocks->size()) +
                                " flags, the pattern " + std::to_string(pattern.num_blocks()) + " blocks");
  const int ndofs = 3 * pattern.num_nodes();
  unknown_of_dof_.assign(ndofs, -1);
  for (int d = 0; d < ndofs; ++d)
    if (!fixed[d]) {
      unknown_of_dof_[d] = static_cast<int>(dof_of_unknown_.size());
      dof_of_unknown_.push_back(d);
    }
  // The lower triangle in compressed columns, in two passes over the blocks: count each
  // column's entries, then place them. Block rows are node rows, visited in order, and a
  // row holds one block per column at most, so each column receives its rows in ascending
  // order without a sort (per-column vectors and their sort: 1.30 ms for the slinky's late
  // patterns, built at every basis change on the step's thread; 0.45 ms so).
  const auto& start = pattern.row_start();
  const auto& col = pattern.column();
  const auto for_each_lower_entry = [&](auto&& visit) {
    for (int rn = 0; rn < pattern.num_nodes(); ++rn)
      for (std::int64_t k = start[rn]; k < start[rn + 1]; ++k) {
        if (kept_blocks && !(*kept_blocks)[k]) continue;
        for (int r = 0; r < 3; ++r) {
          const int ur = unknown_of_dof_[3 * rn + r];
          if (ur < 0) continue;
          for (int c = 0; c < 3; ++c) {
            const int uc = unknown_of_dof_[3 * col[k] + c];
            if (uc >= 0 && ur >= uc) visit(ur, uc, k * 9 + r * 3 + c);
          }
        }
      }
  };
  column_start_.assign(dof_of_unknown_.size() + 1, 0);
  for_each_lower_entry([&](int, int uc, std::int64_t) { ++column_start_[uc + 1]; });
  for (size_t j = 0; j < dof_of_unknown_.size(); ++j) column_start_[j + 1] += column_start_[j];
  row_index_.resize(static_cast<size_t>(column_start_.back()));
  slot_source_.resize(row_index_.size());
  std::vector<int> next(column_start_.begin(), column_start_.end() - 1);
  for_each_lower_entry([&](int ur, int uc, std::int64_t source) {
    const int slot = next[uc]++;
    if (slot > column_start_[uc] && row_index_[slot - 1] >= ur)
      throw std::logic_error("FreeDofSystem: the pattern holds two blocks at one (row, column)");
    row_index_[slot] = ur;
    slot_source_[slot] = source;
  });
}

void FreeDofSystem::gather(const double* a, double sa, const double* b, double sb, std::vector<double>& values) const {
  values.resize(slot_source_.size());
  // Short gathers (small cut models) run serially: waking the OpenMP team costs more.
  const std::int64_t n = static_cast<std::int64_t>(slot_source_.size());
  kernels::forall(
      n,
      [&](std::int64_t s) {
        const std::int64_t src = slot_source_[s];
        values[s] = b ? sa * a[src] + sb * b[src] : sa * a[src];
      },
      n >= (1 << 15) ? kernels::Execution::parallel : kernels::Execution::serial);
}

void FreeDofSystem::restrict_vector(const std::vector<double>& full, std::vector<double>& reduced) const {
  reduced.resize(dof_of_unknown_.size());
  for (size_t i = 0; i < dof_of_unknown_.size(); ++i) reduced[i] = full[dof_of_unknown_[i]];
}

void FreeDofSystem::expand_vector(const std::vector<double>& reduced, std::vector<double>& full) const {
  full.assign(unknown_of_dof_.size(), 0.0);
  for (size_t i = 0; i < dof_of_unknown_.size(); ++i) full[dof_of_unknown_[i]] = reduced[i];
}

}  // namespace dgtex

#include "dgtex/free_dof_system.h"

#include <algorithm>
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
  // Collect (column, row, source) for the lower triangle; block rows are node rows, so the
  // entries of one block row are scattered over three unknown rows.
  std::vector<std::vector<std::pair<int, std::int64_t>>> per_column(dof_of_unknown_.size());
  const auto& start = pattern.row_start();
  const auto& col = pattern.column();
  for (int rn = 0; rn < pattern.num_nodes(); ++rn)
    for (std::int64_t k = start[rn]; k < start[rn + 1]; ++k) {
      if (kept_blocks && !(*kept_blocks)[k]) continue;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          const int ur = unknown_of_dof_[3 * rn + r];
          const int uc = unknown_of_dof_[3 * col[k] + c];
          if (ur < 0 || uc < 0 || ur < uc) continue;
          per_column[uc].emplace_back(ur, k * 9 + r * 3 + c);
        }
    }
  column_start_.assign(dof_of_unknown_.size() + 1, 0);
  for (size_t j = 0; j < per_column.size(); ++j) {
    auto& entries = per_column[j];
    std::sort(entries.begin(), entries.end());
    for (const auto& [row, source] : entries) {
      row_index_.push_back(row);
      slot_source_.push_back(source);
    }
    column_start_[j + 1] = static_cast<int>(row_index_.size());
  }
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

#pragma once
// Internal helper of the multigrid kernels: two dependent row passes fused into one
// streaming pass (see smooth_texels_sweep in dgtex/kernels/multigrid_smooth.h).
#include <algorithm>
#include <cstdint>

#include "dgtex/kernels/forall.h"

namespace dgtex::kernels::detail {

// Runs first(j) and second(j) for every row j in [0, ny), where second(j) needs first(j - 1),
// first(j), first(j + 1) done and first(j) needs second(j - 1), second(j + 1) not yet done.
// Within each fixed block of rows (the parallel work items) second(j - 1) runs right after
// first(j); the block's first and last rows get second() in a short second pass. Every row
// sees the same inputs for any block scheduling, so results do not depend on the threads.
// both(j) does first(j) and then second(j - 1) where a block runs them back to back (for a
// fused row kernel; without it, the two calls).
constexpr int lagged_block_rows = 32;
template <class First, class Second, class Both>
void lagged_rows(int ny, First first, Second second, Both both, Execution execution) {
  const int blocks = (ny + lagged_block_rows - 1) / lagged_block_rows;
  forall_then(
      blocks,
      [&](std::int64_t k) {
        const int j0 = static_cast<int>(k) * lagged_block_rows, j1 = std::min(ny, j0 + lagged_block_rows);
        for (int j = j0; j < j1; ++j) {
          if (j - 1 > j0)
            both(j);
          else
            first(j);
        }
      },
      blocks,
      [&](std::int64_t k) {
        const int j0 = static_cast<int>(k) * lagged_block_rows, j1 = std::min(ny, j0 + lagged_block_rows);
        second(j0);
        if (j1 - 1 > j0) second(j1 - 1);
      },
      execution);
}
template <class First, class Second>
void lagged_rows(int ny, First first, Second second, Execution execution) {
  lagged_rows(
      ny, first, second,
      [&](int j) {
        first(j);
        second(j - 1);
      },
      execution);
}

}  // namespace dgtex::kernels::detail

#pragma once
// Internal to the multigrid setup kernels (multigrid_galerkin.cpp): which coarse nodes lie
// in a uniform region of the fine level, i.e. every fine node of the window
//   x in [2I - 2, 2I + 3], y in [2J - 2, 2J + 3]
// around coarse node (I, J) satisfies a predicate (its stencil values are those of one
// translation-invariant row). The window covers every fine value that the interpolation
// weights and the Galerkin row of (I, J) read (multigrid_galerkin.cpp lists them); fine
// nodes outside the grid never qualify.
#include <cstdint>
#include <vector>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::kernels::detail {

// Returns one byte per coarse node (padded layout of fine.coarser(), ghosts 0): 1 where the
// whole window satisfies uniform(f) (f = fine padded index). Separable: along each fine row
// the length of the qualifying run ending at each node (a window's columns all qualify iff
// the run ending at its last column is >= 6 long), then per coarse node the AND over the
// window's six rows.
template <class Uniform>
std::vector<std::uint8_t> uniform_windows(GridShape fine, const Uniform& uniform, Execution execution) {
  const GridShape coarse = fine.coarser();
  constexpr int width = 6, reach_low = 2, reach_high = 3;  // the window spans 2I - 2 .. 2I + 3
  // Per fine row y and coarse column I: 1 if the window's columns of row y all qualify.
  std::vector<std::uint8_t> row_windows(static_cast<std::size_t>(fine.ny) * coarse.nx, 0);
  std::vector<std::uint8_t> windows(coarse.padded_size(), 0);
  forall_then(
      fine.ny,
      [&](std::int64_t y64) {
        const int y = static_cast<int>(y64);
        const std::int64_t row = fine.at(0, y);
        std::uint8_t* out = row_windows.data() + static_cast<std::size_t>(y) * coarse.nx;
        int run = 0;
        // The window of column I ends at x = 2I + 3 (windows ending beyond the row stay 0;
        // those starting before it have runs shorter than 6). Two nodes a step, so the odd
        // one always closes a window.
        const Uniform qualifies = uniform;  // a local copy: the byte stores below may alias its state
        for (int x = 0; x + 1 < fine.nx; x += 2) {
          run = qualifies(row + x) ? run + 1 : 0;
          run = qualifies(row + x + 1) ? run + 1 : 0;
          if (x + 1 >= reach_high) out[(x + 1 - reach_high) / 2] = run >= width;
        }
      },
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        const int y0 = 2 * J - reach_low, y1 = y0 + width - 1;
        if (y0 < 0 || y1 >= fine.ny) return;  // the window leaves the grid: stays 0
        std::uint8_t* out = windows.data() + coarse.at(0, J);
        const std::uint8_t* rows = row_windows.data() + static_cast<std::size_t>(y0) * coarse.nx;
        for (int I = 0; I < coarse.nx; ++I) {
          std::uint8_t all = 1;
          for (int k = 0; k < width; ++k) all &= rows[static_cast<std::size_t>(k) * coarse.nx + I];
          out[I] = all;
        }
      },
      execution);
  return windows;
}

}  // namespace dgtex::kernels::detail

#pragma once
// Connected components of a TexelTile's active texels across uncut texel edges (thesis
// §5.4.2: the components C_i of complete cuts are found by flood fill). Two texels are
// connected iff they are 4-neighbours, both active and no wall separates them (the same
// coupling as the Laplace problem, kernels::texels_coupled_east/north). Dirichlet flags
// play no role here.
//
// Canonical labels: components are numbered 0, 1, ... in the order of their smallest
// texel index (j * width + i); inactive texels get -1. Both forms below produce exactly
// these labels, so they agree bitwise and do not depend on the thread count.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
#include <vector>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/texel_grid.h"

namespace dgtex::kernels {

// Serial reference: breadth-first search from each unlabelled texel in index order.
// Writes width * height labels; returns the number of components.
int label_components_reference(const TexelTile& tile, std::vector<int>& labels);

// Parallel form: union-find. Rows are joined along their east links in parallel, then
// the north links are merged with a lock-free union that always hangs the root with the
// larger index below the smaller one, so each component's final root is its smallest
// texel; roots are renumbered with a prefix sum over rows.
int label_components(const TexelTile& tile, std::vector<int>& labels, Execution execution = Execution::parallel);

// Serial union-find over an int parent array (roots: parent[x] == x), for the callers with
// their own coupling rules: the root of x, halving the path on the way.
inline int find_root_halving(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}
// Joins the sets of a and b, hanging the larger root below the smaller (so parent[x] <= x
// holds and each set's root stays its smallest member).
inline void unite_smaller_root(std::vector<int>& parent, int a, int b) {
  a = find_root_halving(parent, a), b = find_root_halving(parent, b);
  if (a != b) parent[a < b ? b : a] = a < b ? a : b;
}

}  // namespace dgtex::kernels

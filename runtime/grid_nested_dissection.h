#pragma once
// Internal to the Laplace multigrid: a fill-reducing order of a grid level's active nodes for
// the sparse Cholesky of a large coarsest level. Geometric nested dissection: the box is cut
// by one grid line across its longer side (a line separates a 9-point stencil: nodes two
// columns apart never couple), both halves are ordered the same way, the line's nodes come
// last. Why: with this order CHOLMOD needs no ordering of its own (CHOLMOD_NATURAL), and its
// AMD analysis was ~60% of factoring the slinky's 97 x 33 coarsest level: 1.0 + 0.7 ms with
// AMD, 0.24 + 0.9 ms in this order (its fill is AMD's or less, see the tests). Serial and
// deterministic.
#include <cstdint>
#include <vector>

#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::detail {

// The padded indices (GridShape::at) of the nodes (i, j) with active[at(i, j)] != 0, every
// one once, in nested-dissection order.
std::vector<std::int64_t> grid_nested_dissection_order(const kernels::GridShape& g, const std::uint8_t* active);

}  // namespace dgtex::detail

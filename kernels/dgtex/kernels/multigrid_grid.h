#pragma once
// Layout shared by the multigrid kernels. Every level is a dense nx x ny grid of nodes
// stored with one ghost node on each side ((nx+2) x (ny+2), row-major), so neighbour reads
// never leave the array; ghost entries are 0 and kernels never write them.
// Level 0 is the texel tile itself (node = texel), its 5-point operator is encoded by one
// LaplaceTexelBits byte per node (see multigrid_unknowns.h). Coarse levels are vertex
// coarsenings (coarse node (I, J) = fine node (2I, 2J)) with Galerkin operators P^T A P:
// symmetric 9-point stencils stored as five coefficient arrays.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Value types that describe layouts (GridShape) or point into caller arrays (*View).
#include <cstddef>
#include <cstdint>

namespace dgtex::kernels {

struct GridShape {
  int nx = 0;
  int ny = 0;
  int stride() const { return nx + 2; }
  std::size_t padded_size() const { return static_cast<std::size_t>(nx + 2) * (ny + 2); }
  std::int64_t at(int i, int j) const { return static_cast<std::int64_t>(j + 1) * (nx + 2) + (i + 1); }
  GridShape coarser() const { return {(nx + 1) / 2, (ny + 1) / 2}; }
};

// Symmetric 9-point operator: at node (i, j) the diagonal c and the couplings to
// (i+1, j) e, (i, j+1) n, (i+1, j+1) ne, (i-1, j+1) nw. The other four couplings are read
// from the neighbours (west = e(i-1, j), south = n(i, j-1), south-west = ne(i-1, j-1),
// south-east = nw(i+1, j-1)), so the operator is exactly symmetric. c = 0 marks a node
// without unknown (its row and column are zero).
// Real: double, or float for the single-precision preconditioner cycle
// (LaplaceMultigridOptions::single_precision_min_texels).
template <class Real>
struct Stencil9ViewOf {
  const Real* c;
  const Real* e;
  const Real* n;
  const Real* ne;
  const Real* nw;
};
using Stencil9View = Stencil9ViewOf<double>;
using Stencil9ViewFloat = Stencil9ViewOf<float>;

// Operator-dependent interpolation P from a coarse grid to the next finer one, stored on
// the coarse grid: for coarse node (I, J) the weights of fine nodes
//   (2I+1, 2J)  : xw to (I, J), xe to (I+1, J)
//   (2I, 2J+1)  : ys to (I, J), yn to (I, J+1)
//   (2I+1, 2J+1): sw to (I, J), se to (I+1, J), nw to (I, J+1), ne to (I+1, J+1)
// Fine node (2I, 2J) is the coarse node itself (weight 1). Weights of fine nodes outside
// the fine grid are 0. Restriction is P^T.
template <class Real>
struct InterpolationViewOf {
  const Real* xw;
  const Real* xe;
  const Real* ys;
  const Real* yn;
  const Real* sw;
  const Real* se;
  const Real* nw;
  const Real* ne;
};
using InterpolationView = InterpolationViewOf<double>;
using InterpolationViewFloat = InterpolationViewOf<float>;

}  // namespace dgtex::kernels

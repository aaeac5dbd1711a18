#pragma once
// Named texel domains for tests and benchmarks of the harmonic (Laplace) solvers.
// Single-element domains are T x T tiles (tri: texels with i + j >= T are inactive, the
// outside of the reference triangle). Unless stated, Dirichlet data is +1 on the first
// active texel of every row (west side) and -1 on the last one (east side; for tri the
// hypotenuse), and cuts are zero-Neumann walls ("other cuts" c_j, j != i, of §5.5.2), so
// every domain tests that walls do not leak:
//   open      no walls (quad: the exact solution is linear in i)
//   slit      one wall from the south border up to 3T/4, at an odd texel position
//   spiral    a rectangular spiral wall from the centre, arm spacing max(4, T/16);
//             Dirichlet +1 on the 2x2 texels at the spiral's centre, -1 on the west column
//   accordion 18 parallel walls alternately from the south and north borders, leaving
//             T/8 open: a serpentine channel between the west and east Dirichlet columns
//   chad      a circle wall (radius T/4, tri: T/5) closed except for a 2-texel bridge
//   one_ring  3x3 quad elements of T x T texels in one 3T x 3T tile (element borders are no
//             walls); the enriched cut runs from the west border to the centre at height
//             3T/2 + 1 with +1 / -1 Dirichlet texels along its north / south sides, a second
//             (Neumann) cut runs from the south border up to 3T/2 at x = 5T/3; zero-Neumann
//             elsewhere (quad only).
// Pure functions returning tiles by value (thread-safe). Positions in texel units.
#include <string>
#include <vector>

#include "dgtex/kernels/texel_grid.h"

namespace dgtex {

enum class LaplaceDomain { open, slit, spiral, accordion, chad, one_ring };
enum class TexelElementShape { quad, tri };

// Throws std::invalid_argument for T < 16 or one_ring with tri.
kernels::TexelTile make_laplace_domain(LaplaceDomain domain, int T, TexelElementShape shape = TexelElementShape::quad);

std::string laplace_domain_name(LaplaceDomain domain);
// Throws std::invalid_argument listing the valid names.
LaplaceDomain parse_laplace_domain(const std::string& name);
const std::vector<LaplaceDomain>& all_laplace_domains();

// Walls along texel edges, for building domains: a vertical wall on the line x (between
// texel columns x-1 and x) for rows [j0, j1), and a horizontal one on the line y (between
// rows y-1 and y) for columns [i0, i1). Parts outside the tile are ignored.
void add_vertical_wall(kernels::TexelTile& tile, int x, int j0, int j1);
void add_horizontal_wall(kernels::TexelTile& tile, int y, int i0, int i1);

}  // namespace dgtex

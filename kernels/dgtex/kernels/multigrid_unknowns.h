#pragma once
// Which texels of a TexelTile are unknowns of the harmonic (Laplace) problem.
// The discrete problem shared by the multigrid, the direct solver and the enrichment code:
// texels (i, j) and a 4-neighbour are coupled (weight 1) iff both are active (not
// `inactive`), both lie in the tile and no wall separates them. Dirichlet texels keep their
// value; at every other active texel  sum over coupled neighbours (u_n - u_c) = 0.
// A component of free texels (connected through couplings between free texels) that
// touches no Dirichlet texel has no data: its value is defined to be 0 (thesis §5.5.2)
// and it is not an unknown, so the remaining system is symmetric positive definite.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Values are dimensionless (texel units).
#include <cstddef>  // texel_grid.h uses size_t without including it
#include <cstdint>
#include <cstring>
#include <vector>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/texel_grid.h"

namespace dgtex::kernels {

// Bits of one byte per texel that describe its row of the 5-point operator.
enum LaplaceTexelBits : std::uint8_t {
  couples_west_unknown = 1u << 0,  // coupled to the west neighbour, which is an unknown
  couples_east_unknown = 1u << 1,
  couples_south_unknown = 1u << 2,
  couples_north_unknown = 1u << 3,
  degree_shift = 4,  // bits 4..6: number of coupled active neighbours (0..4), Dirichlet included
  is_unknown = 1u << 7,
};
constexpr std::uint8_t laplace_degree_mask = 7u << degree_shift;
inline int laplace_degree(std::uint8_t bits) { return (bits & laplace_degree_mask) >> degree_shift; }

// The byte of an unknown coupled to four unknown neighbours (degree 4): most texels of a
// tile, whose row is 4 x(t) minus the four neighbours (the multigrid's fast paths).
constexpr std::uint8_t interior_texel = is_unknown | couples_west_unknown | couples_east_unknown |
                                        couples_south_unknown | couples_north_unknown | (4u << degree_shift);
// Whether bits[0 .. 3] are all interior_texel (one 4-byte compare).
inline bool four_interior_texels(const std::uint8_t* bits) {
  std::uint32_t word;
  std::memcpy(&word, bits, sizeof word);
  return word == 0x01010101u * interior_texel;
}

// Whether texel (i, j) is coupled to (i+1, j) / (i, j+1) (both active, no wall, in the tile).
inline bool texels_coupled_east(const TexelTile& tile, int i, int j) {
  return i + 1 < tile.width && !(tile.flags[tile.index(i, j)] & (wall_east | inactive)) &&
         !(tile.flags[tile.index(i + 1, j)] & inactive);
}
inline bool texels_coupled_north(const TexelTile& tile, int i, int j) {
  return j + 1 < tile.height && !(tile.flags[tile.index(i, j)] & (wall_north | inactive)) &&
         !(tile.flags[tile.index(i, j + 1)] & inactive);
}

// Writes one LaplaceTexelBits byte per texel into `bits` (width * height). Returns the
// number of free texels in components without Dirichlet data (not unknowns, value 0).
// One branch-free pass over the flags (parallel rows, 16 texels a vector) writes the bytes
// as if every component had Dirichlet data, and bitsets of run ends, south links and
// Dirichlet contacts; the components of free texels are then found by union-find over runs
// of east-coupled free texels (intervals of a row, united where they overlap a south link),
// and only the texels of components without data are rewritten. The result does not
// depend on the execution.
int classify_laplace_texels(const TexelTile& tile, std::vector<std::uint8_t>& bits,
                            Execution execution = Execution::parallel);
// The same bytes written into a padded grid (multigrid_grid.h layout: (width+2) x
// (height+2), ghosts set to 0), the form the multigrid uses.
int classify_laplace_texels_padded(const TexelTile& tile, std::uint8_t* padded_bits,
                                   Execution execution = Execution::parallel);
// Serial reference: a flood fill with an explicit stack from each free texel in index order.
int classify_laplace_texels_reference(const TexelTile& tile, std::vector<std::uint8_t>& bits);

}  // namespace dgtex::kernels

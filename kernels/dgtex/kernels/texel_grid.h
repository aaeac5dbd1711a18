#pragma once
// A dense tile of texels: the shared layout of the texel kernels (cut rasterisation, flood
// fill, Laplace multigrid, harmonic enrichment). Texel (i, j) has index j * width + i and
// covers [i, i+1] x [j, j+1] in texel units; i runs along xi1, j along xi2.
// Cuts live on texel *edges*: bit wall_east of texel (i, j) says the edge between (i, j)
// and (i+1, j) is cut; wall_north the edge between (i, j) and (i, j+1). A wall on the tile
// border means a zero-Neumann boundary there. inactive texels lie outside the domain
// (e.g. the upper half of a tri6 element's square). dirichlet texels hold a fixed value.
// A crease lies on texel edges too (kink_east, kink_north): the values stay continuous
// across it, but the texel rule's finite differences (enriched_basis.h) and the enriched
// quadrature's cells do not cross it, as for a wall, so the crease is a kink of the field
// and not a one-texel spike of its curvature.
// TexelTile is a value type that owns its flags and values. Positions in texel units.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dgtex::kernels {

enum TexelFlags : std::uint8_t {
  wall_east = 1u << 0,
  wall_north = 1u << 1,
  dirichlet = 1u << 2,
  inactive = 1u << 3,
  kink_east = 1u << 4,
  kink_north = 1u << 5,
};

// The edges that finite differences and quadrature cells do not cross: walls and kinks.
constexpr std::uint8_t stencil_barrier_east = wall_east | kink_east;
constexpr std::uint8_t stencil_barrier_north = wall_north | kink_north;

struct TexelTile {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> flags;  // width * height, TexelFlags bits
  std::vector<double> values;       // width * height (Dirichlet data, or a solution)

  TexelTile() = default;
  TexelTile(int w, int h) : width(w), height(h), flags(static_cast<std::size_t>(w) * h, 0), values(static_cast<std::size_t>(w) * h, 0.0) {}
  int index(int i, int j) const { return j * width + i; }
  bool is_wall_east(int i, int j) const { return flags[index(i, j)] & wall_east; }
  bool is_wall_north(int i, int j) const { return flags[index(i, j)] & wall_north; }
  // Whether texels (i,j) and its neighbour across the given direction are connected.
  bool connected_east(int i, int j) const { return i + 1 < width && !is_wall_east(i, j); }
  bool connected_north(int i, int j) const { return j + 1 < height && !is_wall_north(i, j); }
};

}  // namespace dgtex::kernels

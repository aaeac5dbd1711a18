#include "dgtex/laplace_problem.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex {

void validate_laplace_tile(const kernels::TexelTile& tile) {
  if (tile.width <= 0 || tile.height <= 0)
    throw std::invalid_argument("Laplace solve: texel tile is empty (width " + std::to_string(tile.width) +
                                ", height " + std::to_string(tile.height) + "); both must be positive");
  const std::size_t n = static_cast<std::size_t>(tile.width) * tile.height;
  if (tile.flags.size() != n || tile.values.size() != n)
    throw std::invalid_argument("Laplace solve: texel tile " + std::to_string(tile.width) + "x" +
                                std::to_string(tile.height) + " needs " + std::to_string(n) + " flags and values, has " +
                                std::to_string(tile.flags.size()) + " flags and " + std::to_string(tile.values.size()) + " values");
  for (std::size_t t = 0; t < n; ++t)
    if ((tile.flags[t] & kernels::dirichlet) && !std::isfinite(tile.values[t]))
      throw std::invalid_argument("Laplace solve: Dirichlet texel " + std::to_string(t % tile.width) + "," +
                                  std::to_string(t / tile.width) + " has a non-finite value");
}

LaplaceResidualNorms laplace_residual_norms(const kernels::TexelTile& tile, const std::vector<std::uint8_t>& bits) {
  using namespace kernels;
  const int w = tile.width, h = tile.height;
  double rr = 0, bb = 0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int t = tile.index(i, j);
      if (!(bits[t] & is_unknown)) continue;
      double b = 0, ax = laplace_degree(bits[t]) * tile.values[t];
      auto neighbour = [&](bool coupled, int nb) {
        if (!coupled) return;
        if (bits[nb] & is_unknown) ax -= tile.values[nb];
        else b += tile.values[nb];  // a coupled non-unknown neighbour of an unknown is Dirichlet
      };
      neighbour(i > 0 && texels_coupled_east(tile, i - 1, j), t - 1);
      neighbour(texels_coupled_east(tile, i, j), t + 1);
      neighbour(j > 0 && texels_coupled_north(tile, i, j - 1), t - w);
      neighbour(texels_coupled_north(tile, i, j), t + w);
      rr += (b - ax) * (b - ax);
      bb += b * b;
    }
  return {std::sqrt(rr), std::sqrt(bb)};
}

}  // namespace dgtex

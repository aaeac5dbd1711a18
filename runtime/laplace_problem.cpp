#include "dgtex/laplace_problem.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex {
namespace {

// Whether every Dirichlet texel's value is finite (exponent not all ones). Branch-free per
// texel, and only the values of 8-texel groups (one cache line of values) with a Dirichlet
// flag are read: Dirichlet texels are few (borders, curves), so the scan reads the 1-byte
// flags rather than the 8-byte values. Open, spiral and chad at T = 256 and 1024 together:
// 16.7 -> 4.2 M instructions (callgrind) against the per-texel branchy loop; T = 1024,
// 2 threads busy machine: 0.57 -> 0.05 ms, so one thread does it (no parallel rows).
bool dirichlet_values_finite(const std::uint8_t* flags, const double* values, std::size_t n) {
  constexpr std::uint64_t dirichlet_bytes = 0x0101010101010101ull * kernels::dirichlet;
  constexpr std::uint64_t exponent = 0x7ff0000000000000ull;
  std::uint64_t non_finite = 0;
  auto check = [&](std::size_t t) {
    std::uint64_t bits;
    std::memcpy(&bits, values + t, sizeof bits);
    non_finite |= static_cast<std::uint64_t>((flags[t] & kernels::dirichlet) != 0) & ((bits & exponent) == exponent);
  };
  std::size_t t = 0;
  for (; t + 8 <= n; t += 8) {
    std::uint64_t group;
    std::memcpy(&group, flags + t, sizeof group);
    if (group & dirichlet_bytes)
      for (std::size_t u = t; u < t + 8; ++u) check(u);
  }
  for (; t < n; ++t) check(t);
  return non_finite == 0;
}

}  // namespace

void validate_laplace_tile(const kernels::TexelTile& tile) {
  if (tile.width <= 0 || tile.height <= 0)
    throw std::invalid_argument("Laplace solve: texel tile is empty (width " + std::to_string(tile.width) +
                                ", height " + std::to_string(tile.height) + "); both must be positive");
  const std::size_t n = static_cast<std::size_t>(tile.width) * tile.height;
  if (tile.flags.size() != n || tile.values.size() != n)
    throw std::invalid_argument("Laplace solve: texel tile " + std::to_string(tile.width) + "x" +
                                std::to_string(tile.height) + " needs " + std::to_string(n) + " flags and values, has " +
                                std::to_string(tile.flags.size()) + " flags and " + std::to_string(tile.values.size()) + " values");
  if (!dirichlet_values_finite(tile.flags.data(), tile.values.data(), n))
    for (std::size_t t = 0; t < n; ++t)  // the first bad texel, in index order
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

#include "dgtex/kernels/texel_derivative_rows.h"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/kernels/texel_grid.h"
#include "texel_difference_rule.h"

namespace dgtex::kernels {
namespace {

// Per-texel connectivity bits: the texel is in the domain, and each unit neighbour is
// reachable (in the domain and no wall between), as enriched_basis.cpp's reachable() says.
enum : std::uint8_t { in_domain = 1, reach_east = 2, reach_west = 4, reach_north = 8, reach_south = 16 };

struct Tile {
  ElementType type;
  int t;
  const double* values;
  const std::uint8_t* flags;
  int row0;                         // first row held in bits
  std::vector<std::uint8_t> bits;   // rows row0 .. row0 + bits.size() / t - 1

  // Connectivity bits of rows [row0, row_last); domain of rows row0 - 1 .. row_last first.
  void classify(int row_last) {
    const int d0 = std::max(row0 - 1, 0), d1 = std::min(row_last + 1, t);
    std::vector<std::uint8_t> domain(static_cast<std::size_t>(d1 - d0) * t);
    for (int j = d0; j < d1; ++j)
      for (int i = 0; i < t; ++i)
        domain[static_cast<std::size_t>(j - d0) * t + i] =
            !(type == ElementType::tri6 && i + j > t - 1) && !(flags[j * t + i] & inactive);
    bits.resize(static_cast<std::size_t>(row_last - row0) * t);  // every entry written below
    for (int j = row0; j < row_last; ++j) {
      const std::uint8_t* row = domain.data() + static_cast<std::size_t>(j - d0) * t;
      const std::uint8_t* below = j > 0 ? row - t : nullptr;
      const std::uint8_t* above = j + 1 < t ? row + t : nullptr;
      const std::uint8_t* f = flags + static_cast<std::size_t>(j) * t;
      std::uint8_t* b = bits.data() + static_cast<std::size_t>(j - row0) * t;
      auto texel = [&](int i) {
        if (!row[i]) return std::uint8_t(0);
        std::uint8_t c = in_domain;
        if (i + 1 < t && row[i + 1] && !(f[i] & stencil_barrier_east)) c |= reach_east;
        if (i > 0 && row[i - 1] && !(f[i - 1] & stencil_barrier_east)) c |= reach_west;
        if (above && above[i] && !(f[i] & stencil_barrier_north)) c |= reach_north;
        if (below && below[i] && !(f[i - t] & stencil_barrier_north)) c |= reach_south;
        return c;
      };
      // The same bits without branches (0/1 products) for the texels that have all four
      // neighbours in the tile: a loop that vectorizes.
      if (above && below && t > 2) {
        const std::uint8_t* fs = f - t;
        for (int i = 1; i + 1 < t; ++i) {
          const int in = row[i];
          const int east = in & row[i + 1] & ((f[i] & stencil_barrier_east) == 0);
          const int west = in & row[i - 1] & ((f[i - 1] & stencil_barrier_east) == 0);
          const int north = in & above[i] & ((f[i] & stencil_barrier_north) == 0);
          const int south = in & below[i] & ((fs[i] & stencil_barrier_north) == 0);
          b[i] = static_cast<std::uint8_t>(in * in_domain | east * reach_east | west * reach_west | north * reach_north |
                                           south * reach_south);
        }
        b[0] = texel(0);
        b[t - 1] = texel(t - 1);
      } else {
        for (int i = 0; i < t; ++i) b[i] = texel(i);
      }
    }
  }
  std::uint8_t at(int i, int j) const { return bits[static_cast<std::size_t>(j - row0) * t + i]; }
  double value(int i, int j) const { return values[j * t + i]; }

  // Whether texel (i, j) connects to its unit neighbour (i + di, j + dj).
  bool reaches(int i, int j, int di, int dj) const {
    const std::uint8_t bit = di > 0 ? reach_east : di < 0 ? reach_west : dj > 0 ? reach_north : reach_south;
    return at(i, j) & bit;
  }
  // The rule of enriched_basis.cpp (texel_difference_rule.h) on the connectivity bits.
  void differences(int i, int j, int axis, double& g, double& s) const {
    detail::axis_difference_rule(
        i, j, axis == 0 ? 1 : 0, axis == 0 ? 0 : 1, [this](int a, int b) { return value(a, b); },
        [this](int a, int b, int da, int db) { return reaches(a, b, da, db); }, g, s);
  }
};

}  // namespace

void texel_derivative_rows(ElementType type, int t, const TextureView& texture, int row_begin, int row_end,
                           const TexelDerivativePlanes& out) {
  if (row_begin < 0)
    throw std::invalid_argument("texel_derivative_rows: row_begin must be >= 0, got " + std::to_string(row_begin));
  row_end = std::min(row_end, t);
  if (row_begin >= row_end) return;
  // Connectivity of rows row_begin - 2 .. row_end + 1 (one-sided differences look two rows
  // away; the mixed term takes neighbour rows' gradients, which look one row further).
  Tile tile{type, t, texture.values, texture.flags, std::max(row_begin - 2, 0), {}};
  tile.classify(std::min(row_end + 2, t));
  // g_1 (and S_11) of rows row_begin - 1 .. row_end: d/dxi2 g_1 of the mixed term needs the
  // rows around.
  const int g_row0 = std::max(row_begin - 1, 0), g_last = std::min(row_end + 1, t);
  // Every entry of g1 and s11 is written below (no zero-filling).
  const std::size_t g_size = static_cast<std::size_t>(g_last - g_row0) * t;
  std::unique_ptr<double[]> g1_data(new double[g_size]), s11_data(new double[g_size]);
  double* const g1 = g1_data.get();
  double* const s11 = s11_data.get();
  std::vector<double> row_g2(t, 0.0), row_s22(t, 0.0);
  // Each pass first writes the central difference everywhere it can be formed (a loop
  // that vectorizes; the same expressions as the rule's central case, so bitwise equal),
  // then redoes the texels that lack a reachable neighbour on either side with the rule
  // itself. On a cut T = 256 element that made this function ~3x cheaper (callgrind).
  constexpr std::uint8_t east_west = reach_east | reach_west, north_south = reach_north | reach_south;
  for (int j = g_row0; j < g_last; ++j) {
    const std::size_t row = static_cast<std::size_t>(j - g_row0) * t;
    const double* v = texture.values + static_cast<std::size_t>(j) * t;
    double* g = g1 + row;
    double* s = s11 + row;
    for (int i = 1; i + 1 < t; ++i) {
      const double hp = v[i + 1], hm = v[i - 1];
      g[i] = 0.5 * (hp - hm);
      s[i] = hp - 2 * v[i] + hm;
    }
    const std::uint8_t* b = &tile.bits[static_cast<std::size_t>(j - tile.row0) * t];
    for (int i = 0; i < t; ++i) {
      if ((b[i] & east_west) == east_west) continue;
      if (b[i] & in_domain) tile.differences(i, j, 0, g[i], s[i]);
      else g[i] = s[i] = 0;
    }
  }
  for (int j = row_begin; j < row_end; ++j) {
    const std::uint8_t* b = &tile.bits[static_cast<std::size_t>(j - tile.row0) * t];
    if (j > 0 && j + 1 < t) {
      const double* v = texture.values + static_cast<std::size_t>(j) * t;
      for (int i = 0; i < t; ++i) {
        const double hp = v[i + t], hm = v[i - t];
        row_g2[i] = 0.5 * (hp - hm);
        row_s22[i] = hp - 2 * v[i] + hm;
      }
      for (int i = 0; i < t; ++i) {
        if ((b[i] & north_south) == north_south) continue;
        if (b[i] & in_domain) tile.differences(i, j, 1, row_g2[i], row_s22[i]);
        else row_g2[i] = row_s22[i] = 0;
      }
    } else {
      for (int i = 0; i < t; ++i) {
        if (b[i] & in_domain) tile.differences(i, j, 1, row_g2[i], row_s22[i]);
        else row_g2[i] = row_s22[i] = 0;
      }
    }
    const std::size_t row = static_cast<std::size_t>(j - g_row0) * t;
    const double* g1_row = g1 + row;
    const std::size_t o = static_cast<std::size_t>(j - row_begin) * t;
    // All four neighbours reachable (mixed term central in both directions): vectorized
    // pass over the interior when the rows above and below are held; the others below.
    constexpr std::uint8_t all = in_domain | east_west | north_south;
    const bool interior_row = j > g_row0 && j + 1 < g_last;
    if (interior_row) {
      const double* v = texture.values + static_cast<std::size_t>(j) * t;
      const double* s11_row = s11 + row;
      for (int i = 1; i + 1 < t; ++i) {
        out.value[o + i] = v[i];
        out.g[0][o + i] = g1_row[i];
        out.s[0][o + i] = s11_row[i];
        out.g[1][o + i] = row_g2[i];
        out.s[1][o + i] = row_s22[i];
        out.s[2][o + i] = 0.5 * (0.5 * (g1_row[i + t] - g1_row[i - t]) + 0.5 * (row_g2[i + 1] - row_g2[i - 1]));
      }
    }
    for (int i = 0; i < t; ++i) {
      const std::uint8_t b = tile.at(i, j);
      if (interior_row && b == all) continue;
      if (!(b & in_domain)) {
        out.value[o + i] = out.g[0][o + i] = out.g[1][o + i] = out.s[0][o + i] = out.s[1][o + i] = out.s[2][o + i] = 0;
        continue;
      }
      out.value[o + i] = tile.value(i, j);
      out.g[0][o + i] = g1_row[i];
      out.s[0][o + i] = s11[row + i];
      out.g[1][o + i] = row_g2[i];
      out.s[1][o + i] = row_s22[i];
      const bool north = b & reach_north, south = b & reach_south;
      const bool east = b & reach_east, west = b & reach_west;
      const double g1_north = north ? g1_row[i + t] : 0, g1_south = south ? g1_row[i - t] : 0;
      const double g2_east = east ? row_g2[i + 1] : 0, g2_west = west ? row_g2[i - 1] : 0;
      out.s[2][o + i] =
          0.5 * (detail::mixed_difference_rule(north, south, g1_north, g1_south, g1_row[i]) +
                  detail::mixed_difference_rule(east, west, g2_east, g2_west, row_g2[i]));
    }
  }
}

}  // namespace dgtex::kernels

#include "dgtex/harmonic_enrichment.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/flood_fill.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/laplace_direct.h"

namespace dgtex {
namespace {

using kernels::TexelTile;

void check_cut_fits(const TexelTile& tile, const kernels::CutRaster& cut) {
  const int n = tile.width * tile.height;
  if (tile.width <= 0 || tile.height <= 0 || tile.flags.size() != static_cast<std::size_t>(n) ||
      tile.values.size() != static_cast<std::size_t>(n))
    throw std::invalid_argument("harmonic enrichment: the tile must be non-empty with width * height flags and values");
  for (const auto& e : cut.edges)
    if (e.left_texel >= n || e.right_texel >= n || e.x < 0 || e.y < 0 || e.x > tile.width || e.y > tile.height)
      throw std::invalid_argument("harmonic enrichment: the cut was rasterised for a larger tile than " +
                                  std::to_string(tile.width) + "x" + std::to_string(tile.height));
}

}  // namespace

void set_cut_dirichlet(TexelTile& tile, const kernels::CutRaster& cut, const CutSideValue& value) {
  check_cut_fits(tile, cut);
  std::vector<double> sum(tile.values.size(), 0.0);
  std::vector<int> count(tile.values.size(), 0);
  for (const auto& e : cut.edges) {
    if (e.left_texel >= 0) sum[e.left_texel] += value(e.left_texel, +1), ++count[e.left_texel];
    if (e.right_texel >= 0) sum[e.right_texel] += value(e.right_texel, -1), ++count[e.right_texel];
  }
  for (std::size_t t = 0; t < sum.size(); ++t)
    if (count[t] > 0) {
      const double v = count[t] == 1 ? sum[t] : sum[t] / count[t];
      if (!std::isfinite(v))
        throw std::invalid_argument("harmonic enrichment: the Dirichlet value of texel (" +
                                    std::to_string(t % tile.width) + ", " + std::to_string(t / tile.width) +
                                    ") is not finite");
      tile.values[t] = v;
      tile.flags[t] |= kernels::dirichlet;
    }
}

void set_cut_dirichlet(TexelTile& tile, const kernels::CutRaster& cut) {
  set_cut_dirichlet(tile, cut, [](int, int side) { return static_cast<double>(side); });
}

HarmonicEnrichment harmonic_enrichment(const TexelTile& cut_tile, const kernels::CutRaster& cut,
                                       const CutSideValue& value) {
  HarmonicEnrichment result;
  result.tile = cut_tile;
  TexelTile& h = result.tile;
  check_cut_fits(h, cut);
  for (std::size_t t = 0; t < h.values.size(); ++t)
    if (!(h.flags[t] & kernels::dirichlet)) h.values[t] = 0.0;
  set_cut_dirichlet(h, cut, value);

  // Components whose Dirichlet data are one constant are that constant: fix them all as
  // Dirichlet for the solve so only the genuinely harmonic components are unknowns.
  std::vector<int> labels;
  const int count = kernels::label_components(h, labels);
  enum : int { no_data = 0, constant = 1, varying = 2 };
  std::vector<int> state(count, no_data);
  std::vector<double> constant_value(count, 0.0);
  for (std::size_t t = 0; t < labels.size(); ++t) {
    const int c = labels[t];
    if (c < 0 || !(h.flags[t] & kernels::dirichlet)) continue;
    if (state[c] == no_data) state[c] = constant, constant_value[c] = h.values[t];
    else if (state[c] == constant && h.values[t] != constant_value[c]) state[c] = varying;
  }
  TexelTile solve = h;
  for (std::size_t t = 0; t < labels.size(); ++t) {
    const int c = labels[t];
    if (c >= 0 && state[c] == constant && !(solve.flags[t] & kernels::dirichlet)) {
      solve.flags[t] |= kernels::dirichlet;
      solve.values[t] = constant_value[c];
    }
  }
  for (int c = 0; c < count; ++c) {
    result.constant_components += state[c] == constant;
    result.solved_components += state[c] == varying;
  }
  if (result.solved_components > 0) result.stats = solve_laplace_direct(solve);
  h.values = solve.values;  // flags of h keep only the real Dirichlet data
  return result;
}

HarmonicEnrichment harmonic_enrichment(const TexelTile& cut_tile, const kernels::CutRaster& cut) {
  return harmonic_enrichment(cut_tile, cut, [](int, int side) { return static_cast<double>(side); });
}

// ---------------------------------------------------------------------------------------

std::array<int, 2> block_texel(const PlacedTile& where, int i, int j) {
  const int t = where.tile->width;
  if (where.orientation >= 4) i = t - 1 - i;
  for (int r = 0; r < (where.orientation & 3); ++r) {
    const int turned_i = t - 1 - j;
    j = i;
    i = turned_i;
  }
  return {i + where.offset_x, j + where.offset_y};
}

namespace {

void check_placement(const PlacedTile& where, int width, int height, int resolution) {
  if (!where.tile || where.tile->width != where.tile->height || where.tile->width != resolution ||
      where.tile->flags.size() != static_cast<std::size_t>(resolution) * resolution ||
      where.tile->values.size() != where.tile->flags.size())
    throw std::invalid_argument("tile block: every placed tile must be a square " + std::to_string(resolution) + "x" +
                                std::to_string(resolution) + " tile");
  if (where.orientation < 0 || where.orientation > 7)
    throw std::invalid_argument("tile block: orientation must be in 0..7, got " + std::to_string(where.orientation));
  if (where.offset_x < 0 || where.offset_y < 0 || where.offset_x + resolution > width ||
      where.offset_y + resolution > height)
    throw std::invalid_argument("tile block: a tile at offset (" + std::to_string(where.offset_x) + ", " +
                                std::to_string(where.offset_y) + ") does not fit in the " + std::to_string(width) +
                                "x" + std::to_string(height) + " block");
}

// Calls wall(block_a, block_b) for each wall of the tile between two of its texels.
template <class F>
void for_each_turned_wall(const PlacedTile& where, F&& wall) {
  const TexelTile& tile = *where.tile;
  const int t = tile.width;
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      const auto f = tile.flags[tile.index(i, j)];
      if ((f & kernels::wall_east) && i + 1 < t) wall(block_texel(where, i, j), block_texel(where, i + 1, j));
      if ((f & kernels::wall_north) && j + 1 < t) wall(block_texel(where, i, j), block_texel(where, i, j + 1));
    }
}

void set_wall_between(TexelTile& block, std::array<int, 2> a, std::array<int, 2> b) {
  if (a[0] > b[0] || a[1] > b[1]) std::swap(a, b);
  block.flags[block.index(a[0], a[1])] |= (b[0] > a[0]) ? kernels::wall_east : kernels::wall_north;
}

}  // namespace

TexelTile assemble_tile_block(const std::vector<PlacedTile>& tiles, int width, int height) {
  if (width <= 0 || height <= 0 || tiles.empty())
    throw std::invalid_argument("tile block: needs a positive size and at least one tile");
  const int resolution = tiles.front().tile ? tiles.front().tile->width : 0;
  for (const PlacedTile& where : tiles) check_placement(where, width, height, resolution);
  TexelTile block(width, height);
  std::fill(block.flags.begin(), block.flags.end(), kernels::inactive);
  std::vector<char> is_region(block.flags.size(), 0);
  for (const PlacedTile& where : tiles) {
    if (where.dirichlet_neighbour) continue;
    const TexelTile& tile = *where.tile;
    for (int j = 0; j < resolution; ++j)
      for (int i = 0; i < resolution; ++i) {
        const int s = tile.index(i, j);
        if (tile.flags[s] & kernels::inactive) continue;
        const auto [bi, bj] = block_texel(where, i, j);
        const int b = block.index(bi, bj);
        block.flags[b] = static_cast<std::uint8_t>((block.flags[b] & ~kernels::inactive & ~kernels::dirichlet) |
                                                   (tile.flags[s] & kernels::dirichlet));
        block.values[b] = tile.values[s];
        is_region[b] = 1;
      }
    for_each_turned_wall(where, [&](auto a, auto b) { set_wall_between(block, a, b); });
  }
  // C0 data: neighbour texels 4-adjacent to a region texel (no wall of the neighbour's own
  // between them is possible: they lie in different tiles).
  for (const PlacedTile& where : tiles) {
    if (!where.dirichlet_neighbour) continue;
    const TexelTile& tile = *where.tile;
    for (int j = 0; j < resolution; ++j)
      for (int i = 0; i < resolution; ++i) {
        const int s = tile.index(i, j);
        if (tile.flags[s] & kernels::inactive) continue;
        const auto [bi, bj] = block_texel(where, i, j);
        const int b = block.index(bi, bj);
        if (is_region[b]) continue;
        bool touches_region = false;
        const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
          const int ni = bi + di[k], nj = bj + dj[k];
          if (ni >= 0 && nj >= 0 && ni < width && nj < height && is_region[block.index(ni, nj)]) touches_region = true;
        }
        if (!touches_region) continue;
        block.flags[b] = static_cast<std::uint8_t>((block.flags[b] & ~kernels::inactive) | kernels::dirichlet);
        block.values[b] = tile.values[s];
      }
  }
  return block;
}

TexelTile extract_tile(const TexelTile& block, const PlacedTile& where) {
  check_placement(where, block.width, block.height, where.tile ? where.tile->width : 0);
  TexelTile tile = *where.tile;
  auto block_connected = [&](std::array<int, 2> a, std::array<int, 2> b) {
    if (a[0] > b[0] || a[1] > b[1]) std::swap(a, b);
    const auto f = block.flags[block.index(a[0], a[1])];
    return !(f & ((b[0] > a[0]) ? kernels::wall_east : kernels::wall_north));
  };
  for (int j = 0; j < tile.height; ++j)
    for (int i = 0; i < tile.width; ++i) {
      const int s = tile.index(i, j);
      const auto here = block_texel(where, i, j);
      const int b = block.index(here[0], here[1]);
      std::uint8_t f = static_cast<std::uint8_t>((tile.flags[s] & kernels::inactive) | (block.flags[b] & kernels::dirichlet));
      if (i + 1 < tile.width && !block_connected(here, block_texel(where, i + 1, j))) f |= kernels::wall_east;
      if (j + 1 < tile.height && !block_connected(here, block_texel(where, i, j + 1))) f |= kernels::wall_north;
      tile.flags[s] = f;
      tile.values[s] = (f & kernels::inactive) ? 0.0 : block.values[b];
    }
  return tile;
}

}  // namespace dgtex

#include "dgtex/heaviside.h"

#include <stdexcept>
#include <string>

#include "dgtex/kernels/flood_fill.h"

namespace dgtex {
namespace {

// Side bits per component: 1 = has a texel left of the cut, 2 = right of it.
// Returns -1 if complete, else a texel of a component touching both sides.
int classify_sides(const kernels::TexelTile& cut_tile, const kernels::CutRaster& cut, const std::vector<int>& labels,
                   int count, std::vector<int>& side_bits) {
  side_bits.assign(count, 0);
  for (const kernels::CutLatticeEdge& e : cut.edges) {
    if (e.left_texel >= 0) side_bits[labels[e.left_texel]] |= 1;
    if (e.right_texel >= 0) side_bits[labels[e.right_texel]] |= 2;
  }
  for (const kernels::CutLatticeEdge& e : cut.edges)
    for (int t : {e.left_texel, e.right_texel})
      if (t >= 0 && side_bits[labels[t]] == 3) return t;
  (void)cut_tile;
  return -1;
}

}  // namespace

std::vector<kernels::TexelTile> canonical_heavisides(const kernels::TexelTile& cut_tile) {
  std::vector<int> labels;
  const int count = kernels::label_components(cut_tile, labels);
  std::vector<kernels::TexelTile> heavisides(count, cut_tile);
  for (auto& h : heavisides) std::fill(h.values.begin(), h.values.end(), 0.0);
  for (std::size_t t = 0; t < labels.size(); ++t)
    if (labels[t] >= 0) heavisides[labels[t]].values[t] = 1.0;
  return heavisides;
}

bool is_complete_cut(const kernels::TexelTile& cut_tile, const kernels::CutRaster& cut) {
  std::vector<int> labels, sides;
  const int count = kernels::label_components(cut_tile, labels);
  bool left = false, right = false;
  for (const auto& e : cut.edges) {
    left |= e.left_texel >= 0;
    right |= e.right_texel >= 0;
  }
  return left && right && classify_sides(cut_tile, cut, labels, count, sides) < 0;
}

kernels::TexelTile complete_cut_heaviside(const kernels::TexelTile& cut_tile, const kernels::CutRaster& cut) {
  std::vector<int> labels, sides;
  const int count = kernels::label_components(cut_tile, labels);
  const int both = classify_sides(cut_tile, cut, labels, count, sides);
  if (both >= 0)
    throw std::invalid_argument("complete cut Heaviside: the cut is partial, texel (" +
                                std::to_string(both % cut_tile.width) + ", " + std::to_string(both / cut_tile.width) +
                                ") is reachable from both of its sides; use harmonic_enrichment");
  kernels::TexelTile h = cut_tile;
  for (std::size_t t = 0; t < labels.size(); ++t) {
    const int bits = labels[t] >= 0 ? sides[labels[t]] : 0;
    h.values[t] = bits == 1 ? 1.0 : bits == 2 ? -1.0 : 0.0;
  }
  return h;
}

}  // namespace dgtex

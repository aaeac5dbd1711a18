#pragma once
// Multi-element harmonic problems for the mesh texel Laplace tests (mesh_texel_laplace.h).
#include <cmath>
#include <cstddef>
#include <vector>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/texel_grid.h"
#include "dgtex/mesh.h"
#include "dgtex/mesh_texel_laplace.h"

namespace dgtex::testing_support {

// Tiles (T x T) of the given elements: Dirichlet +1 on a short run of texels in the first
// solved tile and -1 in the last, a wall in every tile (at varying positions), free texels
// 0.5 (a warm start that is not the solution). Tiles listed in `frozen` (indices into
// `elements`) are settled: smooth non-constant values that act as data.
inline std::vector<RegionTile> make_test_region(const Mesh& mesh, const std::vector<int>& elements, int T,
                                                const std::vector<int>& frozen = {}) {
  std::vector<RegionTile> region;
  for (std::size_t n = 0; n < elements.size(); ++n) {
    RegionTile r;
    r.element = elements[n];
    r.tile = kernels::make_element_tile(mesh.type, T);
    for (double& v : r.tile.values) v = 0.5;
    const int x = 5 + 7 * static_cast<int>(n) % 20;
    for (int j = 2; j < T / 2; ++j) r.tile.flags[j * T + x] |= kernels::wall_east;
    region.push_back(std::move(r));
  }
  for (int l : frozen) {
    region[l].frozen = true;
    for (std::size_t k = 0; k < region[l].tile.values.size(); ++k) region[l].tile.values[k] = 0.25 * std::sin(0.1 * k);
  }
  int first = 0, last = static_cast<int>(region.size()) - 1;
  while (region[first].frozen) ++first;
  while (region[last].frozen) --last;
  for (int i = 3; i < 9; ++i) {
    region[first].tile.flags[4 * T + i] |= kernels::dirichlet;
    region[first].tile.values[4 * T + i] = 1.0;
    region[last].tile.flags[6 * T + i] |= kernels::dirichlet;
    region[last].tile.values[6 * T + i] = -1.0;
  }
  return region;
}

}  // namespace dgtex::testing_support

#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex::kernels {

int classify_laplace_texels(const TexelTile& tile, std::vector<std::uint8_t>& bits) {
  const int w = tile.width, h = tile.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  bits.assign(n, 0);
  auto free_texel = [&](int t) { return !(tile.flags[t] & (dirichlet | inactive)); };

  // Degrees (couplings to active neighbours) and whether a free texel touches Dirichlet data.
  std::vector<std::uint8_t> touches_dirichlet(n, 0);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int t = tile.index(i, j);
      if (tile.flags[t] & inactive) continue;
      int degree = 0;
      auto visit = [&](bool coupled, int nb) {
        if (!coupled) return;
        ++degree;
        if (tile.flags[nb] & dirichlet) touches_dirichlet[t] = 1;
      };
      visit(i > 0 && texels_coupled_east(tile, i - 1, j), t - 1);
      visit(texels_coupled_east(tile, i, j), t + 1);
      visit(j > 0 && texels_coupled_north(tile, i, j - 1), t - w);
      visit(texels_coupled_north(tile, i, j), t + w);
      bits[t] = static_cast<std::uint8_t>(degree << degree_shift);
    }

  // Flood fill over free texels; a component is solvable iff one of its texels touches
  // Dirichlet data. Component ids are assigned in texel order, so the result is unique.
  std::vector<int> component(n, -1), stack, members;
  int zeroed = 0;
  for (int seed = 0; seed < static_cast<int>(n); ++seed) {
    if (component[seed] >= 0 || !free_texel(seed)) continue;
    bool has_dirichlet = false;
    members.clear();
    stack.assign(1, seed);
    component[seed] = seed;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      members.push_back(t);
      has_dirichlet = has_dirichlet || touches_dirichlet[t];
      const int i = t % w, j = t / w;
      auto push = [&](bool coupled, int nb) {
        if (coupled && component[nb] < 0 && free_texel(nb)) {
          component[nb] = seed;
          stack.push_back(nb);
        }
      };
      push(i > 0 && texels_coupled_east(tile, i - 1, j), t - 1);
      push(texels_coupled_east(tile, i, j), t + 1);
      push(j > 0 && texels_coupled_north(tile, i, j - 1), t - w);
      push(texels_coupled_north(tile, i, j), t + w);
    }
    if (has_dirichlet)
      for (int t : members) bits[t] |= is_unknown;
    else
      zeroed += static_cast<int>(members.size());
  }

  // Couplings between unknowns (the off-diagonal entries of the reduced system).
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int t = tile.index(i, j);
      if (!(bits[t] & is_unknown)) continue;
      if (i > 0 && texels_coupled_east(tile, i - 1, j) && (bits[t - 1] & is_unknown)) bits[t] |= couples_west_unknown;
      if (texels_coupled_east(tile, i, j) && (bits[t + 1] & is_unknown)) bits[t] |= couples_east_unknown;
      if (j > 0 && texels_coupled_north(tile, i, j - 1) && (bits[t - w] & is_unknown)) bits[t] |= couples_south_unknown;
      if (texels_coupled_north(tile, i, j) && (bits[t + w] & is_unknown)) bits[t] |= couples_north_unknown;
    }
  return zeroed;
}

}  // namespace dgtex::kernels

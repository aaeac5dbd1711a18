#include "dgtex/laplace_domains.h"

#include <algorithm>
#include <stdexcept>

namespace dgtex {
using kernels::TexelTile;

void add_vertical_wall(TexelTile& tile, int x, int j0, int j1) {
  if (x < 1 || x >= tile.width) return;
  for (int j = std::max(j0, 0); j < std::min(j1, tile.height); ++j) tile.flags[tile.index(x - 1, j)] |= kernels::wall_east;
}

void add_horizontal_wall(TexelTile& tile, int y, int i0, int i1) {
  if (y < 1 || y >= tile.height) return;
  for (int i = std::max(i0, 0); i < std::min(i1, tile.width); ++i) tile.flags[tile.index(i, y - 1)] |= kernels::wall_north;
}

namespace {

void set_dirichlet(TexelTile& tile, int i, int j, double value) {
  if (i < 0 || j < 0 || i >= tile.width || j >= tile.height) return;
  const int t = tile.index(i, j);
  if (tile.flags[t] & kernels::inactive) return;
  tile.flags[t] |= kernels::dirichlet;
  tile.values[t] = value;
}

// +1 on the first active texel of each row, -1 on the last (rows with one texel: +1).
void west_east_dirichlet(TexelTile& tile) {
  for (int j = 0; j < tile.height; ++j) {
    int first = -1, last = -1;
    for (int i = 0; i < tile.width; ++i)
      if (!(tile.flags[tile.index(i, j)] & kernels::inactive)) {
        if (first < 0) first = i;
        last = i;
      }
    if (first < 0) continue;
    set_dirichlet(tile, last, j, -1.0);
    set_dirichlet(tile, first, j, +1.0);
  }
}

// A rectangular spiral of walls from corner point (cx, cy): arms of length s, s, 2s, 2s, ...
// turning east, north, west, south, until an arm would leave [lo, hi]^2.
void spiral_walls(TexelTile& tile, int cx, int cy, int s, int lo, int hi) {
  int x = cx, y = cy;
  const int dx[4] = {1, 0, -1, 0}, dy[4] = {0, 1, 0, -1};
  for (int arm = 0;; ++arm) {
    const int length = s * (arm / 2 + 1), d = arm % 4;
    const int nx = x + dx[d] * length, ny = y + dy[d] * length;
    if (nx < lo || nx > hi || ny < lo || ny > hi) break;
    if (dy[d] == 0) add_horizontal_wall(tile, y, std::min(x, nx), std::max(x, nx));
    else add_vertical_wall(tile, x, std::min(y, ny), std::max(y, ny));
    x = nx;
    y = ny;
  }
}

// Walls around the texels whose centres lie inside the circle, except on the two
// east-most boundary edges in rows cy-1 and cy (the bridge).
void circle_walls(TexelTile& tile, double cx, double cy, double radius) {
  auto inside = [&](int i, int j) {
    const double x = i + 0.5 - cx, y = j + 0.5 - cy;
    return i >= 0 && j >= 0 && i < tile.width && j < tile.height && x * x + y * y < radius * radius;
  };
  const int bridge_row = static_cast<int>(cy);
  for (int j = 0; j < tile.height; ++j)
    for (int i = 0; i < tile.width; ++i) {
      if (inside(i, j) != inside(i + 1, j) && i + 1 < tile.width) {
        const bool bridge = inside(i, j) && (j == bridge_row || j == bridge_row - 1);
        if (!bridge) tile.flags[tile.index(i, j)] |= kernels::wall_east;
      }
      if (inside(i, j) != inside(i, j + 1) && j + 1 < tile.height) tile.flags[tile.index(i, j)] |= kernels::wall_north;
    }
}

}  // namespace

TexelTile make_laplace_domain(LaplaceDomain domain, int T, TexelElementShape shape) {
  if (T < 16)
    throw std::invalid_argument("Laplace domain: size T = " + std::to_string(T) + " is too small, need T >= 16");
  const bool tri = shape == TexelElementShape::tri;
  if (domain == LaplaceDomain::one_ring) {
    if (tri) throw std::invalid_argument("Laplace domain: one_ring is defined for quad elements only");
    TexelTile tile(3 * T, 3 * T);
    const int y = 3 * T / 2 + 1, end = 3 * T / 2;
    add_horizontal_wall(tile, y, 0, end);
    for (int i = 0; i < end; ++i) {
      set_dirichlet(tile, i, y, +1.0);
      set_dirichlet(tile, i, y - 1, -1.0);
    }
    add_vertical_wall(tile, 5 * T / 3, 0, 3 * T / 2);
    return tile;
  }
  TexelTile tile(T, T);
  if (tri)
    for (int j = 0; j < T; ++j)
      for (int i = T - j; i < T; ++i) tile.flags[tile.index(i, j)] |= kernels::inactive;
  switch (domain) {
    case LaplaceDomain::open: break;
    case LaplaceDomain::slit: add_vertical_wall(tile, (tri ? T / 3 : T / 2) + 1, 0, 3 * T / 4); break;
    case LaplaceDomain::spiral: {
      const int s = std::max(4, T / 16), c = tri ? T / 3 : T / 2;
      spiral_walls(tile, c, c, s, 2, tri ? 2 * c - 2 : T - 2);
      break;
    }
    case LaplaceDomain::accordion:
      for (int k = 0; k < 18; ++k) {
        const int x = static_cast<int>((k + 1) * T / 19.0 + 0.5);
        if (k % 2 == 0) add_vertical_wall(tile, x, 0, T - T / 8);
        else add_vertical_wall(tile, x, T / 8, T);
      }
      break;
    case LaplaceDomain::chad:
      if (tri) circle_walls(tile, T / 3.0, T / 3.0, T / 5.0);
      else circle_walls(tile, T / 2.0, T / 2.0, T / 4.0);
      break;
    case LaplaceDomain::one_ring: break;
  }
  if (domain == LaplaceDomain::spiral) {
    const int c = tri ? T / 3 : T / 2;
    for (int j = c - 1; j <= c; ++j)
      for (int i = c - 1; i <= c; ++i) set_dirichlet(tile, i, j, +1.0);
    for (int j = 0; j < T; ++j) set_dirichlet(tile, 0, j, -1.0);
  } else {
    west_east_dirichlet(tile);
  }
  return tile;
}

std::string laplace_domain_name(LaplaceDomain domain) {
  switch (domain) {
    case LaplaceDomain::open: return "open";
    case LaplaceDomain::slit: return "slit";
    case LaplaceDomain::spiral: return "spiral";
    case LaplaceDomain::accordion: return "accordion";
    case LaplaceDomain::chad: return "chad";
    case LaplaceDomain::one_ring: return "one_ring";
  }
  return "unknown";
}

const std::vector<LaplaceDomain>& all_laplace_domains() {
  static const std::vector<LaplaceDomain> domains = {LaplaceDomain::open,      LaplaceDomain::slit,
                                                     LaplaceDomain::spiral,    LaplaceDomain::accordion,
                                                     LaplaceDomain::chad,      LaplaceDomain::one_ring};
  return domains;
}

LaplaceDomain parse_laplace_domain(const std::string& name) {
  for (LaplaceDomain d : all_laplace_domains())
    if (laplace_domain_name(d) == name) return d;
  throw std::invalid_argument("unknown Laplace domain '" + name +
                              "'; valid: open, slit, spiral, accordion, chad, one_ring");
}

}  // namespace dgtex

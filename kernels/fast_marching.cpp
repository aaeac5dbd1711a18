#include "dgtex/kernels/fast_marching.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>
#include <utility>

namespace dgtex::kernels {

namespace {

void check_spacing(double spacing_x, double spacing_y, const char* who) {
  if (!(std::isfinite(spacing_x) && spacing_x > 0 && std::isfinite(spacing_y) && spacing_y > 0))
    throw std::invalid_argument(std::string(who) + ": texel spacings must be finite and positive, got " +
                                std::to_string(spacing_x) + ", " + std::to_string(spacing_y));
}

enum class State : std::uint8_t { far, trial, known };

// Solves the upwind quadratic for known neighbour values a (along x) and b (along y), either
// possibly +infinity (no known neighbour on that axis).
double upwind_update(double a, double b, double hx, double hy) {
  const double inf = std::numeric_limits<double>::infinity();
  const double one_axis = std::min(a == inf ? inf : a + hx, b == inf ? inf : b + hy);
  if (a == inf || b == inf) return one_axis;
  const double hx2 = hx * hx, hy2 = hy * hy;
  const double qa = hx2 + hy2;
  const double qb = -2.0 * (hy2 * a + hx2 * b);
  const double qc = hy2 * a * a + hx2 * b * b - hx2 * hy2;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0) return one_axis;
  const double d = (-qb + std::sqrt(disc)) / (2.0 * qa);
  return d >= std::max(a, b) ? std::min(d, one_axis) : one_axis;
}

double point_segment_distance(double px, double py, const TexelPoint& p, const TexelPoint& q, double hx, double hy) {
  // In physical units: scale texel coordinates by the spacings first.
  const double ax = p[0] * hx, ay = p[1] * hy, bx = q[0] * hx, by = q[1] * hy;
  const double dx = bx - ax, dy = by - ay;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = px - (ax + t * dx), ey = py - (ay + t * dy);
  return std::sqrt(ex * ex + ey * ey);
}

}  // namespace

int fast_marching_reference(TexelTile& tile, const std::vector<std::uint8_t>& seeded, double spacing_x,
                            double spacing_y) {
  check_spacing(spacing_x, spacing_y, "fast_marching_reference");
  const int w = tile.width, h = tile.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  if (seeded.size() != n)
    throw std::invalid_argument("fast_marching_reference: seeded has " + std::to_string(seeded.size()) +
                                " entries, the tile " + std::to_string(n));
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<State> state(n, State::far);
  using Entry = std::pair<double, int>;  // (distance, texel): ties by index
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (std::size_t k = 0; k < n; ++k) {
    if (tile.flags[k] & inactive) continue;
    if (seeded[k]) {
      const double v = tile.values[k];
      if (!(std::isfinite(v) && v >= 0))
        throw std::invalid_argument("fast_marching_reference: seed texel " + std::to_string(k) +
                                    " has distance " + std::to_string(v) + ", expected a finite value >= 0");
      state[k] = State::known;
    } else {
      tile.values[k] = inf;
    }
  }
  auto active = [&](int i, int j) { return !(tile.flags[tile.index(i, j)] & inactive); };
  // Known value of the neighbour of (i, j) at offset (di, dj), +inf if blocked or not known.
  auto known_neighbour = [&](int i, int j, int di, int dj) {
    const int ni = i + di, nj = j + dj;
    if (ni < 0 || nj < 0 || ni >= w || nj >= h || !active(ni, nj)) return inf;
    const bool connected = di > 0   ? tile.connected_east(i, j)
                           : di < 0 ? tile.connected_east(ni, nj)
                           : dj > 0 ? tile.connected_north(i, j)
                                    : tile.connected_north(ni, nj);
    if (!connected) return inf;
    const int k = tile.index(ni, nj);
    return state[k] == State::known ? tile.values[k] : inf;
  };
  auto update = [&](int i, int j) {
    const int k = tile.index(i, j);
    if (state[k] == State::known || !active(i, j)) return;
    const double a = std::min(known_neighbour(i, j, -1, 0), known_neighbour(i, j, 1, 0));
    const double b = std::min(known_neighbour(i, j, 0, -1), known_neighbour(i, j, 0, 1));
    const double d = upwind_update(a, b, spacing_x, spacing_y);
    if (d < tile.values[k]) {
      tile.values[k] = d;
      state[k] = State::trial;
      heap.push({d, k});
    }
  };
  auto update_neighbours = [&](int k) {
    const int i = k % w, j = k / w;
    if (i + 1 < w && tile.connected_east(i, j)) update(i + 1, j);
    if (i > 0 && tile.connected_east(i - 1, j)) update(i - 1, j);
    if (j + 1 < h && tile.connected_north(i, j)) update(i, j + 1);
    if (j > 0 && tile.connected_north(i, j - 1)) update(i, j - 1);
  };
  for (std::size_t k = 0; k < n; ++k)
    if (state[k] == State::known && !(tile.flags[k] & inactive)) update_neighbours(static_cast<int>(k));
  while (!heap.empty()) {
    const auto [d, k] = heap.top();
    heap.pop();
    if (state[k] == State::known || d != tile.values[k]) continue;  // stale entry
    state[k] = State::known;
    update_neighbours(k);
  }
  int unreached = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (!(tile.flags[k] & inactive) && state[k] != State::known) ++unreached;
  return unreached;
}

int seed_polyline_distance(const std::vector<TexelPoint>& polyline, TexelTile& tile, std::vector<std::uint8_t>& seeded,
                           double spacing_x, double spacing_y, double band) {
  check_spacing(spacing_x, spacing_y, "seed_polyline_distance");
  if (polyline.size() < 2)
    throw std::invalid_argument("seed_polyline_distance: a polyline needs at least 2 points, got " +
                                std::to_string(polyline.size()));
  for (const TexelPoint& p : polyline)
    if (!(std::isfinite(p[0]) && std::isfinite(p[1])))
      throw std::invalid_argument("seed_polyline_distance: polyline points must be finite");
  if (!(std::isfinite(band) && band >= 0))
    throw std::invalid_argument("seed_polyline_distance: band must be finite and >= 0, got " + std::to_string(band));
  const std::size_t n = static_cast<std::size_t>(tile.width) * tile.height;
  seeded.resize(n, 0);
  int count = 0;
  for (int j = 0; j < tile.height; ++j)
    for (int i = 0; i < tile.width; ++i) {
      const int k = tile.index(i, j);
      if (tile.flags[k] & inactive) continue;
      const double px = (i + 0.5) * spacing_x, py = (j + 0.5) * spacing_y;
      double d = std::numeric_limits<double>::infinity();
      for (std::size_t s = 0; s + 1 < polyline.size(); ++s)
        d = std::min(d, point_segment_distance(px, py, polyline[s], polyline[s + 1], spacing_x, spacing_y));
      if (d > band) continue;
      tile.values[k] = seeded[k] ? std::min(tile.values[k], d) : d;
      seeded[k] = 1;
      ++count;
    }
  return count;
}

}  // namespace dgtex::kernels

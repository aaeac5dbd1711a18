#include "dgtex/kernels/cut_rasterization.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dgtex::kernels {
namespace {

struct LatticePoint {
  int x, y;
};

LatticePoint snap(double x, double y) {
  return {static_cast<int>(std::floor(x + 0.5)), static_cast<int>(std::floor(y + 0.5))};
}

// Liang-Barsky clip of p + t (q - p), t in [0, 1], to [0, w] x [0, h]. False if nothing is left.
bool clip_to_tile(TexelPoint& p, TexelPoint& q, double w, double h) {
  const double d[2] = {q[0] - p[0], q[1] - p[1]};
  double t0 = 0.0, t1 = 1.0;
  auto clip = [&](double denominator, double numerator) {  // keep t with denominator * t <= numerator
    if (denominator == 0.0) return numerator >= 0.0;
    const double t = numerator / denominator;
    if (denominator < 0.0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    return t0 <= t1;
  };
  if (!clip(-d[0], p[0]) || !clip(d[0], w - p[0]) || !clip(-d[1], p[1]) || !clip(d[1], h - p[1])) return false;
  const TexelPoint a = {p[0] + t0 * d[0], p[1] + t0 * d[1]};
  const TexelPoint b = {p[0] + t1 * d[0], p[1] + t1 * d[1]};
  // Exact end points stay exact (no rounding by t * d when nothing was clipped).
  if (t0 > 0.0) p = a;
  if (t1 < 1.0) q = b;
  return true;
}

int texel_or_none(const TexelTile& tile, int i, int j) {
  if (i < 0 || j < 0 || i >= tile.width || j >= tile.height) return -1;
  const int t = tile.index(i, j);
  return (tile.flags[t] & inactive) ? -1 : t;
}

CutLatticeEdge make_edge(const TexelTile& tile, int x, int y, int dx, int dy) {
  CutLatticeEdge e{x, y, dx, dy, -1, -1};
  if (dx == 1) {
    e.left_texel = texel_or_none(tile, x, y);
    e.right_texel = texel_or_none(tile, x, y - 1);
  } else if (dx == -1) {
    e.left_texel = texel_or_none(tile, x - 1, y - 1);
    e.right_texel = texel_or_none(tile, x - 1, y);
  } else if (dy == 1) {
    e.left_texel = texel_or_none(tile, x - 1, y);
    e.right_texel = texel_or_none(tile, x, y);
  } else {
    e.left_texel = texel_or_none(tile, x, y - 1);
    e.right_texel = texel_or_none(tile, x - 1, y - 1);
  }
  return e;
}

// The lattice path of one polyline segment (appended to `out`).
void rasterize_segment(TexelPoint p, TexelPoint q, const TexelTile& tile, std::vector<CutLatticeEdge>& out) {
  // Canonical direction (lexicographically smaller end first) so that both directions of a
  // segment round identically and give the same lattice edges.
  const bool reversed = q < p;
  if (reversed) std::swap(p, q);
  if (!clip_to_tile(p, q, tile.width, tile.height)) return;
  const LatticePoint a = snap(p[0], p[1]), b = snap(q[0], q[1]);
  if (a.x == b.x && a.y == b.y) return;
  const double ux = q[0] - p[0], uy = q[1] - p[1];
  // Unnormalised distance of a lattice point to the segment's line (same line either way).
  auto distance = [&](int x, int y) { return std::abs(ux * (y - p[1]) - uy * (x - p[0])); };
  // Distances equal to 1e-9 texels are ties: a segment along a tri6 hypotenuse arrives with
  // round-off from the surface projection, and an exact comparison then let the staircase
  // wander to the inner side of the diagonal texels (giving them the other side's value).
  const double tie = 1e-9 * (std::abs(ux) + std::abs(uy));
  const int sx = b.x > a.x ? 1 : -1, sy = b.y > a.y ? 1 : -1;
  const std::size_t first = out.size();
  int x = a.x, y = a.y;
  while (x != b.x || y != b.y) {
    bool step_x;
    if (x == b.x) step_x = false;
    else if (y == b.y) step_x = true;
    else {
      const double dist_x = distance(x + sx, y), dist_y = distance(x, y + sy);
      if (std::abs(dist_x - dist_y) > tie) step_x = dist_x < dist_y;
      else if (sx != sy) step_x = sx > 0;  // larger x + y first (only differs when sx != sy)
      else step_x = true;
    }
    const int dx = step_x ? sx : 0, dy = step_x ? 0 : sy;
    out.push_back(make_edge(tile, x, y, dx, dy));
    x += dx;
    y += dy;
  }
  if (reversed) {
    std::reverse(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
    for (std::size_t k = first; k < out.size(); ++k) {
      const CutLatticeEdge& e = out[k];
      out[k] = make_edge(tile, e.x + e.dx, e.y + e.dy, -e.dx, -e.dy);
    }
  }
}

void validate_polyline(const std::vector<TexelPoint>& polyline, const TexelTile& tile) {
  if (polyline.size() < 2)
    throw std::invalid_argument("cut rasterization: a cut needs at least 2 polyline points, got " +
                                std::to_string(polyline.size()));
  if (tile.width <= 0 || tile.height <= 0 || tile.flags.size() != static_cast<std::size_t>(tile.width) * tile.height)
    throw std::invalid_argument("cut rasterization: the tile must be non-empty with width * height flags");
  for (std::size_t k = 0; k < polyline.size(); ++k)
    if (!std::isfinite(polyline[k][0]) || !std::isfinite(polyline[k][1]))
      throw std::invalid_argument("cut rasterization: polyline point " + std::to_string(k) + " is not finite");
}

void mark_walls(const std::vector<CutLatticeEdge>& edges, TexelTile& tile) {
  for (const CutLatticeEdge& e : edges) {
    if (e.dy == 0) {  // horizontal edge on lattice line y, between rows y - 1 and y
      const int i = std::min(e.x, e.x + e.dx);
      if (e.y > 0 && e.y < tile.height && i >= 0 && i < tile.width) tile.flags[tile.index(i, e.y - 1)] |= wall_north;
    } else {  // vertical edge on lattice line x, between columns x - 1 and x
      const int j = std::min(e.y, e.y + e.dy);
      if (e.x > 0 && e.x < tile.width && j >= 0 && j < tile.height) tile.flags[tile.index(e.x - 1, j)] |= wall_east;
    }
  }
}

}  // namespace

void mark_cut_walls(const CutRaster& cut, TexelTile& tile) { mark_walls(cut.edges, tile); }

int CutRaster::interior_edge_count() const {
  int n = 0;
  for (const CutLatticeEdge& e : edges) n += (e.left_texel >= 0 && e.right_texel >= 0);
  return n;
}

CutRaster rasterize_cut_reference(const std::vector<TexelPoint>& polyline, TexelTile& tile) {
  validate_polyline(polyline, tile);
  CutRaster raster;
  for (std::size_t s = 0; s + 1 < polyline.size(); ++s) rasterize_segment(polyline[s], polyline[s + 1], tile, raster.edges);
  mark_walls(raster.edges, tile);
  return raster;
}

CutRaster rasterize_cut(const std::vector<TexelPoint>& polyline, TexelTile& tile, Execution execution) {
  validate_polyline(polyline, tile);
  const std::int64_t segments = static_cast<std::int64_t>(polyline.size()) - 1;
  std::vector<std::vector<CutLatticeEdge>> pieces(static_cast<std::size_t>(segments));
  // A thread team costs more than rasterising a few segments: short polylines run serially
  // (the result is the same either way).
  constexpr std::int64_t min_parallel_segments = 64;
  if (segments < min_parallel_segments) execution = Execution::serial;
  forall(
      segments, [&](std::int64_t s) { rasterize_segment(polyline[s], polyline[s + 1], tile, pieces[s]); }, execution);
  CutRaster raster;
  std::size_t total = 0;
  for (const auto& piece : pieces) total += piece.size();
  raster.edges.reserve(total);
  for (const auto& piece : pieces) raster.edges.insert(raster.edges.end(), piece.begin(), piece.end());
  mark_walls(raster.edges, tile);
  return raster;
}

namespace {

// Whether the lattice edge from (x, y) along +x (axis 0) or +y (axis 1) is a wall between
// two texels of the tile.
bool is_wall(const TexelTile& tile, int x, int y, int axis) {
  if (axis == 0) return y > 0 && y < tile.height && x >= 0 && x < tile.width && tile.is_wall_north(x, y - 1);
  return x > 0 && x < tile.width && y >= 0 && y < tile.height && tile.is_wall_east(x - 1, y);
}

bool is_domain_texel(const TexelTile& tile, int i, int j) {
  return i >= 0 && j >= 0 && i < tile.width && j < tile.height && !(tile.flags[tile.index(i, j)] & inactive);
}

// Whether lattice point (x, y) touches an earlier cut's wall or the domain boundary.
bool touches_walls_or_boundary(const TexelTile& tile, int x, int y) {
  if (is_wall(tile, x, y, 0) || is_wall(tile, x - 1, y, 0) || is_wall(tile, x, y, 1) || is_wall(tile, x, y - 1, 1))
    return true;
  return !is_domain_texel(tile, x - 1, y - 1) || !is_domain_texel(tile, x, y - 1) || !is_domain_texel(tile, x - 1, y) ||
         !is_domain_texel(tile, x, y);
}

}  // namespace

std::vector<CutRaster> split_cut_at_crossings(const CutRaster& cut, const TexelTile& earlier_walls) {
  if (earlier_walls.width <= 0 || earlier_walls.height <= 0 ||
      earlier_walls.flags.size() != static_cast<std::size_t>(earlier_walls.width) * earlier_walls.height)
    throw std::invalid_argument("split_cut_at_crossings: the wall tile must be non-empty with width * height flags");
  const std::size_t n = cut.edges.size();
  // Path vertex k (0 < k < n) is the start of edge k; it is interior if edge k-1 ends there
  // (clipping can leave breaks in a path; the vertices at a break are path ends).
  auto interior = [&](std::size_t k) {
    const CutLatticeEdge &a = cut.edges[k - 1], &b = cut.edges[k];
    return a.x + a.dx == b.x && a.y + a.dy == b.y;
  };
  auto touches = [&](std::size_t k) { return touches_walls_or_boundary(earlier_walls, cut.edges[k].x, cut.edges[k].y); };
  std::vector<std::size_t> splits;
  for (std::size_t k = 1; k < n;) {
    if (!interior(k) || !touches(k)) {
      ++k;
      continue;
    }
    const std::size_t first = k;
    while (k < n && interior(k) && touches(k)) ++k;
    // A contact that continues into a path end is where the cut starts or ends (a junction).
    const CutLatticeEdge &before = cut.edges[first - 1], &last = cut.edges[k - 1];
    const bool end_before = first - 1 == 0 || !interior(first - 1);
    const bool end_after = k == n || !interior(k);
    const bool at_end = (end_before && touches_walls_or_boundary(earlier_walls, before.x, before.y)) ||
                        (end_after && touches_walls_or_boundary(earlier_walls, last.x + last.dx, last.y + last.dy));
    if (!at_end) splits.push_back(first);
  }
  std::vector<CutRaster> pieces;
  std::size_t begin = 0;
  splits.push_back(n);
  for (std::size_t end : splits) {
    CutRaster piece;
    piece.edges.assign(cut.edges.begin() + static_cast<std::ptrdiff_t>(begin),
                       cut.edges.begin() + static_cast<std::ptrdiff_t>(end));
    if (!piece.edges.empty()) pieces.push_back(std::move(piece));
    begin = end;
  }
  return pieces;
}

TexelPoint texel_point_from_parametric(ElementType type, int resolution, double xi1, double xi2) {
  if (type == ElementType::quad8) return {(xi1 + 1.0) * 0.5 * resolution, (xi2 + 1.0) * 0.5 * resolution};
  return {xi1 * resolution, xi2 * resolution};
}

std::array<double, 2> parametric_from_texel_point(ElementType type, int resolution, TexelPoint point) {
  if (type == ElementType::quad8) return {2.0 * point[0] / resolution - 1.0, 2.0 * point[1] / resolution - 1.0};
  return {point[0] / resolution, point[1] / resolution};
}

TexelTile make_element_tile(ElementType type, int resolution) {
  if (resolution < 1 || (resolution & (resolution - 1)) != 0)
    throw std::invalid_argument("texel tile: the texture resolution must be a positive power of two, got " +
                                std::to_string(resolution));
  TexelTile tile(resolution, resolution);
  if (type == ElementType::tri6)
    for (int j = 0; j < resolution; ++j)
      for (int i = 0; i < resolution; ++i)
        if (!is_tri6_texel_active(i, j, resolution)) tile.flags[tile.index(i, j)] = inactive;
  return tile;
}

}  // namespace dgtex::kernels

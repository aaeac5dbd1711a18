#include "dgtex/mesh_texel_laplace.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/flood_fill.h"
#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "graph_laplacian_amg.h"
#include "seamed_patch_laplace.h"

namespace dgtex {

int edge_texel_index(ElementType type, int t, int edge, int s) {
  int i = 0, j = 0;
  if (type == ElementType::quad8) {
    switch (edge) {
      case 0: i = s, j = 0; break;
      case 1: i = t - 1, j = s; break;
      case 2: i = t - 1 - s, j = t - 1; break;
      default: i = 0, j = t - 1 - s; break;
    }
  } else {
    switch (edge) {
      case 0: i = s, j = 0; break;
      case 1: i = t - 1 - s, j = s; break;
      default: i = 0, j = t - 1 - s; break;
    }
  }
  return j * t + i;
}

int texel_edges(ElementType type, int t, int i, int j, int edges[2], int positions[2]) {
  int n = 0;
  auto add = [&](int k, int s) {
    if (n < 2) edges[n] = k, positions[n] = s, ++n;
  };
  if (type == ElementType::quad8) {
    if (j == 0) add(0, i);
    if (i == t - 1) add(1, j);
    if (j == t - 1) add(2, t - 1 - i);
    if (i == 0) add(3, t - 1 - j);
  } else {
    if (i + j > t - 1) return 0;
    if (j == 0) add(0, i);
    if (i + j == t - 1) add(1, j);
    if (i == 0) add(2, t - 1 - j);
  }
  return n;
}

void MeshEdgeWalls::set(int element, int edge, int s) {
  std::vector<char>& row = rows_[element];
  if (row.empty()) row.assign(4 * static_cast<std::size_t>(resolution_), 0);
  row[static_cast<std::size_t>(edge) * resolution_ + s] = 1;
}

void MeshEdgeWalls::block(int element, int edge, int s, const ElementAdjacency& adjacency) {
  set(element, edge, s);
  const auto nb = adjacency.neighbour(element, edge);
  if (nb[0] >= 0) set(nb[0], nb[1], resolution_ - 1 - s);
}

std::vector<long long> MeshEdgeWalls::keys_of_element(int element) const {
  std::vector<long long> out;
  if (const char* row = of_element(element))
    for (int k = 0; k < 4 * resolution_; ++k)
      if (row[k]) out.push_back(static_cast<long long>(element) * 4 * resolution_ + k);
  return out;
}

std::vector<char> MeshEdgeWalls::flags(int num_elements) const {
  std::vector<char> out(static_cast<size_t>(num_elements) * 4 * resolution_, 0);
  for (const auto& [element, row] : rows_)
    if (element >= 0 && element < num_elements)
      std::copy(row.begin(), row.end(), out.begin() + static_cast<std::ptrdiff_t>(element) * 4 * resolution_);
  return out;
}

namespace {

using kernels::TexelTile;

class TexelGraph {
 public:
  TexelGraph(std::vector<RegionTile>& tiles, ElementType type, const ElementAdjacency& adjacency,
             const MeshEdgeWalls& walls)
      : tiles_(tiles), type_(type) {
    t_ = tiles.front().tile.width;
    tt_ = t_ * t_;
    std::unordered_map<int, int> local;
    for (std::size_t l = 0; l < tiles.size(); ++l) {
      const TexelTile& tile = tiles[l].tile;
      if (tile.width != t_ || tile.height != t_ || tile.flags.size() != static_cast<std::size_t>(tt_) ||
          tile.values.size() != tile.flags.size())
        throw std::invalid_argument("mesh texel Laplace: every tile must be " + std::to_string(t_) + "x" +
                                    std::to_string(t_) + " with width * height flags and values");
      if (!local.emplace(tiles[l].element, static_cast<int>(l)).second)
        throw std::invalid_argument("mesh texel Laplace: element " + std::to_string(tiles[l].element) +
                                    " appears twice in the region");
    }
    if (!walls.empty() && walls.resolution() != t_)
      throw std::invalid_argument("mesh texel Laplace: the edge walls are at resolution " +
                                  std::to_string(walls.resolution()) + ", the tiles at " + std::to_string(t_));
    across_.assign(tiles.size() * 4, {-1, -1});
    blocked_.resize(tiles.size());
    for (std::size_t l = 0; l < tiles.size(); ++l) blocked_[l] = walls.of_element(tiles[l].element);
    for (std::size_t l = 0; l < tiles.size(); ++l)
      for (int k = 0; k < adjacency.edges_per_element(); ++k) {
        const auto nb = adjacency.neighbour(tiles[l].element, k);
        if (nb[0] < 0) continue;
        const auto it = local.find(nb[0]);
        if (it != local.end()) across_[4 * l + k] = {it->second, nb[1]};
      }
  }

  int nodes() const { return static_cast<int>(tiles_.size()) * tt_; }
  // Whether boundary texel s of local edge `edge` of tile l couples to the tile across it.
  bool couples_across(int l, int edge, int s) const {
    const auto nb = across_[4 * l + edge];
    return nb[0] >= 0 && !blocked(l, edge, s) && !blocked(nb[0], nb[1], t_ - 1 - s);
  }
  // The region tile across local edge `edge` of tile l and its local edge there ({-1, -1}: none).
  std::array<int, 2> across(int l, int edge) const { return across_[4 * l + edge]; }
  bool active(int node) const { return !(flags(node) & kernels::inactive); }
  double& value(int node) { return tiles_[node / tt_].tile.values[node % tt_]; }
  double value(int node) const { return tiles_[node / tt_].tile.values[node % tt_]; }

  // Whether texel (i, j) of a tile can couple across a mesh edge: the element's border
  // texels (tri6: also the hypotenuse's staircase; beyond it all texels are inactive).
  bool on_border(int i, int j) const {
    return i == 0 || j == 0 || i == t_ - 1 || j == t_ - 1 || (type_ == ElementType::tri6 && i + j >= t_ - 1);
  }
  // Calls f(neighbour node) for every active texel coupled to `node` (an active texel).
  template <class F>
  void for_each_coupling(int node, F&& f) const {
    const int l = node / tt_, t = node % tt_, i = t % t_, j = t / t_;
    const TexelTile& tile = tiles_[l].tile;
    if (kernels::texels_coupled_east(tile, i, j)) f(node + 1);
    if (i > 0 && kernels::texels_coupled_east(tile, i - 1, j)) f(node - 1);
    if (kernels::texels_coupled_north(tile, i, j)) f(node + t_);
    if (j > 0 && kernels::texels_coupled_north(tile, i, j - 1)) f(node - t_);
    if (on_border(i, j)) for_each_coupling_across(node, f);
  }

  // Calls f(v, w) for every coupling across tile l's mesh edges, v in tile l, w beyond
  // (both active), edge by edge: the same pairs as for_each_coupling_across over l's
  // border texels, without finding each texel's edges.
  template <class F>
  void for_each_coupling_across_edges(int l, F&& f) const {
    for (int k = 0; k < (type_ == ElementType::quad8 ? 4 : 3); ++k) {
      const auto nb = across_[4 * l + k];
      if (nb[0] < 0) continue;
      for (int s = 0; s < t_; ++s) {
        if (blocked(l, k, s)) continue;
        const int v = l * tt_ + edge_texel_index(type_, t_, k, s);
        const int w = nb[0] * tt_ + edge_texel_index(type_, t_, nb[1], t_ - 1 - s);
        if (active(v) && active(w)) f(v, w);
      }
    }
  }

  // Calls f(v, w) for every pair of active lattice neighbours that a wall separates: in a
  // tile (its wall bits), and across a mesh edge that a cut along it blocks (each such pair
  // twice, once from either tile).
  template <class F>
  void for_each_walled_pair(F&& f) const {
    for (int l = 0; l < static_cast<int>(tiles_.size()); ++l) {
      const std::uint8_t* flags = tiles_[l].tile.flags.data();
      for (int j = 0; j < t_; ++j)
        for (int i = 0; i < t_; ++i) {
          const int k = j * t_ + i, v = l * tt_ + k;
          if (!active(v)) continue;
          if (i + 1 < t_ && (flags[k] & kernels::wall_east) && active(v + 1)) f(v, v + 1);
          if (j + 1 < t_ && (flags[k] & kernels::wall_north) && active(v + t_)) f(v, v + t_);
        }
      for (int k = 0; k < (type_ == ElementType::quad8 ? 4 : 3); ++k) {
        const auto nb = across_[4 * l + k];
        if (nb[0] < 0) continue;
        for (int s = 0; s < t_; ++s) {
          if (!blocked(l, k, s) && !blocked(nb[0], nb[1], t_ - 1 - s)) continue;
          const int v = l * tt_ + edge_texel_index(type_, t_, k, s);
          const int w = nb[0] * tt_ + edge_texel_index(type_, t_, nb[1], t_ - 1 - s);
          if (active(v) && active(w)) f(v, w);
        }
      }
    }
  }

  // The couplings of `node` (an active texel on its tile's border) across mesh edges only.
  template <class F>
  void for_each_coupling_across(int node, F&& f) const {
    const int l = node / tt_, t = node % tt_, i = t % t_, j = t / t_;
    int edges[2], positions[2];
    const int n = texel_edges(type_, t_, i, j, edges, positions);
    for (int e = 0; e < n; ++e) {
      const auto nb = across_[4 * l + edges[e]];
      if (nb[0] < 0 || blocked(l, edges[e], positions[e])) continue;
      const int other = nb[0] * tt_ + edge_texel_index(type_, t_, nb[1], t_ - 1 - positions[e]);
      if (active(other)) f(other);
    }
  }

 private:
  std::uint8_t flags(int node) const { return tiles_[node / tt_].tile.flags[node % tt_]; }
  bool blocked(int l, int edge, int s) const { return blocked_[l] && blocked_[l][edge * t_ + s]; }

  std::vector<RegionTile>& tiles_;
  ElementType type_;
  int t_ = 0, tt_ = 0;
  std::vector<std::array<int, 2>> across_;
  std::vector<const char*> blocked_;  // per tile: its element's MeshEdgeWalls flags, or nullptr
};

// The texel Laplacian over the unknowns (node_of: unknown -> graph node, unknown_of: node
// -> unknown or -1), row by row with columns in increasing order, written straight into
// compressed rows (Eigen's inserts took ~2 ms of a 20k-unknown fracture region); b gets the
// data's share of the right side. The row arrays are freed on return, before any solve.
detail::SparseRows texel_laplacian(TexelGraph& graph, const std::vector<int>& node_of,
                                   const std::vector<int>& unknown_of, Eigen::VectorXd& b) {
  const int m = static_cast<int>(node_of.size());
  std::vector<int> offsets(m + 1, 0), columns;
  std::vector<double> values;
  columns.reserve(5 * static_cast<std::size_t>(m)), values.reserve(5 * static_cast<std::size_t>(m));
  for (int k = 0; k < m; ++k) {
    int degree = 0;
    const std::size_t row_start = columns.size();
    columns.push_back(k);
    graph.for_each_coupling(node_of[k], [&](int w) {
      ++degree;
      if (unknown_of[w] >= 0) columns.push_back(unknown_of[w]);
      else b[k] += graph.value(w);
    });
    std::sort(columns.begin() + row_start, columns.end());
    for (std::size_t e = row_start; e < columns.size(); ++e) values.push_back(columns[e] == k ? degree : -1.0);
    offsets[k + 1] = static_cast<int>(columns.size());
  }
  detail::SparseRows a(m, m);
  a.resizeNonZeros(static_cast<Eigen::Index>(columns.size()));
  std::copy(offsets.begin(), offsets.end(), a.outerIndexPtr());
  std::copy(columns.begin(), columns.end(), a.innerIndexPtr());
  std::copy(values.begin(), values.end(), a.valuePtr());
  return a;
}

// The value of each component that no data reaches (parent: flattened roots; untouched(v)
// says whether texel v is free in one), per root: such components that walls join into
// one group take the value that every texel beyond the group's walls holds, where there is
// one; NaN where those texels disagree or there are none.
// Such a component is a piece that other cuts separate from this cut's texels, and any
// constant is harmonic there. With 0 there, the cut's enriched functions
// (H - H(xi^a)) N^a were nonzero on the piece for every node of either side, copies of the
// functions of the cuts around the piece; the enrichment-mass test then found the copies
// dependent and dropped them, and with them their part next to this cut (a corner cut off
// beside a loop on a 4 x 4 plate: both pieces hung on each other, swinging 0.28 sideways).
// The one value beyond the walls is the side of this cut the piece lies on: the functions
// of the nodes on that side vanish on the piece, as with this cut alone. A group beside
// both sides keeps 0: the quadrants beyond an X's crossing, walled apart by the crack's
// other segment, would otherwise take +1 and -1 and repeat that segment's function.
template <class Untouched>
std::unordered_map<int, double> untouched_component_values(const TexelGraph& graph, const std::vector<int>& parent,
                                                           Untouched&& untouched) {
  std::unordered_map<int, int> group;  // root -> a root of its group (union-find over roots)
  auto find = [&](int root) {
    auto it = group.emplace(root, root).first;
    while (it->second != it->first) it = group.find(it->second);
    return it->first;
  };
  graph.for_each_walled_pair([&](int v, int w) {
    if (!untouched(v)) return;
    const int a = find(parent[v]);
    if (untouched(w)) {
      const int b = find(parent[w]);
      if (a != b) group[std::max(a, b)] = std::min(a, b);
    }
  });
  std::unordered_map<int, double> group_value;  // NaN once two values met
  graph.for_each_walled_pair([&](int v, int w) {
    for (int side = 0; side < 2; ++side, std::swap(v, w)) {
      if (!untouched(v) || untouched(w)) continue;
      const double beyond = graph.value(w);
      const auto [it, first] = group_value.emplace(find(parent[v]), beyond);
      if (!first && it->second != beyond) it->second = std::numeric_limits<double>::quiet_NaN();
    }
  });
  std::unordered_map<int, double> value;
  for (const auto& entry : group) {
    const auto it = group_value.find(find(entry.first));
    value[entry.first] = it == group_value.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
  }
  return value;
}

// Walls (or opens) the edge between patch texels g and q, lattice neighbours (q = g +- 1 or
// g +- width, width > 1): its bit sits on the west / south texel of the pair.
void set_wall_between(TexelTile& patch, int g, int q, bool wall) {
  const int low = std::min(g, q);
  const std::uint8_t bit = std::abs(q - g) == 1 ? kernels::wall_east : kernels::wall_north;
  if (wall) patch.flags[low] |= bit;
  else patch.flags[low] &= static_cast<std::uint8_t>(~bit);
}

// Where each solved region tile sits in one planar texel tile (quad8 only): tile l covers
// texels [T * x[l], T * (x[l] + 1)) x [T * y[l], T * (y[l] + 1)) of the patch (inside a
// one-texel margin). Frozen tiles are not placed: their texels coupled to placed tiles
// become Dirichlet "ghost" texels in the margin or gaps beside the edge they couple
// across (see solve_mesh_texel_laplace), so a ring closed only through frozen tiles (a
// cylinder with a settled element) still fits. Exact when every
// coupling of the texel graph is a 5-point coupling of the patch and vice versa: every mesh
// edge shared by two region tiles pairs edge k with edge (k + 2) % 4 (the neighbour keeps the
// orientation) and joins tiles that sit side by side across that edge; side-by-side tiles
// that are not neighbours through those edges get a wall. A region that closes up (a ring
// of elements around a cylinder) is cut open: the neighbour pairs whose tiles do not sit
// side by side become seams (tile, local edge), walled in the patch and coupled by the
// seamed solve (seamed_patch_laplace.h). Fails (returns false) for tri6, regions that turn
// (a flipped neighbour) or fall apart.
struct PatchPlacement {
  std::vector<int> x, y;
  int columns = 0, rows = 0;
  std::vector<std::array<int, 2>> seams;  // (tile, local edge); each pair listed from both sides
};

bool place_region_in_plane(const std::vector<RegionTile>& tiles, ElementType type, const ElementAdjacency& adjacency,
                           PatchPlacement& placement) {
  if (type != ElementType::quad8) return false;
  const int count = static_cast<int>(tiles.size());
  std::unordered_map<int, int> local;
  for (int l = 0; l < count; ++l)
    if (!tiles[l].frozen) local.emplace(tiles[l].element, l);
  if (local.empty()) return false;
  placement.seams.clear();
  constexpr int dx[4] = {0, 1, 0, -1}, dy[4] = {-1, 0, 1, 0};  // quad8 local edges: south, east, north, west
  std::vector<int> x(count, 0), y(count, 0);
  std::vector<char> placed(count, 0);
  int first = 0;
  while (tiles[first].frozen) ++first;
  std::vector<int> queue = {first};
  placed[first] = 1;
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const int l = queue[q];
    for (int k = 0; k < 4; ++k) {
      const auto nb = adjacency.neighbour(tiles[l].element, k);
      if (nb[0] < 0) continue;
      const auto it = local.find(nb[0]);
      if (it == local.end()) continue;
      const int m = it->second;
      if (nb[1] != (k + 2) % 4) return false;  // the neighbour is turned: no planar 5-point patch
      if (placed[m]) {
        if (x[m] != x[l] + dx[k] || y[m] != y[l] + dy[k]) placement.seams.push_back({l, k});  // closes up
        continue;
      }
      placed[m] = 1, x[m] = x[l] + dx[k], y[m] = y[l] + dy[k];
      queue.push_back(m);
    }
  }
  if (queue.size() != local.size()) return false;  // not edge-connected
  int x0 = x[first], y0 = y[first];
  for (int l : queue) x0 = std::min(x0, x[l]), y0 = std::min(y0, y[l]);
  std::unordered_map<long long, int> at;
  for (int l : queue) {
    x[l] -= x0, y[l] -= y0;
    if (!at.emplace(static_cast<long long>(x[l]) << 32 | static_cast<unsigned>(y[l]), l).second) return false;
  }
  placement.columns = 0, placement.rows = 0;
  for (int l : queue) placement.columns = std::max(placement.columns, x[l] + 1), placement.rows = std::max(placement.rows, y[l] + 1);
  placement.x = std::move(x);
  placement.y = std::move(y);
  return true;
}

// Where a tile's texels lie on one texel lattice: texel (i, j) at origin + R (i, j), R one of
// the eight symmetries of the square lattice (rotations and reflections, row-major).
struct LatticeTransform {
  std::array<int, 4> r{1, 0, 0, 1};
  int ox = 0, oy = 0;
  std::array<int, 2> turn(int di, int dj) const { return {r[0] * di + r[1] * dj, r[2] * di + r[3] * dj}; }
  std::array<int, 2> at(int i, int j) const {
    const auto d = turn(i, j);
    return {ox + d[0], oy + d[1]};
  }
  bool operator==(const LatticeTransform& o) const { return r == o.r && ox == o.ox && oy == o.oy; }
};

constexpr std::array<std::array<int, 4>, 8> kLatticeSymmetries = {{
    {1, 0, 0, 1}, {0, -1, 1, 0}, {-1, 0, 0, -1}, {0, 1, -1, 0},  // rotations by 0, 90, 180, 270 degrees
    {-1, 0, 0, 1}, {1, 0, 0, -1}, {0, 1, 1, 0}, {0, -1, -1, 0},  // reflections
}};

// The step from boundary texel s of a local edge to its partner across the edge, in the
// element's own texel frame: straight out of the edge; for the tri6 hypotenuse's staircase
// texels (T-1-s, s), east (their north neighbours then hold the partners of the next texel).
std::array<int, 2> step_across(ElementType type, int edge) {
  constexpr int quad8[4][2] = {{0, -1}, {1, 0}, {0, 1}, {-1, 0}};
  constexpr int tri6[3][2] = {{0, -1}, {1, 0}, {-1, 0}};
  const int* d = type == ElementType::quad8 ? quad8[edge] : tri6[edge];
  return {d[0], d[1]};
}

// Lays every tile of the region on one texel lattice so that each boundary texel's partner
// across a mesh edge is its lattice neighbour there: a breadth-first walk over the solved
// tiles fixes each neighbour's transform from the shared edge (its T partner texels must sit
// one step out of the edge, and its interior on the far side). Frozen tiles are placed from
// the first solved tile that meets them and not walked from (their texels only become ghost
// data beside the solved ones). The two triangles of a square-split cell
// (TriangleSplit::square) sit side by side in T x (T + 1) texels, and each row of cells one
// column on from the row below. Fails (false) where two ways round reach a solved tile with
// different transforms (a closed ring, a vertex the lattice cannot surround, the sheared
// split's hypotenuse against a leg) or the solved tiles are not edge-connected.
bool place_tiles_on_lattice(const TexelGraph& graph, const std::vector<RegionTile>& tiles, ElementType type,
                            std::vector<LatticeTransform>& placed) {
  const int count = static_cast<int>(tiles.size()), t = tiles.front().tile.width;
  const int edges = type == ElementType::quad8 ? 4 : 3;
  placed.assign(count, {});
  std::vector<char> known(count, 0);
  int first = 0;
  while (first < count && tiles[first].frozen) ++first;
  if (first == count) return false;
  known[first] = 1;
  std::vector<int> queue = {first};
  int solved = 0;
  for (const RegionTile& r : tiles) solved += !r.frozen;
  auto local = [&](int edge, int s) {
    const int k = edge_texel_index(type, t, edge, s);
    return std::array<int, 2>{k % t, k / t};
  };
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const int l = queue[q];
    const LatticeTransform& from = placed[l];
    for (int k = 0; k < edges; ++k) {
      const auto [m, km] = graph.across(l, k);
      if (m < 0) continue;
      const auto out = step_across(type, k), d = from.turn(out[0], out[1]);
      // The partner of texel s is texel T-1-s of the neighbour's edge km.
      auto target = [&](int s) {
        const auto e = local(k, s), p = from.at(e[0], e[1]);
        return std::array<int, 2>{p[0] + d[0], p[1] + d[1]};
      };
      LatticeTransform to;
      bool found = false;
      for (const auto& r : kLatticeSymmetries) {
        to.r = r;
        const auto back = step_across(type, km), db = to.turn(back[0], back[1]);
        if (db[0] != -d[0] || db[1] != -d[1]) continue;  // its interior must lie beyond the edge
        const auto e0 = local(km, t - 1), p0 = target(0), r0 = to.turn(e0[0], e0[1]);
        to.ox = p0[0] - r0[0], to.oy = p0[1] - r0[1];
        found = true;
        for (int s = 1; s < t && found; ++s) {
          const auto e = local(km, t - 1 - s);
          found = to.at(e[0], e[1]) == target(s);
        }
        if (found) break;
      }
      if (!found) return false;
      if (known[m]) {
        if (!tiles[m].frozen && !(placed[m] == to)) return false;
        continue;
      }
      known[m] = 1, placed[m] = to;
      if (!tiles[m].frozen) queue.push_back(m);
    }
  }
  return static_cast<int>(queue.size()) == solved;
}

// Solves the region's unknowns by the tile multigrid on one patch tile holding the texel
// graph exactly: the tiles laid on the lattice (place_tiles_on_lattice), every lattice pair
// walled except the couplings of the graph, a coupling that does not join lattice neighbours
// refused. Texels that are not unknowns are Dirichlet data there; frozen texels coupled to
// unknowns become Dirichlet ghost texels at their lattice places. Throws std::runtime_error
// where that fails (two texels on one place, a ghost on two values) or the multigrid does
// not converge; the caller then solves the texel graph by algebraic multigrid.
LaplaceSolveStats solve_on_lattice_patch(TexelGraph& graph, const std::vector<RegionTile>& tiles,
                                         const std::vector<LatticeTransform>& placed, const std::vector<int>& unknown_of,
                                         const LaplaceMultigridOptions& options) {
  const int t = tiles.front().tile.width, tt = t * t;
  auto lattice_point = [&](int node) {
    const int k = node % tt;
    return placed[node / tt].at(k % t, k / t);
  };
  // The patch: the solved tiles' active texels and a one-texel margin for ghosts.
  int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(), y1 = x1;
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
    if (tiles[l].frozen) continue;
    for (int i : {0, t - 1})
      for (int j : {0, t - 1}) {
        const auto p = placed[l].at(i, j);
        x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]), y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
      }
  }
  const int w = x1 - x0 + 3, h = y1 - y0 + 3;
  auto cell = [&](std::array<int, 2> p) { return (p[1] - y0 + 1) * w + (p[0] - x0 + 1); };
  // Texel (i, j) of tile l sits at patch index origin + i * di + j * dj (the transform is
  // linear): no division per texel.
  struct TileCells {
    int origin = 0, di = 0, dj = 0;
  };
  std::vector<TileCells> cells(tiles.size());
  for (std::size_t l = 0; l < tiles.size(); ++l) {
    const LatticeTransform& p = placed[l];
    cells[l] = {cell({p.ox, p.oy}), p.r[0] + p.r[2] * w, p.r[1] + p.r[3] * w};
  }
  TexelTile patch(w, h);
  std::fill(patch.flags.begin(), patch.flags.end(), static_cast<std::uint8_t>(kernels::inactive));
  constexpr int empty = -1, ghost = -2;
  std::vector<int> occupant(patch.flags.size(), empty);
  constexpr std::uint8_t walled = kernels::wall_east | kernels::wall_north;
  // Calls f(l, i, j, v, g) for texel (i, j) of every solved tile l: graph node v, patch index g.
  auto for_each_solved_texel = [&](auto&& f) {
    for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
      if (tiles[l].frozen) continue;
      const TileCells c = cells[l];
      for (int j = 0; j < t; ++j)
        for (int i = 0; i < t; ++i) f(l, i, j, l * tt + j * t + i, c.origin + i * c.di + j * c.dj);
    }
  };
  for_each_solved_texel([&](int, int, int, int v, int g) {
    if (!graph.active(v)) return;
    if (occupant[g] != empty) throw std::runtime_error("two texels on one lattice place");
    occupant[g] = v;
    patch.flags[g] = walled | (unknown_of[v] < 0 ? kernels::dirichlet : 0);
    patch.values[g] = graph.value(v);  // data, or the initial guess (the previous H)
  });
  // Open the couplings of the unknowns (data-data pairs stay walled: they do not enter the
  // equations). Within a tile a coupling is a lattice step by construction; one across a
  // mesh edge is checked, and a frozen partner becomes a ghost.
  for_each_solved_texel([&](int l, int i, int j, int v, int g) {
    if (unknown_of[v] < 0) return;
    const TexelTile& tile = tiles[l].tile;
    const TileCells c = cells[l];
    if (kernels::texels_coupled_east(tile, i, j)) set_wall_between(patch, g, g + c.di, false);
    if (i > 0 && kernels::texels_coupled_east(tile, i - 1, j)) set_wall_between(patch, g, g - c.di, false);
    if (kernels::texels_coupled_north(tile, i, j)) set_wall_between(patch, g, g + c.dj, false);
    if (j > 0 && kernels::texels_coupled_north(tile, i, j - 1)) set_wall_between(patch, g, g - c.dj, false);
    if (!graph.on_border(i, j)) return;
    const auto p = placed[l].at(i, j);
    graph.for_each_coupling_across(v, [&](int u) {
      const auto q = lattice_point(u);
      const int dx = q[0] - p[0], dy = q[1] - p[1];
      if (std::abs(dx) + std::abs(dy) != 1) throw std::runtime_error("a coupling off the lattice");
      const int k = cell(q);
      if (tiles[u / tt].frozen) {
        const double value = graph.value(u);
        if (occupant[k] >= 0 || (occupant[k] == ghost && patch.values[k] != value))
          throw std::runtime_error("a ghost texel on a taken lattice place");
        if (occupant[k] == empty)
          occupant[k] = ghost, patch.flags[k] = walled | kernels::dirichlet, patch.values[k] = value;
      }
      set_wall_between(patch, g, k, false);
    });
  });
  const LaplaceSolveStats s = solve_laplace(patch, LaplaceSolver::multigrid, options);
  for_each_solved_texel([&](int, int, int, int v, int g) {
    if (unknown_of[v] >= 0) graph.value(v) = patch.values[g];
  });
  return s;
}

// The reference solve of a texel Laplacian (full rows) and the safety net of the
// multigrids: CHOLMOD, simplicial (no BLAS: Debian's serial OpenBLAS is not safe for
// concurrent calls) with AMD alone (METIS draws from a global random generator): lock-free
// and the same bits on any thread. The texel graphs of a few tri6 elements (fracture:
// 6k-20k unknowns) factor 2-4x faster simplicial than supernodal here, and AMD was
// CHOLMOD's own pick.
Eigen::VectorXd solve_by_cholmod(const detail::SparseRows& a, const Eigen::VectorXd& b, std::size_t elements,
                                 double& relative_residual) {
  const Eigen::SparseMatrix<double> lower = a.triangularView<Eigen::Lower>();
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky;
  cholmod_common& common = cholesky.cholmod();
  common.supernodal = CHOLMOD_SIMPLICIAL;
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_AMD;
  common.postorder = 1;
  cholesky.compute(lower);
  const auto m = std::to_string(a.rows());
  if (cholesky.info() != Eigen::Success)
    throw std::runtime_error("enrichment Laplace solve: CHOLMOD could not factor the " + m +
                             "-unknown texel Laplacian over " + std::to_string(elements) +
                             " elements (not positive definite or out of memory)");
  Eigen::VectorXd x = cholesky.solve(b);
  if (cholesky.info() != Eigen::Success || !x.allFinite())
    throw std::runtime_error("enrichment Laplace solve: CHOLMOD solve failed for " + m + " unknowns");
  relative_residual = b.norm() > 0 ? (b - a * x).norm() / b.norm() : 0.0;
  return x;
}

}  // namespace

std::vector<int> stale_frozen_tiles(std::vector<RegionTile>& tiles, ElementType type, const ElementAdjacency& adjacency,
                                    const MeshEdgeWalls& edge_walls) {
  std::vector<int> stale;
  if (std::none_of(tiles.begin(), tiles.end(), [](const RegionTile& r) { return r.frozen; })) return stale;
  TexelGraph graph(tiles, type, adjacency, edge_walls);
  const int n = graph.nodes(), tt = tiles.front().tile.width * tiles.front().tile.width;
  auto is_data = [&](int v) { return (tiles[v / tt].tile.flags[v % tt] & kernels::dirichlet) != 0; };
  auto is_free = [&](int v) { return graph.active(v) && !is_data(v); };
  // Components of the free texels, frozen tiles' included: within each tile in texel order
  // (west and south neighbours), then across mesh edges (parent[v] <= v: one forward pass
  // flattens them).
  const int t = tiles.front().tile.width;
  std::vector<int> parent(n);
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
    const std::uint8_t* flags = tiles[l].tile.flags.data();
    for (int k = 0; k < tt; ++k) {
      const int v = l * tt + k, i = k % t, j = k / t;
      parent[v] = v;
      if (!is_free(v)) continue;
      if (i > 0 && is_free(v - 1) && !(flags[k - 1] & kernels::wall_east)) kernels::unite_smaller_root(parent, v, v - 1);
      if (j > 0 && is_free(v - t) && !(flags[k - t] & kernels::wall_north)) kernels::unite_smaller_root(parent, v, v - t);
    }
  }
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l)
    graph.for_each_coupling_across_edges(l, [&](int v, int w) {
      if (is_free(v) && is_free(w)) kernels::unite_smaller_root(parent, v, w);
    });
  for (int v = 0; v < n; ++v) parent[v] = parent[parent[v]];
  enum : std::uint8_t { no_data = 0, constant = 1, varying = 2 };
  std::vector<std::uint8_t> state(n, no_data);
  std::vector<double> constant_value(n, 0.0);
  for (int d = 0; d < n; ++d)
    if (graph.active(d) && is_data(d))
      graph.for_each_coupling(d, [&](int w) {
        if (!is_free(w)) return;
        const int root = parent[w];
        const double x = graph.value(d);
        if (state[root] == no_data) state[root] = constant, constant_value[root] = x;
        else if (state[root] == constant && x != constant_value[root]) state[root] = varying;
      });
  // A component without data holds the value beyond its walls, as the solve gives it.
  auto untouched = [&](int v) { return is_free(v) && state[parent[v]] == no_data; };
  for (const auto& [root, value] : untouched_component_values(graph, parent, untouched))
    if (!std::isnan(value)) constant_value[root] = value;
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
    if (!tiles[l].frozen) continue;
    for (int v = l * tt; v < (l + 1) * tt; ++v)
      if (is_free(v) && state[parent[v]] != varying && graph.value(v) != constant_value[parent[v]]) {
        stale.push_back(l);
        break;
      }
  }
  return stale;
}

MeshLaplaceStats solve_mesh_texel_laplace(std::vector<RegionTile>& tiles, ElementType type,
                                          const ElementAdjacency& adjacency, const MeshEdgeWalls& edge_walls,
                                          LaplaceSolver solver, const LaplaceMultigridOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MeshLaplaceStats stats;
  if (tiles.empty()) return stats;
  TexelGraph graph(tiles, type, adjacency, edge_walls);
  for (const RegionTile& r : tiles) (r.frozen ? stats.frozen_tiles : stats.solved_tiles) += 1;
  const int n = graph.nodes();

  // Components of free texels; each collects the data values it touches. Union-find
  // links the larger root under the smaller, so parent[v] <= v and one forward pass
  // flattens every texel to its root.
  const int t = tiles.front().tile.width, tt = t * t;
  std::vector<char> is_free(n), is_data(n), is_uncut(tiles.size(), 0);
  // Per unfrozen tile, its data (Dirichlet) texels in texel order: the data its free texels
  // meet is found from these few (a cut's raster) instead of from every free texel.
  std::vector<std::vector<int>> dirichlet_texels(tiles.size());
  // An uncut element's flags: only its shape's inactive texels (no walls, no data).
  std::vector<std::uint8_t> uncut(tt, 0);
  if (type == ElementType::tri6)
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i)
        if (!kernels::is_tri6_texel_active(i, j, t)) uncut[j * t + i] = kernels::inactive;
  // Data: active texels of frozen tiles and Dirichlet texels; free: the other active ones.
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
    const std::uint8_t* flags = tiles[l].tile.flags.data();
    const bool frozen = tiles[l].frozen;
    is_uncut[l] = !frozen && tiles[l].tile.flags == uncut;
    char* free_texel = is_free.data() + static_cast<std::size_t>(l) * tt;
    char* data_texel = is_data.data() + static_cast<std::size_t>(l) * tt;
    for (int k = 0; k < tt; ++k) {
      const bool active = !(flags[k] & kernels::inactive);
      const bool data = active && (frozen || (flags[k] & kernels::dirichlet));
      data_texel[k] = data;
      free_texel[k] = active && !data;
    }
    if (!frozen)  // a frozen tile has no free texels to meet its data
      for (int k = 0; k < tt; ++k)
        if (data_texel[k]) dirichlet_texels[l].push_back(k);
  }
  std::vector<int> parent(n);
  // The in-tile sets of an uncut tile, relative to its first texel: every uncut tile has the
  // same flags and free texels, so the first one labelled is copied to the others (most of
  // a region's tiles away from the cut; fracture: 148 in one region).
  std::vector<int> uncut_sets;
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
    const int base = l * tt;
    if (is_uncut[l] && !uncut_sets.empty()) {
      for (int k = 0; k < tt; ++k) parent[base + k] = base + uncut_sets[k];
      continue;
    }
    // Within the tile, in texel order: a free texel joins its west or south neighbour's set
    // by pointing where that neighbour points (an earlier texel, so parent[v] < v), and only
    // where both neighbours are coupled are two sets united (one find each, most texels
    // none). The same sets and roots as uniting every coupling, in half the time (chad).
    const std::uint8_t* flags = tiles[l].tile.flags.data();
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        const int k = j * t + i, v = base + k;
        parent[v] = v;
        if (!is_free[v]) continue;
        const bool west = i > 0 && is_free[v - 1] && !(flags[k - 1] & kernels::wall_east);
        const bool south = j > 0 && is_free[v - t] && !(flags[k - t] & kernels::wall_north);
        if (west) parent[v] = parent[v - 1];
        else if (south) parent[v] = parent[v - t];
        if (west && south && parent[v - 1] != parent[v - t]) kernels::unite_smaller_root(parent, v - 1, v - t);
      }
    if (is_uncut[l]) {
      uncut_sets.resize(tt);
      for (int k = 0; k < tt; ++k) uncut_sets[k] = parent[base + k] - base;
    }
  }
  // Couplings across mesh edges, one shared edge at a time.
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l)
    graph.for_each_coupling_across_edges(l, [&](int v, int w) {
      if (is_free[v] && is_free[w]) kernels::unite_smaller_root(parent, v, w);
    });
  for (int v = 0; v < n; ++v) parent[v] = parent[parent[v]];
  enum : std::uint8_t { no_data = 0, constant = 1, varying = 2 };
  std::vector<std::uint8_t> state(n, no_data);
  // Read only where state is constant, which the write of the value comes with: no zero-fill.
  const std::unique_ptr<double[]> constant_value(new double[n]);
  // (The order in which a component meets its data does not matter: it ends constant
  // with the one value it met, or varying.)
  auto meet = [&](int root, double x) {
    if (state[root] == no_data) state[root] = constant, constant_value[root] = x;
    else if (state[root] == constant && x != constant_value[root]) state[root] = varying;
  };
  for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
    graph.for_each_coupling_across_edges(l, [&](int v, int w) {
      if (is_free[v] && is_data[w]) meet(parent[v], graph.value(w));
    });
    // Free neighbours in the tile of each data texel (free implies active).
    const std::uint8_t* flags = tiles[l].tile.flags.data();
    const double* values = tiles[l].tile.values.data();
    for (const int k : dirichlet_texels[l]) {
      const int i = k % t, j = k / t, v = l * tt + k;
      if (i + 1 < t && is_free[v + 1] && !(flags[k] & kernels::wall_east)) meet(parent[v + 1], values[k]);
      if (i > 0 && is_free[v - 1] && !(flags[k - 1] & kernels::wall_east)) meet(parent[v - 1], values[k]);
      if (j + 1 < t && is_free[v + t] && !(flags[k] & kernels::wall_north)) meet(parent[v + t], values[k]);
      if (j > 0 && is_free[v - t] && !(flags[k - t] & kernels::wall_north)) meet(parent[v - t], values[k]);
    }
  }
  // node -> unknown or -1; allocated with the first unknown (a settled region, like
  // fracture's 148 uncut tiles, touches none of its pages: they cost ~2.5 us each fresh).
  std::vector<int> unknown_of;
  std::vector<int> node_of;
  node_of.reserve(n);
  bool any_untouched = false;  // a component without data (its value is set after the solve)
  for (int v = 0; v < n; ++v) {
    if (!is_free[v]) continue;
    const int root = parent[v];
    if (root == v) {
      stats.constant_components += state[v] == constant;
      stats.solved_components += state[v] == varying;
    }
    if (state[root] == varying) {
      if (unknown_of.empty()) unknown_of.assign(n, -1);
      unknown_of[v] = static_cast<int>(node_of.size());
      node_of.push_back(v);
    } else {
      graph.value(v) = state[root] == constant ? constant_value[root] : 0.0;
      any_untouched |= state[root] == no_data;
    }
  }
  stats.unknowns = static_cast<int>(node_of.size());

  if (!node_of.empty()) {
    // The multigrid where the region allows it; CHOLMOD otherwise, and as the safety net
    // should the multigrid not reach its tolerance (it throws std::runtime_error then).
    PatchPlacement placement;
    if (solver == LaplaceSolver::multigrid && tiles.size() > 1 &&
        place_region_in_plane(tiles, type, adjacency, placement)) {
      try {
        // The solved tiles form a planar block: one patch tile, the tile multigrid, the same
        // discrete problem (every texel-graph coupling is a 5-point coupling there, or a seam
        // coupling of a ring cut open).
        // A one-texel margin for the ghosts, only where frozen tiles are (else the patch is
        // exactly the block of tiles, the multigrid's coarse grids aligned with them).
        const int margin = stats.frozen_tiles > 0 ? 1 : 0;
        const int w = t * placement.columns + 2 * margin, h = t * placement.rows + 2 * margin;
        TexelTile patch(w, h);
        std::fill(patch.flags.begin(), patch.flags.end(), static_cast<std::uint8_t>(kernels::inactive));
        auto patch_index = [&](int l, int i, int j) {
          return (margin + t * placement.y[l] + j) * w + margin + t * placement.x[l] + i;
        };
        std::vector<char> in_tile(patch.flags.size(), 0);
        std::vector<std::uint8_t> seam_edges(tiles.size(), 0);  // bit k: local edge k is a seam
        for (const auto& [l, k] : placement.seams) seam_edges[l] |= static_cast<std::uint8_t>(1u << k);
        // Rows in parallel: each writes its own patch texels.
        kernels::forall(static_cast<std::int64_t>(tiles.size()) * t, [&](std::int64_t row) {
          const int l = static_cast<int>(row / t), j = static_cast<int>(row % t);
          if (tiles[l].frozen) return;
          const std::uint8_t* flags = tiles[l].tile.flags.data() + j * t;
          const double* values = tiles[l].tile.values.data() + j * t;
          const int* unknown = unknown_of.data() + l * tt + j * t;
          const int row_start = patch_index(l, 0, j);
          std::fill(in_tile.begin() + row_start, in_tile.begin() + row_start + t, 1);
          for (int i = 0; i < t; ++i) {
            if (flags[i] & kernels::inactive) continue;
            const int g = row_start + i;
            std::uint8_t f = flags[i] & (kernels::wall_east | kernels::wall_north);
            // Seam edges are walls in the patch (the seamed solve couples them).
            if (i == t - 1)
              f = (f & ~kernels::wall_east) |
                  (graph.couples_across(l, 1, j) && !(seam_edges[l] & 2u) ? 0 : kernels::wall_east);
            if (j == t - 1)
              f = (f & ~kernels::wall_north) |
                  (graph.couples_across(l, 2, t - 1 - i) && !(seam_edges[l] & 4u) ? 0 : kernels::wall_north);
            if (unknown[i] < 0) f |= kernels::dirichlet;
            patch.flags[g] = f;
            patch.values[g] = values[i];  // data, or the initial guess (the previous H)
          }
        });
        // Ghost texels: the frozen texel coupled across a placed tile's edge, as Dirichlet
        // data right beside that edge. Each ghost couples only to its partner(s): walls
        // toward every other neighbour. A ghost that would land in a placed tile, or two
        // different frozen values on one ghost, leave the region to CHOLMOD.
        constexpr int gx[4] = {0, 1, 0, -1}, gy[4] = {-1, 0, 1, 0};  // outward, per quad8 edge
        std::unordered_map<int, std::uint8_t> ghost_partners;  // ghost -> bit d: couples toward direction d
        bool ghosts_fit = true;
        for (int l = 0; l < static_cast<int>(tiles.size()) && ghosts_fit; ++l) {
          if (tiles[l].frozen) continue;
          for (int k = 0; k < 4 && ghosts_fit; ++k) {
            const auto nb = graph.across(l, k);
            if (nb[0] < 0 || !tiles[nb[0]].frozen) continue;
            for (int q = 0; q < t; ++q) {
              if (!graph.couples_across(l, k, q)) continue;
              const int v = l * tt + edge_texel_index(type, t, k, q);
              const int other = nb[0] * tt + edge_texel_index(type, t, nb[1], t - 1 - q);
              if (!graph.active(v) || !graph.active(other)) continue;
              const int i = v % tt % t, j = v % tt / t;
              const int gi = margin + t * placement.x[l] + i + gx[k], gj = margin + t * placement.y[l] + j + gy[k];
              if (gi < 0 || gj < 0 || gi >= w || gj >= h) {
                ghosts_fit = false;
                break;
              }
              const int g = gj * w + gi;
              if (in_tile[g]) {
                ghosts_fit = false;
                break;
              }
              const double value = graph.value(other);
              const auto it = ghost_partners.find(g);
              if (it != ghost_partners.end() && patch.values[g] != value) {
                ghosts_fit = false;
                break;
              }
              patch.flags[g] = kernels::dirichlet;
              patch.values[g] = value;
              ghost_partners[g] |= static_cast<std::uint8_t>(1u << ((k + 2) % 4));  // toward the tile
            }
          }
        }
        if (!ghosts_fit) throw std::runtime_error("ghost texels do not fit the patch");
        for (const auto& [g, partners] : ghost_partners) {
          const int gi = g % w, gj = g / w;
          const int neighbour[4] = {g - w, g + 1, g + w, g - 1};  // south, east, north, west
          const bool inside[4] = {gj > 0, gi + 1 < w, gj + 1 < h, gi > 0};
          for (int d = 0; d < 4; ++d)
            if (!(partners & (1u << d)) && inside[d]) set_wall_between(patch, g, neighbour[d], true);
        }
        // Seam couplings: texel pairs across each seam edge (listed once, from the lower tile).
        std::vector<detail::SeamCoupling> seams;
        for (const auto& [l, k] : placement.seams) {
          const auto nb = graph.across(l, k);
          if (nb[0] < l) continue;
          for (int q = 0; q < t; ++q) {
            if (!graph.couples_across(l, k, q)) continue;
            const int v = l * tt + edge_texel_index(type, t, k, q);
            const int other = nb[0] * tt + edge_texel_index(type, t, nb[1], t - 1 - q);
            if (!graph.active(v) || !graph.active(other) || (unknown_of[v] < 0 && unknown_of[other] < 0)) continue;
            seams.push_back({patch_index(l, v % tt % t, v % tt / t), patch_index(nb[0], other % tt % t, other % tt / t)});
          }
        }
        const LaplaceSolveStats s = seams.empty() ? solve_laplace(patch, LaplaceSolver::multigrid, options)
                                                  : detail::solve_seamed_patch_laplace(patch, seams, options);
        stats.relative_residual = s.relative_residual;
        stats.multigrid = true;
        kernels::forall(static_cast<std::int64_t>(tiles.size()) * t, [&](std::int64_t row) {
          const int l = static_cast<int>(row / t), j = static_cast<int>(row % t);
          if (tiles[l].frozen) return;
          const int first = l * tt + j * t, g = patch_index(l, 0, j);
          for (int i = 0; i < t; ++i)
            if (unknown_of[first + i] >= 0) tiles[l].tile.values[j * t + i] = patch.values[g + i];
        });
      } catch (const std::runtime_error&) {
        stats.multigrid = false;
      }
    } else if (std::vector<LatticeTransform> lattice; solver == LaplaceSolver::multigrid && tiles.size() > 1 &&
                                                      place_tiles_on_lattice(graph, tiles, type, lattice)) {
      // Regions the block placement refuses (tri6, turned neighbours) may still lie on one
      // texel lattice, texel by texel.
      try {
        const LaplaceSolveStats s = solve_on_lattice_patch(graph, tiles, lattice, unknown_of, options);
        stats.relative_residual = s.relative_residual;
        stats.multigrid = true;
      } catch (const std::runtime_error&) {
        stats.multigrid = false;
      }
    } else if (solver == LaplaceSolver::multigrid && tiles.size() == 1) {
      // One tile, no neighbours: the tile multigrid on the tile itself (no copy), with the
      // settled texels (their values set above) marked as data while it runs (unmarked on
      // every way out, an exception too). The multigrid writes only the unknowns; should it
      // fail, CHOLMOD below writes them all.
      struct SettledAsData {
        TexelTile& tile;
        std::vector<int> texels;
        ~SettledAsData() {
          for (int v : texels) tile.flags[v] &= static_cast<std::uint8_t>(~kernels::dirichlet);
        }
      } settled{tiles.front().tile, {}};
      for (int v = 0; v < n; ++v)
        if (is_free[v] && unknown_of[v] < 0) settled.texels.push_back(v), settled.tile.flags[v] |= kernels::dirichlet;
      try {
        const LaplaceSolveStats s = solve_laplace(settled.tile, LaplaceSolver::multigrid, options);
        stats.relative_residual = s.relative_residual;
        stats.multigrid = true;
      } catch (const std::runtime_error&) {
        stats.multigrid = false;
      }
    }
    if (!stats.multigrid) {
      const int m = stats.unknowns;
      Eigen::VectorXd b = Eigen::VectorXd::Zero(m);
      const detail::SparseRows a = texel_laplacian(graph, node_of, unknown_of, b);
      if (solver == LaplaceSolver::multigrid) {
        // No planar patch holds the region (tri6, turned neighbours) or its multigrid did not
        // converge: algebraic multigrid on the texel graph, warm-started like the tile's.
        try {
          Eigen::VectorXd x(m);
          for (int k = 0; k < m; ++k) x[k] = options.warm_start ? graph.value(node_of[k]) : 0.0;
          const detail::GraphAmgStats s =
              detail::solve_graph_laplacian_amg(a, b, x, options.tolerance, options.max_cycles);
          for (int k = 0; k < m; ++k) graph.value(node_of[k]) = x[k];
          stats.relative_residual = s.relative_residual;
          stats.multigrid = stats.algebraic_multigrid = true;
        } catch (const std::runtime_error&) {
          // not converged: CHOLMOD below
        }
      }
      if (!stats.multigrid) {
        const Eigen::VectorXd x = solve_by_cholmod(a, b, tiles.size(), stats.relative_residual);
        for (int k = 0; k < m; ++k) graph.value(node_of[k]) = x[k];
      }
    }
  }
  if (any_untouched) {  // after the solve: the texels beyond their walls have their values
    auto untouched = [&](int v) { return is_free[v] && state[parent[v]] == no_data; };
    const std::unordered_map<int, double> values = untouched_component_values(graph, parent, untouched);
    for (int v = 0; v < n; ++v) {
      if (!untouched(v)) continue;
      const auto it = values.find(parent[v]);
      if (it != values.end() && !std::isnan(it->second)) graph.value(v) = it->second;
    }
  }
  stats.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace dgtex

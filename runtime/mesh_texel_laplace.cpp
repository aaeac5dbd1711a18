#include "dgtex/mesh_texel_laplace.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include "dgtex/kernels/multigrid_unknowns.h"

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

void MeshEdgeWalls::block(int element, int edge, int s, const ElementAdjacency& adjacency) {
  keys_.insert(key(element, edge, s));
  const auto nb = adjacency.neighbour(element, edge);
  if (nb[0] >= 0) keys_.insert(key(nb[0], nb[1], resolution_ - 1 - s));
}

std::vector<long long> MeshEdgeWalls::keys_of_element(int element) const {
  std::vector<long long> out;
  for (int k = 0; k < 4; ++k)
    for (int s = 0; s < resolution_; ++s)
      if (blocked(element, k, s)) out.push_back(key(element, k, s));
  return out;
}

std::vector<char> MeshEdgeWalls::flags(int num_elements) const {
  std::vector<char> out(static_cast<size_t>(num_elements) * 4 * resolution_, 0);
  for (long long k : keys_)
    if (k >= 0 && k < static_cast<long long>(out.size())) out[static_cast<size_t>(k)] = 1;
  return out;
}

namespace {

using kernels::TexelTile;

class TexelGraph {
 public:
  TexelGraph(std::vector<RegionTile>& tiles, ElementType type, const ElementAdjacency& adjacency,
             const MeshEdgeWalls& walls)
      : tiles_(tiles), type_(type), walls_(walls) {
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
    across_.assign(tiles.size() * 4, {-1, -1});
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
    return nb[0] >= 0 && !walls_.blocked(tiles_[l].element, edge, s) &&
           !walls_.blocked(tiles_[nb[0]].element, nb[1], t_ - 1 - s);
  }
  bool active(int node) const { return !(flags(node) & kernels::inactive); }
  bool data(int node) const {
    return active(node) && (tiles_[node / tt_].frozen || (flags(node) & kernels::dirichlet));
  }
  bool free(int node) const { return active(node) && !data(node); }
  double& value(int node) { return tiles_[node / tt_].tile.values[node % tt_]; }

  // Calls f(neighbour node) for every active texel coupled to `node` (an active texel).
  template <class F>
  void for_each_coupling(int node, F&& f) const {
    const int l = node / tt_, t = node % tt_, i = t % t_, j = t / t_;
    const TexelTile& tile = tiles_[l].tile;
    if (kernels::texels_coupled_east(tile, i, j)) f(node + 1);
    if (i > 0 && kernels::texels_coupled_east(tile, i - 1, j)) f(node - 1);
    if (kernels::texels_coupled_north(tile, i, j)) f(node + t_);
    if (j > 0 && kernels::texels_coupled_north(tile, i, j - 1)) f(node - t_);
    int edges[2], positions[2];
    const int n = texel_edges(type_, t_, i, j, edges, positions);
    for (int e = 0; e < n; ++e) {
      const auto nb = across_[4 * l + edges[e]];
      if (nb[0] < 0 || walls_.blocked(tiles_[l].element, edges[e], positions[e])) continue;
      const int other = nb[0] * tt_ + edge_texel_index(type_, t_, nb[1], t_ - 1 - positions[e]);
      if (active(other)) f(other);
    }
  }

 private:
  std::uint8_t flags(int node) const { return tiles_[node / tt_].tile.flags[node % tt_]; }

  std::vector<RegionTile>& tiles_;
  ElementType type_;
  const MeshEdgeWalls& walls_;
  int t_ = 0, tt_ = 0;
  std::vector<std::array<int, 2>> across_;
};

// Where each region tile sits in one planar texel tile (quad8 only): tile l covers texels
// [T * x[l], T * (x[l] + 1)) x [T * y[l], T * (y[l] + 1)) of the patch. Exact when every
// coupling of the texel graph is a 5-point coupling of the patch and vice versa: every mesh
// edge shared by two region tiles pairs edge k with edge (k + 2) % 4 (the neighbour keeps the
// orientation) and joins tiles that sit side by side across that edge; side-by-side tiles
// that are not neighbours through those edges get a wall. Fails (returns false) for tri6,
// regions that turn (a flipped neighbour), close up (a cylinder ring) or fall apart.
struct PatchPlacement {
  std::vector<int> x, y;
  int columns = 0, rows = 0;
};

bool place_region_in_plane(const std::vector<RegionTile>& tiles, ElementType type, const ElementAdjacency& adjacency,
                           PatchPlacement& placement) {
  if (type != ElementType::quad8) return false;
  const int count = static_cast<int>(tiles.size());
  std::unordered_map<int, int> local;
  for (int l = 0; l < count; ++l) local.emplace(tiles[l].element, l);
  constexpr int dx[4] = {0, 1, 0, -1}, dy[4] = {-1, 0, 1, 0};  // quad8 local edges: south, east, north, west
  std::vector<int> x(count, 0), y(count, 0);
  std::vector<char> placed(count, 0);
  std::vector<int> queue = {0};
  placed[0] = 1;
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
        if (x[m] != x[l] + dx[k] || y[m] != y[l] + dy[k]) return false;  // the region closes up
        continue;
      }
      placed[m] = 1, x[m] = x[l] + dx[k], y[m] = y[l] + dy[k];
      queue.push_back(m);
    }
  }
  if (static_cast<int>(queue.size()) != count) return false;  // not edge-connected
  const int x0 = *std::min_element(x.begin(), x.end()), y0 = *std::min_element(y.begin(), y.end());
  std::unordered_map<long long, int> at;
  for (int l = 0; l < count; ++l) {
    x[l] -= x0, y[l] -= y0;
    if (!at.emplace(static_cast<long long>(x[l]) << 32 | static_cast<unsigned>(y[l]), l).second) return false;
  }
  placement.columns = *std::max_element(x.begin(), x.end()) + 1;
  placement.rows = *std::max_element(y.begin(), y.end()) + 1;
  placement.x = std::move(x);
  placement.y = std::move(y);
  return true;
}

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

MeshLaplaceStats solve_mesh_texel_laplace(std::vector<RegionTile>& tiles, ElementType type,
                                          const ElementAdjacency& adjacency, const MeshEdgeWalls& edge_walls,
                                          LaplaceSolver solver, const LaplaceMultigridOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MeshLaplaceStats stats;
  if (tiles.empty()) return stats;
  TexelGraph graph(tiles, type, adjacency, edge_walls);
  for (const RegionTile& r : tiles) (r.frozen ? stats.frozen_tiles : stats.solved_tiles) += 1;
  const int n = graph.nodes();

  // Components of free texels; each collects the data values it touches.
  std::vector<int> parent(n);
  for (int v = 0; v < n; ++v) parent[v] = v;
  for (int v = 0; v < n; ++v) {
    if (!graph.free(v)) continue;
    graph.for_each_coupling(v, [&](int w) {
      if (w > v && graph.free(w)) {
        const int a = find_root(parent, v), b = find_root(parent, w);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    });
  }
  enum : std::uint8_t { no_data = 0, constant = 1, varying = 2 };
  std::vector<std::uint8_t> state(n, no_data);
  std::vector<double> constant_value(n, 0.0);
  for (int v = 0; v < n; ++v) {
    if (!graph.free(v)) continue;
    const int root = find_root(parent, v);
    graph.for_each_coupling(v, [&](int w) {
      if (!graph.data(w)) return;
      const double x = graph.value(w);
      if (state[root] == no_data) state[root] = constant, constant_value[root] = x;
      else if (state[root] == constant && x != constant_value[root]) state[root] = varying;
    });
  }
  std::vector<int> unknown_of(n, -1);
  std::vector<int> node_of;
  for (int v = 0; v < n; ++v) {
    if (!graph.free(v)) continue;
    const int root = find_root(parent, v);
    if (root == v) {
      stats.constant_components += state[v] == constant;
      stats.solved_components += state[v] == varying;
    }
    if (state[root] == varying) {
      unknown_of[v] = static_cast<int>(node_of.size());
      node_of.push_back(v);
    } else {
      graph.value(v) = state[root] == constant ? constant_value[root] : 0.0;
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
        // The region is a planar block of tiles: one patch tile, the tile multigrid, the
        // same discrete problem (every texel-graph coupling is a 5-point coupling there).
        const int t = tiles.front().tile.width, tt = t * t, w = t * placement.columns;
        TexelTile patch(w, t * placement.rows);
        std::fill(patch.flags.begin(), patch.flags.end(), static_cast<std::uint8_t>(kernels::inactive));
        auto patch_index = [&](int l, int i, int j) { return (t * placement.y[l] + j) * w + t * placement.x[l] + i; };
        for (int l = 0; l < static_cast<int>(tiles.size()); ++l) {
          const std::vector<std::uint8_t>& flags = tiles[l].tile.flags;
          for (int j = 0; j < t; ++j)
            for (int i = 0; i < t; ++i) {
              const int v = l * tt + j * t + i;
              if (!graph.active(v)) continue;
              std::uint8_t f = flags[j * t + i] & (kernels::wall_east | kernels::wall_north);
              if (i == t - 1) f = (f & ~kernels::wall_east) | (graph.couples_across(l, 1, j) ? 0 : kernels::wall_east);
              if (j == t - 1)
                f = (f & ~kernels::wall_north) | (graph.couples_across(l, 2, t - 1 - i) ? 0 : kernels::wall_north);
              if (unknown_of[v] < 0) f |= kernels::dirichlet;
              const int g = patch_index(l, i, j);
              patch.flags[g] = f;
              patch.values[g] = graph.value(v);  // data, or the initial guess (the previous H)
            }
        }
        const LaplaceSolveStats s = solve_laplace(patch, LaplaceSolver::multigrid, options);
        stats.relative_residual = s.relative_residual;
        stats.multigrid = true;
        for (int v : node_of) graph.value(v) = patch.values[patch_index(v / tt, v % tt % t, v % tt / t)];
      } catch (const std::runtime_error&) {
        stats.multigrid = false;
      }
    } else if (solver == LaplaceSolver::multigrid && tiles.size() == 1) {
      try {
        // One tile, no neighbours: the tile multigrid, with the settled texels as data.
        TexelTile tile = tiles.front().tile;
        for (int v = 0; v < n; ++v)
          if (graph.free(v) && unknown_of[v] < 0) tile.flags[v] |= kernels::dirichlet, tile.values[v] = graph.value(v);
        const LaplaceSolveStats s = solve_laplace(tile, LaplaceSolver::multigrid, options);
        stats.relative_residual = s.relative_residual;
        stats.multigrid = true;
        for (int v : node_of) graph.value(v) = tile.values[v];
      } catch (const std::runtime_error&) {
        stats.multigrid = false;
      }
    }
    if (!stats.multigrid) {
      // Lower triangle, column by column (rows in increasing order: cheap inserts).
      const int m = stats.unknowns;
      Eigen::SparseMatrix<double> a(m, m);
      a.reserve(Eigen::VectorXi::Constant(m, 5));
      Eigen::VectorXd b = Eigen::VectorXd::Zero(m);
      std::vector<int> rows;
      for (int k = 0; k < m; ++k) {
        const int v = node_of[k];
        int degree = 0;
        rows.clear();
        graph.for_each_coupling(v, [&](int w) {
          ++degree;
          if (unknown_of[w] > k) rows.push_back(unknown_of[w]);
          else if (unknown_of[w] < 0) b[k] += graph.value(w);
        });
        std::sort(rows.begin(), rows.end());
        a.insert(k, k) = static_cast<double>(degree);
        for (int r : rows) a.insert(r, k) = -1.0;
      }
      a.makeCompressed();
      Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky;
      cholesky.compute(a);
      if (cholesky.info() != Eigen::Success)
        throw std::runtime_error("enrichment Laplace solve: CHOLMOD could not factor the " + std::to_string(m) +
                                 "-unknown texel Laplacian over " + std::to_string(tiles.size()) +
                                 " elements (not positive definite or out of memory)");
      const Eigen::VectorXd x = cholesky.solve(b);
      if (cholesky.info() != Eigen::Success || !x.allFinite())
        throw std::runtime_error("enrichment Laplace solve: CHOLMOD solve failed for " + std::to_string(m) + " unknowns");
      stats.relative_residual = b.norm() > 0 ? (b - a.selfadjointView<Eigen::Lower>() * x).norm() / b.norm() : 0.0;
      for (int k = 0; k < m; ++k) graph.value(node_of[k]) = x[k];
    }
  }
  stats.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace dgtex

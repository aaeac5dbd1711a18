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

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

MeshLaplaceStats solve_mesh_texel_laplace(std::vector<RegionTile>& tiles, ElementType type,
                                          const ElementAdjacency& adjacency, const MeshEdgeWalls& edge_walls,
                                          LaplaceSolver solver) {
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
    if (solver == LaplaceSolver::multigrid && tiles.size() == 1) {
      // One tile, no neighbours: the tile multigrid, with the settled texels as data.
      TexelTile tile = tiles.front().tile;
      for (int v = 0; v < n; ++v)
        if (graph.free(v) && unknown_of[v] < 0) tile.flags[v] |= kernels::dirichlet, tile.values[v] = graph.value(v);
      const LaplaceSolveStats s = solve_laplace(tile, LaplaceSolver::multigrid);
      stats.relative_residual = s.relative_residual;
      for (int v : node_of) graph.value(v) = tile.values[v];
    } else {
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

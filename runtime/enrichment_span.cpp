#include "dgtex/enrichment_span.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "dgtex/kernels/forall.h"

namespace dgtex {
namespace {

const kernels::TexelTile* texture_of(const EnrichmentFunction& f, int element) {
  const auto it = std::lower_bound(f.elements.begin(), f.elements.end(), element,
                                   [](const ElementTexture& t, int e) { return t.element < e; });
  return it != f.elements.end() && it->element == element ? &it->tile : nullptr;
}

// Eight interleaved partial sums, combined pairwise: one running sum waits on the adder's
// latency for every texel (accordion's 18 functions on one T=256 tile: 342 dot products,
// ~30 ms); eight chains vectorize. A fixed order: the same sum on every run and thread.
// Clones per instruction set: wider vectors hold the same eight sums (no FMA contraction
// in this file), so every clone rounds the same.
__attribute__((target_clones("avx512f", "avx2", "default")))
double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  const std::size_t n = a.size(), blocked = n - n % 8;
  for (std::size_t k = 0; k < blocked; k += 8)
    for (int l = 0; l < 8; ++l) s[l] += a[k + l] * b[k + l];
  for (std::size_t k = blocked; k < n; ++k) s[k - blocked] += a[k] * b[k];
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// column -= (q . column) q, the cloned loops as dot's.
__attribute__((target_clones("avx512f", "avx2", "default")))
void subtract_projection(std::vector<double>& column, const std::vector<double>& q) {
  const double c = dot(q, column);
  for (std::size_t p = 0; p < column.size(); ++p) column[p] -= c * q[p];
}

__attribute__((target_clones("avx512f", "avx2", "default")))
void divide(std::vector<double>& column, double norm) {
  for (double& v : column) v /= norm;
}

// Count, mean and sum of squared deviations of one tile's active texel values (two
// passes: stable for the nearly constant tiles of complete cuts).
struct TexelMoments {
  double count = 0, mean = 0, m2 = 0;
};

TexelMoments active_moments(const kernels::TexelTile& tile) {
  TexelMoments m;
  double sum = 0;
  for (std::size_t p = 0; p < tile.flags.size(); ++p)
    if (!(tile.flags[p] & kernels::inactive)) sum += tile.values[p], m.count += 1;
  if (m.count == 0) return m;
  m.mean = sum / m.count;
  for (std::size_t p = 0; p < tile.flags.size(); ++p)
    if (!(tile.flags[p] & kernels::inactive)) m.m2 += (tile.values[p] - m.mean) * (tile.values[p] - m.mean);
  return m;
}

// Pooled moments of several tiles (Chan et al.'s combination, stable like the two passes).
TexelMoments pool(const std::vector<const TexelMoments*>& parts) {
  TexelMoments all;
  for (const TexelMoments* p : parts) all.count += p->count;
  if (all.count == 0) return all;
  for (const TexelMoments* p : parts) all.mean += p->count * p->mean;
  all.mean /= all.count;
  for (const TexelMoments* p : parts) all.m2 += p->m2 + p->count * (p->mean - all.mean) * (p->mean - all.mean);
  return all;
}

// Nodes that several functions enrich and that share a support (the node's elements).
struct SharedSupport {
  int node;                                                   // the first such node (for messages)
  std::vector<int> functions;                                 // in function order
  std::vector<std::vector<const kernels::TexelTile*>> tiles;  // per function, per element
  std::vector<char> keeps;                                    // per function: adds to the span there
};

// Which functions add to the span of 1 and the earlier functions over the support's active
// texels: classical Gram-Schmidt, twice.
void span_keeps(SharedSupport& support, double tolerance) {
  const auto& tiles = support.tiles;
  support.keeps.assign(support.functions.size(), 0);
  // Sample positions: the active texels of the support (flags are the same in every
  // function: the walls of all cuts and the inactive bits).
  std::size_t n = 0;
  for (const kernels::TexelTile* tile : tiles[0])
    for (std::uint8_t flag : tile->flags) n += !(flag & kernels::inactive);
  if (n == 0) return;
  std::vector<std::vector<double>> basis(1, std::vector<double>(n, 1.0 / std::sqrt(static_cast<double>(n))));
  std::vector<double> column;
  for (std::size_t k = 0; k < support.functions.size(); ++k) {
    column.clear();
    for (std::size_t t = 0; t < tiles[k].size(); ++t) {
      const kernels::TexelTile& mask = *tiles[0][t];
      for (std::size_t p = 0; p < mask.flags.size(); ++p)
        if (!(mask.flags[p] & kernels::inactive)) column.push_back(tiles[k][t]->values[p]);
    }
    if (column.size() != n)
      throw std::invalid_argument("enrichment function " + std::to_string(support.functions[k]) +
                                  ": the textures around node " + std::to_string(support.node) +
                                  " differ in size or active texels from function " +
                                  std::to_string(support.functions[0]) + "'s");
    for (int pass = 0; pass < 2; ++pass)  // twice: classical Gram-Schmidt loses orthogonality once
      for (const std::vector<double>& q : basis) subtract_projection(column, q);
    const double norm = std::sqrt(dot(column, column));
    if (!(norm > tolerance * std::sqrt(static_cast<double>(n)))) continue;  // adds nothing there
    divide(column, norm);
    basis.push_back(column);
    support.keeps[k] = 1;
  }
}

}  // namespace

std::vector<std::vector<int>> independent_enriched_nodes(const std::vector<std::vector<int>>& node_elements,
                                                         const std::vector<EnrichmentFunction>& functions,
                                                         double tolerance) {
  // Node -> the functions enriching it, in function order.
  std::map<int, std::vector<int>> by_node;
  for (int i = 0; i < static_cast<int>(functions.size()); ++i)
    for (int a : functions[i].enriched_nodes) by_node[a].push_back(i);

  std::vector<std::vector<int>> kept(functions.size());
  // Per (function, element) moments, for nodes that only one function enriches: there the
  // Gram-Schmidt residual of H against 1 is H minus its mean, whose norm is sqrt(m2) of the
  // pooled moments, so each tile is read once instead of once per incident node. Computed
  // up front, one tile per work item (chad: 4 tiles of 65k texels, 1.9 ms a step on one
  // thread); each tile is summed in texel order, so the result does not depend on threads.
  std::map<std::pair<int, int>, TexelMoments> moments;
  {
    std::vector<std::pair<const kernels::TexelTile*, TexelMoments*>> work;  // map nodes stay put
    for (const auto& [a, list] : by_node) {
      if (list.size() != 1 || a < 0 || a >= static_cast<int>(node_elements.size())) continue;
      for (int e : node_elements[a]) {
        const kernels::TexelTile* tile = texture_of(functions[list[0]], e);
        if (!tile) continue;  // reported below
        const auto [it, fresh] = moments.emplace(std::make_pair(list[0], e), TexelMoments{});
        if (fresh) work.emplace_back(tile, &it->second);
      }
    }
    kernels::forall(static_cast<std::int64_t>(work.size()),
                    [&](std::int64_t k) { *work[k].second = active_moments(*work[k].first); });
  }
  std::vector<const TexelMoments*> parts;
  // Nodes that several functions enrich: one Gram-Schmidt per distinct (support, functions)
  // (nodes with the same elements in the same order and the same functions get the same
  // answer: all nodes of an element with many cuts, midside nodes), one per work item.
  std::vector<SharedSupport> shared;
  std::map<std::pair<std::vector<int>, std::vector<int>>, int> shared_index;
  constexpr int dropped = -1, kept_alone = -2;
  std::vector<int> answer;  // per node of by_node: dropped, kept_alone, or its shared support
  for (const auto& [a, list] : by_node) {
    if (list.size() == 1 && a >= 0 && a < static_cast<int>(node_elements.size())) {
      parts.clear();
      for (int e : node_elements[a]) {
        const kernels::TexelTile* tile = texture_of(functions[list[0]], e);
        if (!tile)
          throw std::invalid_argument("enrichment function " + std::to_string(list[0]) + ": element " +
                                      std::to_string(e) + " is incident to enriched node " + std::to_string(a) +
                                      " but has no texture");
        parts.push_back(&moments.at({list[0], e}));
      }
      const TexelMoments all = pool(parts);
      answer.push_back(all.count > 0 && std::sqrt(all.m2) > tolerance * std::sqrt(all.count) ? kept_alone : dropped);
      continue;
    }
    if (a < 0 || a >= static_cast<int>(node_elements.size()))
      throw std::invalid_argument("enrichment function " + std::to_string(list[0]) + ": enriched node " +
                                  std::to_string(a) + " out of range [0, " + std::to_string(node_elements.size()) + ")");
    const auto [it, fresh] =
        shared_index.emplace(std::make_pair(node_elements[a], list), static_cast<int>(shared.size()));
    answer.push_back(it->second);
    if (!fresh) continue;
    SharedSupport support{a, list, std::vector<std::vector<const kernels::TexelTile*>>(list.size()), {}};
    for (std::size_t k = 0; k < list.size(); ++k)
      for (int e : node_elements[a]) {
        const kernels::TexelTile* tile = texture_of(functions[list[k]], e);
        if (!tile)
          throw std::invalid_argument("enrichment function " + std::to_string(list[k]) + ": element " + std::to_string(e) +
                                      " is incident to enriched node " + std::to_string(a) + " but has no texture");
        support.tiles[k].push_back(tile);
      }
    shared.push_back(std::move(support));
  }
  std::vector<std::exception_ptr> failures(shared.size());
  kernels::forall_dynamic(static_cast<std::int64_t>(shared.size()), [&](std::int64_t k) {
    try {
      span_keeps(shared[k], tolerance);
    } catch (...) {
      failures[k] = std::current_exception();
    }
  });
  for (const std::exception_ptr& failure : failures)
    if (failure) std::rethrow_exception(failure);
  std::size_t next = 0;
  for (const auto& [a, list] : by_node) {
    const int answer_here = answer[next++];
    if (answer_here == kept_alone) kept[list[0]].push_back(a);
    if (answer_here >= 0)
      for (std::size_t k = 0; k < list.size(); ++k)
        if (shared[answer_here].keeps[k]) kept[list[k]].push_back(a);
  }
  return kept;  // by_node is ordered by node, so each list is sorted
}

EnrichmentFunction restrict_enriched_nodes(const Mesh& mesh, const EnrichmentFunction& f, std::vector<int> nodes) {
  EnrichmentFunction out;
  out.enriched_nodes = std::move(nodes);
  for (const ElementTexture& texture : f.elements) {
    const int* element_nodes = mesh.element_nodes(texture.element);
    bool touches = false;
    for (int k = 0; k < mesh.nodes_per_element() && !touches; ++k)
      touches = std::binary_search(out.enriched_nodes.begin(), out.enriched_nodes.end(), element_nodes[k]);
    if (touches) out.elements.push_back(texture);
  }
  return out;
}

}  // namespace dgtex

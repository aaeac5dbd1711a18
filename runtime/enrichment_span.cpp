#include "dgtex/enrichment_span.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Dense>

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

// The support's samples: column 0 the constant 1, column 1 + k function k's values at the
// active texels (flags are the same in every function: the walls of all cuts and the
// inactive bits).
Eigen::MatrixXd support_samples(const SharedSupport& support) {
  const auto& tiles = support.tiles;
  Eigen::Index n = 0;
  std::vector<char> all_active;  // per element: no inactive texel (quad8), copied whole
  for (const kernels::TexelTile* tile : tiles[0]) {
    Eigen::Index active = 0;
    for (std::uint8_t flag : tile->flags) active += !(flag & kernels::inactive);
    all_active.push_back(active == static_cast<Eigen::Index>(tile->flags.size()));
    n += active;
  }
  Eigen::MatrixXd samples(n, static_cast<Eigen::Index>(tiles.size()) + 1);
  samples.col(0).setOnes();
  for (std::size_t k = 0; k < tiles.size(); ++k) {
    double* column = samples.col(static_cast<Eigen::Index>(k) + 1).data();
    Eigen::Index row = 0;
    for (std::size_t t = 0; t < tiles[k].size(); ++t) {
      const kernels::TexelTile& mask = *tiles[0][t];
      if (tiles[k][t]->flags.size() != mask.flags.size())
        throw std::invalid_argument("enrichment function " + std::to_string(support.functions[k]) +
                                    ": the textures around node " + std::to_string(support.node) +
                                    " differ in size or active texels from function " +
                                    std::to_string(support.functions[0]) + "'s");
      const std::vector<double>& values = tiles[k][t]->values;
      if (all_active[t]) {
        std::copy(values.begin(), values.end(), column + row);
        row += static_cast<Eigen::Index>(values.size());
        continue;
      }
      for (std::size_t p = 0; p < mask.flags.size(); ++p)
        if (!(mask.flags[p] & kernels::inactive)) column[row++] = values[p];
    }
  }
  return samples;
}

// The lower triangle of S^T S for the n x columns samples (column-major), eight interleaved
// sums per entry as in dot: Eigen's product runs at SSE2 width in this build (no -march).
__attribute__((target_clones("avx512f", "avx2", "default")))
void gram_lower(const double* samples, std::size_t n, std::size_t columns, double* gram) {
  std::vector<double> sums(columns * (columns + 1) / 2 * 8, 0.0);
  const std::size_t blocked = n - n % 8;
  for (std::size_t k = 0; k < blocked; k += 8) {
    double* __restrict sum = sums.data();
    for (std::size_t i = 0; i < columns; ++i)
      for (std::size_t j = 0; j <= i; ++j, sum += 8)
        for (int l = 0; l < 8; ++l) sum[l] += samples[i * n + k + l] * samples[j * n + k + l];
  }
  double* sum = sums.data();
  for (std::size_t i = 0; i < columns; ++i)
    for (std::size_t j = 0; j <= i; ++j, sum += 8) {
      for (std::size_t k = blocked; k < n; ++k) sum[k - blocked] += samples[i * n + k] * samples[j * n + k];
      gram[j * columns + i] = ((sum[0] + sum[1]) + (sum[2] + sum[3])) + ((sum[4] + sum[5]) + (sum[6] + sum[7]));
    }
}

// Whether every function certainly adds to the span of 1 and the earlier ones, read from the
// Gram matrix G = S^T S of the samples: one pass over them instead of Gram-Schmidt's two per
// basis vector (the slinky's span test was 21% of its cut update, bound by reading the basis).
// Function k's residual r_k after the earlier columns is its Schur complement in G, at least
// G_kk lambda_min(D G D) (D scales G to a unit diagonal). The bound is taken down by the
// worst-case rounding of G's sums (n eps relative to sqrt(G_ii G_jj)) and of the eigenvalue,
// and must clear the drop threshold by 10%, so Gram-Schmidt (span_keeps) would keep every
// function too: certified supports get its answer without running it, the others run it.
bool certainly_all_independent(const Eigen::MatrixXd& samples, double threshold) {
  const Eigen::Index columns = samples.cols();
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(columns, columns);
  gram_lower(samples.data(), static_cast<std::size_t>(samples.rows()), static_cast<std::size_t>(columns), gram.data());
  Eigen::VectorXd scale(columns);
  for (Eigen::Index i = 0; i < columns; ++i) {
    if (!(gram(i, i) > 0) || !std::isfinite(gram(i, i))) return false;
    scale[i] = 1 / std::sqrt(gram(i, i));
  }
  const Eigen::MatrixXd full = gram.selfadjointView<Eigen::Lower>();
  const Eigen::MatrixXd unit = scale.asDiagonal() * full * scale.asDiagonal();
  const double eps = std::numeric_limits<double>::epsilon();
  const double rounding = static_cast<double>(columns) *
                          (static_cast<double>(samples.rows()) * eps + 10.0 * static_cast<double>(columns) * eps);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(unit, Eigen::EigenvaluesOnly);
  const double lowest = eigen.eigenvalues()[0] - rounding;
  if (!(lowest > 0)) return false;
  for (Eigen::Index k = 1; k < columns; ++k)
    if (!(gram(k, k) * (1 - rounding) * lowest > 1.21 * threshold * threshold)) return false;
  return true;
}

// Which functions add to the span of 1 and the earlier functions over the support's active
// texels: Gram-Schmidt (modified), twice; only where certainly_all_independent cannot tell.
void span_keeps(SharedSupport& support, double tolerance) {
  support.keeps.assign(support.functions.size(), 0);
  const Eigen::MatrixXd samples = support_samples(support);
  const Eigen::Index n = samples.rows();
  if (n == 0) return;
  const double threshold = tolerance * std::sqrt(static_cast<double>(n));  // on a residual's norm
  if (certainly_all_independent(samples, threshold)) {
    support.keeps.assign(support.functions.size(), 1);
    return;
  }
  std::vector<std::vector<double>> basis(
      1, std::vector<double>(static_cast<std::size_t>(n), 1.0 / std::sqrt(static_cast<double>(n))));
  std::vector<double> column(static_cast<std::size_t>(n));
  for (std::size_t k = 0; k < support.functions.size(); ++k) {
    const double* values = samples.col(static_cast<Eigen::Index>(k) + 1).data();
    column.assign(values, values + n);
    for (int pass = 0; pass < 2; ++pass)  // twice: Gram-Schmidt loses orthogonality once
      for (const std::vector<double>& q : basis) subtract_projection(column, q);
    const double norm = std::sqrt(dot(column, column));
    if (!(norm > threshold)) continue;  // adds nothing there
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

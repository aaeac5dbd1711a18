// Enriched assembly of one quad8 element with T = 256 enrichment textures: set-up
// (adaptive quadrature + mass + pattern) and the stiffness assembly, linear and corotated,
// for 1 and 6 enrichment functions, each for complete cuts (constant H: cells merge away
// from the cuts) and partial cuts (harmonic H: texel-resolved near the cuts). Counters:
// enriched DOFs and quadrature points. Argument pairs: (enrichments, partial?).
// BM_EnrichedStiffnessClustered: the corotated stiffness under rotation clusters of 16
// texels (the example scenes' setting) once their rest sums exist: a step's assembly.
// BM_EnrichedMassAndLoadWeights: the fused mass pass of a basis change on one element.
// BM_BendingSums*: the frame split's six bending sums of a curved element for one block of
// 16 stacked points over `cols` reduced functions, as one weighted Gram kernel against six
// products of weighted rows (the form it replaced).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_element_rest_integrals.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/kernels/gram_accumulation.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/shell_model.h"
#include "dgtex/topology.h"

using namespace dgtex;

namespace {

constexpr int kResolution = 256;

// Straight cuts in texel coordinates: complete ones cross the tile (parallel, so each is
// complete); partial ones enter from the left or right border and stop inside.
std::vector<std::vector<kernels::TexelPoint>> cut_lines(int count, bool partial) {
  const double t = kResolution;
  std::vector<std::vector<kernels::TexelPoint>> lines;
  for (int k = 0; k < count; ++k) {
    const double y = t * (k + 0.5) / count + 3;
    if (!partial) lines.push_back({{0, y}, {t, y}});
    else if (k % 2 == 0) lines.push_back({{0, y}, {0.45 * t, y}});
    else lines.push_back({{t, y}, {0.55 * t, y}});
  }
  return lines;
}

std::vector<EnrichmentFunction> enrichments(int count, bool partial, const Mesh& mesh) {
  kernels::TexelTile walls = kernels::make_element_tile(ElementType::quad8, kResolution);
  std::vector<kernels::CutRaster> cuts;
  for (const auto& line : cut_lines(count, partial)) cuts.push_back(kernels::rasterize_cut(line, walls));
  std::vector<EnrichmentFunction> functions;
  for (const auto& cut : cuts) {
    EnrichmentFunction f;
    for (int a = 0; a < 8; ++a) f.enriched_nodes.push_back(mesh.element_nodes(0)[a]);
    std::sort(f.enriched_nodes.begin(), f.enriched_nodes.end());
    f.elements.push_back({0, partial ? harmonic_enrichment(walls, cut).tile : complete_cut_heaviside(walls, cut)});
    functions.push_back(std::move(f));
  }
  return functions;
}

const kernels::ShellSection kSection{1e6, 0.3, 0.01, 1000};

// The one quad8 element's model under `options`, with `functions` set.
std::unique_ptr<ShellModel> enriched_model(const Mesh& mesh, const std::vector<EnrichmentFunction>& functions,
                                           const ShellModelOptions& options) {
  auto model = std::make_unique<ShellModel>(mesh, build_topology(mesh), std::vector<kernels::ShellSection>(1, kSection),
                                            std::vector<int>{}, options);
  model->set_enrichments(functions);
  return model;
}

struct Setup {
  Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  std::unique_ptr<ShellModel> model;
  std::vector<EnrichmentFunction> functions;
};

Setup& setup(int count, bool partial) {
  static std::map<std::pair<int, bool>, Setup> cache;
  Setup& s = cache[{count, partial}];
  if (!s.model) {
    s.functions = enrichments(count, partial, s.mesh);
    s.model = enriched_model(s.mesh, s.functions, ShellModelOptions{});
  }
  return s;
}

void counters(benchmark::State& state, const ShellModel& model) {
  state.counters["enriched_dofs"] = model.num_enriched_dofs();
  state.counters["element_qp"] = static_cast<double>(model.num_enriched_element_quadrature_points());
  state.counters["edge_qp"] = static_cast<double>(model.num_enriched_edge_quadrature_points());
}

void BM_EnrichedSetUp(benchmark::State& state) {
  Setup& s = setup(static_cast<int>(state.range(0)), state.range(1) != 0);
  for (auto _ : state) s.model->set_enrichments(s.functions);
  counters(state, *s.model);
}

void BM_EnrichedStiffnessLinear(benchmark::State& state) {
  Setup& s = setup(static_cast<int>(state.range(0)), state.range(1) != 0);
  std::vector<double> K;
  for (auto _ : state) s.model->assemble_stiffness(nullptr, K, nullptr);
  counters(state, *s.model);
}

void BM_EnrichedStiffnessCorotated(benchmark::State& state) {
  Setup& s = setup(static_cast<int>(state.range(0)), state.range(1) != 0);
  std::vector<double> current = s.model->rest_state(), K, f;
  for (size_t d = 0; d < current.size(); ++d) current[d] += 0.01 * std::sin(0.7 * d);
  for (auto _ : state) s.model->assemble_stiffness(current.data(), K, &f);
  counters(state, *s.model);
}

void BM_EnrichedStiffnessClustered(benchmark::State& state) {
  Setup& s = setup(static_cast<int>(state.range(0)), state.range(1) != 0);
  ShellModelOptions options;
  options.rotation_cluster_texels = 16;
  const std::unique_ptr<ShellModel> clustered = enriched_model(s.mesh, s.functions, options);
  std::vector<double> current = clustered->rest_state(), K, f;
  for (size_t d = 0; d < current.size(); ++d) current[d] += 0.01 * std::sin(0.7 * d);
  clustered->assemble_stiffness(current.data(), K, &f);  // builds the rest sums, untimed
  for (auto _ : state) clustered->assemble_stiffness(current.data(), K, &f);
  counters(state, *clustered);
  state.counters["clusters"] = static_cast<double>(clustered->num_rotation_clusters());
}

void BM_EnrichedStiffnessPerTexel(benchmark::State& state) {
  // The dense reference: per-texel quadrature everywhere (no merging).
  const int count = static_cast<int>(state.range(0));
  const bool partial = state.range(1) != 0;
  Setup& s = setup(count, partial);
  ShellModelOptions options;
  options.enrichment_quadrature.adaptive = false;
  const std::unique_ptr<ShellModel> dense = enriched_model(s.mesh, s.functions, options);
  std::vector<double> K;
  for (auto _ : state) dense->assemble_stiffness(nullptr, K, nullptr);
  counters(state, *dense);
}

// The fused mass and load weights (kernels::enriched_element_mass_and_load_weights) of one
// element with `count` harmonic partial cuts at T = 256, per-texel quadrature (4 points a
// texel, 262k points: the densest rule), on the machine's threads.
void BM_EnrichedMassAndLoadWeights(benchmark::State& state) {
  Setup& s = setup(static_cast<int>(state.range(0)), true);
  const int npe = kernels::nodes_per_element(ElementType::quad8);
  std::vector<kernels::TextureView> views;
  std::vector<int> node, start = {0};
  std::vector<double> shift;
  for (const EnrichmentFunction& f : s.functions) {
    const kernels::TexelTile& tile = f.elements[0].tile;
    views.push_back({tile.values.data(), tile.flags.data()});
    for (int a = 0; a < npe; ++a) node.push_back(100 + static_cast<int>(node.size())), shift.push_back(0.1 * a);
  }
  start.push_back(static_cast<int>(views.size()));
  const std::vector<kernels::ShellSection> sections(1, kSection);
  const int element = 0;
  kernels::EnrichedElementBatch batch{ElementType::quad8, 1, &element, s.mesh.elements.data(), s.mesh.positions.data(),
                                      sections.data(), kResolution, 0, start.data(), views.data(), node.data(),
                                      shift.data()};
  batch.width = kernels::enriched_basis_count(batch, 0);
  kernels::EnrichedQuadratureOptions per_texel;
  per_texel.adaptive = false;
  std::vector<std::int64_t> qs;
  std::vector<double> qp;
  kernels::enriched_element_quadrature(batch, per_texel, qs, qp);
  const int W = batch.width;
  std::vector<double> mass(static_cast<std::size_t>(W) * W), area(W), weights(W);
  for (auto _ : state) {
    kernels::enriched_element_mass_and_load_weights(batch, {qs.data(), qp.data()}, mass.data(), area.data(),
                                                    weights.data());
    benchmark::ClobberMemory();
  }
  state.counters["functions"] = W;
  state.counters["points"] = static_cast<double>(qs.back());
}

struct BendingBlock {
  static constexpr int points = 16, sums = 6;
  std::vector<double> rows, weights, weighted_rows;  // 3 rows a point; per sum, its weighted rows
  std::vector<std::vector<double>> G;
  explicit BendingBlock(int cols)
      : rows(static_cast<std::size_t>(points) * 3 * cols), weights(points * sums),
        weighted_rows(sums * rows.size()), G(sums, std::vector<double>(static_cast<std::size_t>(cols) * cols)) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    for (double& x : rows) x = u(rng);
    for (double& x : weights) x = u(rng);
    for (double& x : weighted_rows) x = u(rng);
  }
};

void BM_BendingSumsWeightedGrams(benchmark::State& state) {
  const int cols = static_cast<int>(state.range(0));
  BendingBlock b(cols);
  double* sums[BendingBlock::sums];
  for (int k = 0; k < BendingBlock::sums; ++k) sums[k] = b.G[k].data();
  const bool overwrite[BendingBlock::sums] = {};
  for (auto _ : state) {
    kernels::accumulate_weighted_grams(BendingBlock::points, 3, cols, b.rows.data(), b.weights.data(),
                                       BendingBlock::sums, sums, overwrite);
    benchmark::ClobberMemory();
  }
}

void BM_BendingSumsSixProducts(benchmark::State& state) {
  const int cols = static_cast<int>(state.range(0));
  BendingBlock b(cols);
  for (auto _ : state) {
    for (int k = 0; k < BendingBlock::sums; ++k)
      kernels::accumulate_product(3 * BendingBlock::points, cols, b.weighted_rows.data() + k * b.rows.size(),
                                  b.weighted_rows.data() + k * b.rows.size(), b.G[k].data(), false, true);
    benchmark::ClobberMemory();
  }
}

void enriched_args(benchmark::internal::Benchmark* b) {
  b->Args({1, 0})->Args({6, 0})->Args({1, 1})->Args({6, 1})->Unit(benchmark::kMillisecond);
}
BENCHMARK(BM_EnrichedSetUp)->Apply(enriched_args);
BENCHMARK(BM_EnrichedStiffnessLinear)->Apply(enriched_args);
BENCHMARK(BM_EnrichedStiffnessCorotated)->Apply(enriched_args);
BENCHMARK(BM_EnrichedStiffnessClustered)->Apply(enriched_args);
BENCHMARK(BM_EnrichedStiffnessPerTexel) ->Args({1, 1})->Args({6, 1})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_EnrichedMassAndLoadWeights)->Arg(1)->Arg(6)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BendingSumsWeightedGrams)->Arg(16)->Arg(32)->Arg(64);
BENCHMARK(BM_BendingSumsSixProducts)->Arg(16)->Arg(32)->Arg(64);

}  // namespace

BENCHMARK_MAIN();

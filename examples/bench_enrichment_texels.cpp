// Throughput of the texel-level enrichment stages on one element tile: cut
// rasterisation, flood fill (BFS reference vs parallel union-find), the harmonic
// enrichment of a partial cut (CHOLMOD) and OpenVDB tile copies.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/flood_fill.h"
#include "dgtex/texel_storage.h"

using namespace dgtex;

namespace {

std::vector<kernels::TexelPoint> wavy_cut(int t, double length_fraction) {
  std::vector<kernels::TexelPoint> line;
  for (int k = 0; k <= 64; ++k) {
    const double s = length_fraction * k / 64.0;
    line.push_back({s * t, t * (0.5 + 0.2 * std::sin(9.0 * s))});
  }
  return line;
}

kernels::TexelTile random_walls(int t) {
  std::mt19937 rng(1);
  std::bernoulli_distribution wall(0.45);
  kernels::TexelTile tile(t, t);
  for (auto& f : tile.flags) f = static_cast<std::uint8_t>((wall(rng) ? kernels::wall_east : 0) | (wall(rng) ? kernels::wall_north : 0));
  return tile;
}

void BM_RasterizeCut(benchmark::State& state) {
  const int t = static_cast<int>(state.range(0));
  const auto line = wavy_cut(t, 1.0);
  for (auto _ : state) {
    kernels::TexelTile tile(t, t);
    benchmark::DoNotOptimize(kernels::rasterize_cut(line, tile).edges.size());
  }
}
BENCHMARK(BM_RasterizeCut)->Arg(256)->Arg(1024)->Unit(benchmark::kMicrosecond);

void BM_FloodFillReference(benchmark::State& state) {
  const auto tile = random_walls(static_cast<int>(state.range(0)));
  std::vector<int> labels;
  for (auto _ : state) benchmark::DoNotOptimize(kernels::label_components_reference(tile, labels));
  state.SetItemsProcessed(state.iterations() * tile.width * tile.height);
}
BENCHMARK(BM_FloodFillReference)->Arg(256)->Arg(1024)->Unit(benchmark::kMicrosecond);

void BM_FloodFillParallel(benchmark::State& state) {
  const auto tile = random_walls(static_cast<int>(state.range(0)));
  std::vector<int> labels;
  for (auto _ : state) benchmark::DoNotOptimize(kernels::label_components(tile, labels));
  state.SetItemsProcessed(state.iterations() * tile.width * tile.height);
}
BENCHMARK(BM_FloodFillParallel)->Arg(256)->Arg(1024)->Unit(benchmark::kMicrosecond);

void BM_HarmonicEnrichmentPartialCut(benchmark::State& state) {
  const int t = static_cast<int>(state.range(0));
  kernels::TexelTile tile(t, t);
  const auto cut = kernels::rasterize_cut(wavy_cut(t, 0.6), tile);
  for (auto _ : state) benchmark::DoNotOptimize(harmonic_enrichment(tile, cut).tile.values.data());
}
BENCHMARK(BM_HarmonicEnrichmentPartialCut)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond);

void BM_TexelStorageRoundTrip(benchmark::State& state) {
  const int t = static_cast<int>(state.range(0));
  TexelStorage storage(t);
  kernels::TexelTile tile(t, t), out;
  for (std::size_t k = 0; k < tile.values.size(); ++k) tile.values[k] = 1.0 + static_cast<double>(k % 7);
  for (auto _ : state) {
    storage.copy_tile_in("H", 3, tile);
    benchmark::DoNotOptimize(storage.copy_tile_out("H", 3, out));
  }
}
BENCHMARK(BM_TexelStorageRoundTrip)->Arg(256)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

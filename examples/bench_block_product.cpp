// Google Benchmark cases of the block products of the corotated step and its PCG
// (dgtex/kernels/block_product.h): K x over a fully coupled pattern of n nodes (the cut
// single-element scenes: spiral1 16, spiral6 56, the accordion 147) and over a sparse one
// (1400 nodes, 30 blocks a row, fracture-like), by the one-entry reference (scalar sums,
// the form the products had before the kernel), the widest path, and the widest path with
// the isotropic mass fused in (the PCG's A p), for the ratios in the same run.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "dgtex/kernels/block_product.h"

namespace {

using dgtex::kernels::BlockRows;

// blocks_per_row = 0: fully coupled (every row all nodes), else that many random columns.
struct Pattern {
  int nodes = 0;
  std::vector<std::int64_t> row_start{0};
  std::vector<int> column;
  std::vector<double> blocks, scalars, x, spread, y, y_scalars;
  Pattern(int n, int blocks_per_row) : nodes(n) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-1, 1);
    std::uniform_int_distribution<int> node(0, n - 1);
    for (int r = 0; r < n; ++r) {
      for (int k = 0; k < (blocks_per_row ? blocks_per_row : n); ++k) column.push_back(blocks_per_row ? node(rng) : k);
      row_start.push_back(static_cast<std::int64_t>(column.size()));
    }
    blocks.resize(9 * column.size());
    for (double& v : blocks) v = u(rng);
    scalars.resize(column.size());
    for (double& v : scalars) v = u(rng);
    x.resize(3 * n);
    for (double& v : x) v = u(rng);
    spread.resize(9 * n);
    dgtex::kernels::spread_block_vector(n, x.data(), spread.data());
    y.resize(3 * n);
    y_scalars.resize(3 * n);
  }
  BlockRows rows() const { return {row_start.data(), column.data()}; }
};

Pattern pattern_of(const benchmark::State& state) {
  return Pattern(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
}

void reference(benchmark::State& state) {
  Pattern p = pattern_of(state);
  for (auto _ : state) {
    dgtex::kernels::block_rows_product_reference(p.rows(), 0, p.nodes, p.blocks.data(), p.x.data(), p.y.data());
    benchmark::DoNotOptimize(p.y.data());
  }
}

void widest_path(benchmark::State& state) {
  Pattern p = pattern_of(state);
  for (auto _ : state) {
    dgtex::kernels::spread_block_vector(p.nodes, p.x.data(), p.spread.data());
    dgtex::kernels::block_rows_product(p.rows(), 0, p.nodes, p.blocks.data(), p.spread.data(), p.y.data());
    benchmark::DoNotOptimize(p.y.data());
  }
}

void widest_path_with_mass(benchmark::State& state) {
  Pattern p = pattern_of(state);
  for (auto _ : state) {
    dgtex::kernels::spread_block_vector(p.nodes, p.x.data(), p.spread.data());
    dgtex::kernels::block_and_scalar_rows_product(p.rows(), 0, p.nodes, p.blocks.data(), p.scalars.data(),
                                                  p.spread.data(), p.y.data(), p.y_scalars.data());
    benchmark::DoNotOptimize(p.y.data());
  }
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int n : {16, 56, 147}) b->Args({n, 0});
  b->Args({1400, 30});
}

}  // namespace

BENCHMARK(reference)->Apply(sizes);
BENCHMARK(widest_path)->Apply(sizes);
BENCHMARK(widest_path_with_mass)->Apply(sizes);
BENCHMARK_MAIN();

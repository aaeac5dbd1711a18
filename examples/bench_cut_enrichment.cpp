// Google Benchmark cases for the mesh-level harmonic enrichment (cut_manager.h):
//  - one_ring: a partial cut ending in the centre element of a 3x3 plate; the whole
//    Omega_i (all 9 elements) is solved as one texel graph (CHOLMOD), per T and element type;
//  - progressive: a cut advancing across a 8x3 plate, one update per step with freezing
//    (the per-step cost that a dynamic run pays).
#include <benchmark/benchmark.h>

#include "dgtex/cut_manager.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/topology.h"

namespace {

dgtex::Cut points_cut(std::vector<dgtex::Vec3> points) {
  dgtex::Cut cut;
  cut.kind = dgtex::Cut::Kind::points;
  cut.points = std::move(points);
  return cut;
}

void one_ring(benchmark::State& state) {
  const int t = static_cast<int>(state.range(0));
  const auto type = static_cast<dgtex::ElementType>(state.range(1));
  const dgtex::Mesh mesh = dgtex::make_rectangle(3, 3, 3, 3, type);
  const dgtex::Topology topology = dgtex::build_topology(mesh);
  dgtex::EnrichmentOptions options;
  options.texture_resolution = t;
  options.solver = dgtex::EnrichmentOptions::Solver::cholmod;
  const dgtex::Cut cut = points_cut({{0, 1.41, 0}, {1.55, 1.52, 0}});
  int unknowns = 0;
  for (auto _ : state) {
    dgtex::CutManager manager(mesh, topology, {cut}, options);
    manager.update(0.0);
    state.SetIterationTime(manager.last_update().solve_ms * 1e-3);
    unknowns = manager.last_update().unknowns;
  }
  state.counters["unknowns"] = unknowns;
  state.SetLabel(std::string(type == dgtex::ElementType::quad8 ? "quad8" : "tri6") + " T=" + std::to_string(t));
}

void progressive(benchmark::State& state) {
  const int t = static_cast<int>(state.range(0));
  const dgtex::Mesh mesh = dgtex::make_rectangle(8, 3, 8, 3, dgtex::ElementType::quad8);
  const dgtex::Topology topology = dgtex::build_topology(mesh);
  dgtex::EnrichmentOptions options;
  options.texture_resolution = t;
  options.solver = dgtex::EnrichmentOptions::Solver::cholmod;
  dgtex::Cut cut = points_cut({{0, 1.41, 0}, {7.5, 1.62, 0}});
  cut.has_schedule = true;
  cut.speed = 1.0;
  double worst = 0;
  for (auto _ : state) {
    dgtex::CutManager manager(mesh, topology, {cut}, options);
    double total = 0;
    for (double time = 0.25; time <= 7.5; time += 0.25) {
      manager.update(time);
      total += manager.last_update().ms;
      worst = std::max(worst, manager.last_update().ms);
    }
    state.SetIterationTime(total * 1e-3 / 30);
  }
  state.counters["worst_update_ms"] = worst;
  state.SetLabel("8x3 quad8 T=" + std::to_string(t) + ", mean per update");
}

}  // namespace

BENCHMARK(one_ring)
    ->ArgsProduct({{64, 128, 256}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(progressive)->Arg(64)->Arg(128)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_MAIN();

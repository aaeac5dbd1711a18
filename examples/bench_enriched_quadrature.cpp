// Adaptive enriched quadrature (enriched_element_quadrature) on T = 256 textures like the
// progressive-cut scenes': one quad8 element with the harmonic enrichment of a partial
// spiral cut (spiral1), four quad8 elements with partial straight cuts (chad-sized), one
// with complete cuts (Heaviside) and one with six partial cuts (six textures on one element,
// as spiral6 has). Fast form (1 thread and all threads) against the serial reference twin;
// both give bitwise the same points (test_enrichment_quadrature_speed).
// Argument: scene (0 spiral, 1 four elements, 2 complete cuts, 3 six arcs); reference? (0/1);
// threads.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <map>
#include <memory>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/mesh_generators.h"

using namespace dgtex;

namespace {

constexpr int kResolution = 256;

struct Scene {
  Mesh mesh;
  std::vector<std::vector<kernels::TexelTile>> tiles;  // per element
  std::vector<kernels::TextureView> views;
  std::vector<int> element, start{0}, nodes;
  std::vector<double> shifts;
  std::vector<kernels::ShellSection> sections;
  int width = 0;

  explicit Scene(std::vector<std::vector<kernels::TexelTile>> textures)
      : mesh(make_rectangle(1.0, 1.0, static_cast<int>(textures.size()), 1, ElementType::quad8)), tiles(std::move(textures)) {
    for (std::size_t e = 0; e < tiles.size(); ++e) {
      element.push_back(static_cast<int>(e));
      for (const kernels::TexelTile& tile : tiles[e]) {
        views.push_back({tile.values.data(), tile.flags.data()});
        for (int a = 0; a < 8; ++a) nodes.push_back(-1), shifts.push_back(0.0);
      }
      start.push_back(static_cast<int>(views.size()));
      width = std::max(width, 8 * (1 + static_cast<int>(tiles[e].size())));
    }
    sections.assign(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  }
  kernels::EnrichedElementBatch batch() const {
    return {ElementType::quad8, static_cast<std::int64_t>(tiles.size()), element.data(), mesh.elements.data(),
            mesh.positions.data(), sections.data(), kResolution, width, start.data(), views.data(), nodes.data(),
            shifts.data()};
  }
};

kernels::TexelTile harmonic(const std::vector<kernels::TexelPoint>& line) {
  kernels::TexelTile walls = kernels::make_element_tile(ElementType::quad8, kResolution);
  const kernels::CutRaster raster = kernels::rasterize_cut(line, walls);
  return harmonic_enrichment(walls, raster).tile;
}

std::unique_ptr<Scene> make_scene(int which) {
  const double t = kResolution;
  if (which == 0) {  // a spiral from the left border inwards
    std::vector<kernels::TexelPoint> line{{0, 0.5 * t}};
    for (int n = 0; n <= 200; ++n) {
      const double a = M_PI + 3.5 * M_PI * n / 200.0, r = 0.48 * t * (1 - 0.8 * n / 200.0);
      line.push_back({0.5 * t + r * std::cos(a), 0.5 * t + r * std::sin(a)});
    }
    return std::make_unique<Scene>(std::vector<std::vector<kernels::TexelTile>>{{harmonic(line)}});
  }
  if (which == 1) {  // four elements, each with a partial cut entering from a different side
    std::vector<std::vector<kernels::TexelTile>> textures;
    textures.push_back({harmonic({{0, 0.4 * t}, {0.6 * t, 0.55 * t}})});
    textures.push_back({harmonic({{0.3 * t, 0}, {0.45 * t, 0.7 * t}})});
    textures.push_back({harmonic({{t, 0.7 * t}, {0.35 * t, 0.6 * t}})});
    textures.push_back({harmonic({{0.6 * t, t}, {0.5 * t, 0.25 * t}})});
    return std::make_unique<Scene>(std::move(textures));
  }
  if (which == 3) {  // one element with six textures (spiral6's count): a spiral in six arcs
    std::vector<kernels::TexelTile> arcs;
    for (int k = 0; k < 6; ++k) {
      std::vector<kernels::TexelPoint> line;
      for (int n = 0; n <= 40; ++n) {
        const double a = M_PI + 3.5 * M_PI * (40 * k + n) / 240.0, r = 0.48 * t * (1 - 0.8 * (40 * k + n) / 240.0);
        line.push_back({0.5 * t + r * std::cos(a), 0.5 * t + r * std::sin(a)});
      }
      arcs.push_back(harmonic(line));
    }
    return std::make_unique<Scene>(std::vector<std::vector<kernels::TexelTile>>{std::move(arcs)});
  }
  kernels::TexelTile walls = kernels::make_element_tile(ElementType::quad8, kResolution);
  const kernels::CutRaster a = kernels::rasterize_cut({{0, 0.3 * t}, {t, 0.6 * t}}, walls);
  const kernels::CutRaster b = kernels::rasterize_cut({{0.2 * t, 0}, {0.4 * t, 0.5 * t}, {0.3 * t, t}}, walls);
  return std::make_unique<Scene>(
      std::vector<std::vector<kernels::TexelTile>>{{complete_cut_heaviside(walls, a), complete_cut_heaviside(walls, b)}});
}

const Scene& scene(int which) {
  static std::map<int, std::unique_ptr<Scene>> cache;
  std::unique_ptr<Scene>& s = cache[which];
  if (!s) s = make_scene(which);
  return *s;
}

void BM_EnrichedElementQuadrature(benchmark::State& state) {
  const Scene& s = scene(static_cast<int>(state.range(0)));
  const bool reference = state.range(1) != 0;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(static_cast<int>(state.range(2)));
  std::vector<std::int64_t> start;
  std::vector<double> points;
  const kernels::EnrichedQuadratureOptions options;
  for (auto _ : state) {
    if (reference) kernels::enriched_element_quadrature_reference(s.batch(), options, start, points);
    else kernels::enriched_element_quadrature(s.batch(), options, start, points);
    benchmark::DoNotOptimize(points.data());
  }
  omp_set_num_threads(saved);
  state.counters["points"] = static_cast<double>(start.back());
}

}  // namespace

BENCHMARK(BM_EnrichedElementQuadrature)
    ->ArgNames({"scene", "reference", "threads"})
    ->ArgsProduct({{0, 1, 2, 3}, {1, 0}, {1}})
    ->Args({0, 0, 2})
    ->Args({1, 0, 2})
    ->Args({3, 0, 2})
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

#pragma once
// One quad8 element at T = 64 with `complete` straight cuts across its tile and `partial`
// cuts from its borders (harmonic enrichment), every node enriched by every function, as
// the input of the enriched element kernels: the batch (its local basis padded by
// `extra_slots` unused slots) and its quadrature (the adaptive rule, or the per-texel rule
// with many points: several chunks even where the adaptive rule merges).
#include <cstdint>
#include <vector>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_element_kernel.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/mesh_generators.h"

namespace dgtex::testing_support {

struct CutQuad8Element {
  static constexpr int T = 64;
  Mesh mesh = make_rectangle(1.0, 0.8, 1, 1, ElementType::quad8);
  std::vector<kernels::TexelTile> tiles;
  std::vector<kernels::TextureView> views;
  std::vector<int> element{0}, start, nodes;
  std::vector<double> shifts;
  std::vector<kernels::ShellSection> sections{{1e6, 0.3, 0.01, 1000}};
  kernels::EnrichedElementBatch batch{};
  std::vector<std::int64_t> qp_start;
  std::vector<double> qp;
  int n = 0;  // basis functions (batch.width - extra_slots)

  CutQuad8Element(int complete, int partial, bool per_texel_rule = false, int extra_slots = 0) {
    kernels::TexelTile walls = kernels::make_element_tile(ElementType::quad8, T);
    const int count = complete + partial;
    for (int k = 0; k < count; ++k) {
      const double y = T * (k + 0.5) / count + 0.3;
      const bool is_partial = k >= complete;
      std::vector<kernels::TexelPoint> line;
      if (!is_partial) line = {{0, y}, {double(T), y + 2}};
      else if (k % 2 == 0) line = {{0, y}, {0.6 * T, y}};
      else line = {{double(T), y}, {0.4 * T, y}};
      const kernels::CutRaster cut = kernels::rasterize_cut(line, walls);
      tiles.push_back(is_partial ? harmonic_enrichment(walls, cut).tile : complete_cut_heaviside(walls, cut));
    }
    start = {0, count};
    int v = mesh.num_nodes();
    for (int k = 0; k < count; ++k) {
      views.push_back({tiles[k].values.data(), tiles[k].flags.data()});
      for (int a = 0; a < 8; ++a) {
        nodes.push_back(v++);
        double xi[2];
        kernels::node_parametric_position(ElementType::quad8, a, xi);
        kernels::TextureSample s;
        kernels::sample_texture(ElementType::quad8, T, views.back(), xi[0], xi[1], s);
        shifts.push_back(s.value);
      }
    }
    n = 8 * (1 + count);
    batch = {ElementType::quad8, 1, element.data(), mesh.elements.data(), mesh.positions.data(), sections.data(),
             T, n + extra_slots, start.data(), views.data(), nodes.data(), shifts.data()};
    kernels::EnrichedQuadratureOptions rule;
    rule.adaptive = !per_texel_rule;
    kernels::enriched_element_quadrature(batch, rule, qp_start, qp);
  }
  kernels::EnrichedQuadrature quadrature() const { return {qp_start.data(), qp.data()}; }
  std::int64_t points() const { return qp_start.back(); }
};

}  // namespace dgtex::testing_support

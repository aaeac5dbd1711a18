#include "dgtex/kernels/enriched_element_rest_integrals.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/gram_accumulation.h"

namespace dgtex::kernels {

int enriched_shape_values(const EnrichedElementBatch& b, std::int64_t e, double xi1, double xi2, const ShapeValues& s,
                          EnrichedTexelCache& cache, double* N, const TexelDerivativeTile* const* derivatives) {
  int ti = 0, tj = 0;
  containing_texel(b.type, b.resolution, xi1, xi2, ti, tj);
  const int first = b.enrichment_start[e], count = b.enrichment_start[e + 1] - first;
  if (cache.element != e || cache.i != ti || cache.j != tj) {
    for (int k = 0; k < count; ++k) {
      const TextureView& texture = b.textures[first + k];
      const TexelDerivativeTile* tile = derivatives ? derivatives[first + k] : nullptr;
      if (tile && texel_in_domain(b.type, b.resolution, texture.flags, ti, tj)) tile->at(ti, tj, cache.fields[k]);
      else texel_derivatives(b.type, b.resolution, texture, ti, tj, cache.fields[k]);
    }
    cache.element = e, cache.i = ti, cache.j = tj;
  }
  const int npe = s.count;
  for (int a = 0; a < npe; ++a) N[a] = s.N[a];
  int n = npe;
  for (int k = 0; k < count; ++k) {
    TextureSample h;
    sample_texel_polynomial(b.type, b.resolution, cache.fields[k], ti, tj, xi1, xi2, h);
    for (int a = 0; a < npe; ++a) {
      const std::int64_t slot = static_cast<std::int64_t>(first + k) * npe + a;
      if (b.enriched_node[slot] < 0) continue;
      const double psi = h.value - b.node_shift[slot];
      N[n++] = psi * s.N[a];
    }
  }
  return n;
}

void enriched_element_mass_and_load_weights(const EnrichedElementBatch& b, const EnrichedQuadrature& quad,
                                            double* mass, double* area_weights, double* mass_weights,
                                            Execution execution) {
  enriched_element_mass_and_load_weights(b, quad, nullptr, mass, area_weights, mass_weights, execution);
}

void enriched_element_mass_and_load_weights(const EnrichedElementBatch& b, const EnrichedQuadrature& quad,
                                            const TexelDerivativeTile* const* derivatives, double* mass,
                                            double* area_weights, double* mass_weights, Execution execution,
                                            double* basis_values) {
  const int W = b.width;
  const int npe = nodes_per_element(b.type);
  constexpr std::int64_t block = rest_integral_block_points;
  const std::int64_t first_point = quad.start[0], all_points = quad.start[b.count] - first_point;
  // Points evaluated before they are summed: all of them where the caller keeps the values,
  // else a bounded wave (values in a scratch array).
  const std::int64_t wave = basis_values ? std::max<std::int64_t>(all_points, 1) : 64 * block;
  std::vector<double> scratch, weights(static_cast<std::size_t>(std::min(wave, all_points)));
  if (!basis_values) scratch.resize(static_cast<std::size_t>(std::min(wave, all_points)) * W);
  std::vector<GramAccumulator> sums;
  sums.reserve(static_cast<std::size_t>(b.count));
  for (std::int64_t e = 0; e < b.count; ++e) {
    sums.emplace_back(enriched_basis_count(b, e));
    std::fill(area_weights + e * W, area_weights + (e + 1) * W, 0.0);
    std::fill(mass_weights + e * W, mass_weights + (e + 1) * W, 0.0);
  }
  // A wave's stretch of one element's points [begin, end) (at most one per element).
  struct Stretch {
    std::int64_t element, begin, end;
  };
  std::vector<Stretch> stretches;
  std::vector<std::pair<std::size_t, std::int64_t>> blocks;  // (stretch, its first point)
  std::int64_t e = 0, begin = first_point;
  while (e < b.count) {
    // The next wave: the points from (e, begin) on, up to `wave` of them.
    const std::int64_t wave_begin = begin;
    stretches.clear();
    blocks.clear();
    for (std::int64_t taken = 0; e < b.count && taken < wave;) {
      const std::int64_t end = std::min(quad.start[e + 1], begin + (wave - taken));
      stretches.push_back({e, begin, end});
      for (std::int64_t p = begin; p < end; p += block) blocks.push_back({stretches.size() - 1, p});
      taken += end - begin;
      begin = end;
      if (begin == quad.start[e + 1]) ++e;
    }
    // Point q's values: at basis_values + q W, or at its place in the wave's scratch.
    const auto values_of = [&](std::int64_t q) {
      return basis_values ? basis_values + q * W : scratch.data() + (q - wave_begin) * W;
    };
    // The values and weights of every point of the wave, in fixed blocks across threads.
    forall(
        static_cast<std::int64_t>(blocks.size()),
        [&](std::int64_t item) {
          const Stretch& s = stretches[blocks[item].first];
          const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[s.element]) * npe;
          EnrichedTexelCache cache;
          for (std::int64_t q = blocks[item].second; q < std::min(s.end, blocks[item].second + block); ++q) {
            const double* x = quad.points + 3 * q;
            ShapeValues shape;
            evaluate_shape(b.type, x[0], x[1], shape);
            enriched_shape_values(b, s.element, x[0], x[1], shape, cache, values_of(q), derivatives);
            weights[q - wave_begin] = x[2] * rest_area_factor(shape, nodes, b.positions);
          }
        },
        execution);
    // The two kernels' sums, each element's in point order (elements side by side).
    forall_dynamic(
        static_cast<std::int64_t>(stretches.size()),
        [&](std::int64_t k) {
          const Stretch& s = stretches[k];
          const int n = enriched_basis_count(b, s.element);
          const ShellSection& sec = b.sections[b.element[s.element]];
          const double rho_h = sec.density * sec.thickness;
          double* area = area_weights + s.element * W;
          double* m = mass_weights + s.element * W;
          GramAccumulator& M = sums[s.element];
          for (std::int64_t q = s.begin; q < s.end; ++q) {
            const double* N = values_of(q);
            const double w = weights[q - wave_begin];
            const double root = std::sqrt(w * rho_h);
            double* row = M.next();
            for (int a = 0; a < n; ++a) row[a] = root * N[a];
            M.push();
            for (int a = 0; a < n; ++a) {
              area[a] += w * N[a];
              m[a] += w * rho_h * N[a];
            }
          }
        },
        execution);
  }
  forall(
      b.count,
      [&](std::int64_t x) {
        const int n = enriched_basis_count(b, x);
        GramAccumulator& M = sums[x];
        M.flush();
        double* out = mass + x * W * W;
        for (int a = 0; a < W; ++a)
          for (int c = 0; c < W; ++c) out[a * W + c] = a < n && c < n ? M(a, c) : 0.0;
      },
      execution);
}

}  // namespace dgtex::kernels

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
  constexpr std::int64_t span = 64 * block;  // points evaluated before they are summed
  std::vector<double> values, weights;
  for (std::int64_t e = 0; e < b.count; ++e) {
    const int n = enriched_basis_count(b, e);
    const ShellSection& sec = b.sections[b.element[e]];
    const double rho_h = sec.density * sec.thickness;
    const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
    double* area = area_weights + e * W;
    double* m = mass_weights + e * W;
    for (int a = 0; a < W; ++a) area[a] = m[a] = 0;
    GramAccumulator M(n);
    for (std::int64_t begin = quad.start[e]; begin < quad.start[e + 1]; begin += span) {
      const std::int64_t count = std::min(span, quad.start[e + 1] - begin);
      // The span's values: in the caller's array (W slots a point) if it keeps them.
      const int stride = basis_values ? W : n;
      if (!basis_values) values.resize(static_cast<std::size_t>(count) * n);
      double* span_values = basis_values ? basis_values + begin * W : values.data();
      weights.resize(static_cast<std::size_t>(count));
      forall(
          (count + block - 1) / block,
          [&](std::int64_t item) {
            EnrichedTexelCache cache;
            for (std::int64_t p = item * block; p < std::min(count, (item + 1) * block); ++p) {
              const double* q = quad.points + 3 * (begin + p);
              ShapeValues s;
              evaluate_shape(b.type, q[0], q[1], s);
              enriched_shape_values(b, e, q[0], q[1], s, cache, span_values + p * stride, derivatives);
              weights[p] = q[2] * rest_area_factor(s, nodes, b.positions);
            }
          },
          execution);
      // The two kernels' sums, in point order.
      for (std::int64_t p = 0; p < count; ++p) {
        const double* N = span_values + p * stride;
        const double w = weights[p];
        const double s = std::sqrt(w * rho_h);
        double* row = M.next();
        for (int a = 0; a < n; ++a) row[a] = s * N[a];
        M.push();
        for (int a = 0; a < n; ++a) {
          area[a] += w * N[a];
          m[a] += w * rho_h * N[a];
        }
      }
    }
    M.flush();
    double* out = mass + e * W * W;
    for (int a = 0; a < W; ++a)
      for (int c = 0; c < W; ++c) out[a * W + c] = a < n && c < n ? M(a, c) : 0.0;
  }
}

}  // namespace dgtex::kernels

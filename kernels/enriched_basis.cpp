#include "dgtex/kernels/enriched_basis.h"

#include <algorithm>
#include <cmath>

#include "dgtex/kernels/texel_grid.h"
#include "texel_difference_rule.h"

namespace dgtex::kernels {
namespace {

// Continuous texel coordinates of a parametric point (texel corners at integers).
inline void texel_coordinates(ElementType type, int t, double xi1, double xi2, double x[2]) {
  if (type == ElementType::quad8) {
    x[0] = 0.5 * (xi1 + 1) * t;
    x[1] = 0.5 * (xi2 + 1) * t;
  } else {
    x[0] = xi1 * t;
    x[1] = xi2 * t;
  }
}

// Whether texel (i, j) and its neighbour (i + di, j + dj) (one unit step) are connected
// (no wall or crease between them).
inline bool reachable(ElementType type, int t, const std::uint8_t* flags, int i, int j, int di, int dj) {
  const int ni = i + di, nj = j + dj;
  if (!texel_in_domain(type, t, flags, ni, nj)) return false;
  if (di == 1) return !(flags[j * t + i] & stencil_barrier_east);
  if (di == -1) return !(flags[nj * t + ni] & stencil_barrier_east);
  if (dj == 1) return !(flags[j * t + i] & stencil_barrier_north);
  return !(flags[nj * t + ni] & stencil_barrier_north);
}

// First and second difference of the texel values along one axis (rule of the header).
void axis_differences(ElementType type, int t, const TextureView& tex, int i, int j, int axis, double& g, double& s) {
  detail::axis_difference_rule(
      i, j, axis == 0 ? 1 : 0, axis == 0 ? 0 : 1, [&](int a, int b) { return tex.values[b * t + a]; },
      [&](int a, int b, int da, int db) { return reachable(type, t, tex.flags, a, b, da, db); }, g, s);
}

// First difference along `axis` of the other axis' gradient (for the mixed term).
double mixed_part(ElementType type, int t, const TextureView& tex, int i, int j, int axis, double own_gradient) {
  const int di = axis == 0 ? 1 : 0, dj = axis == 0 ? 0 : 1;
  const int other = 1 - axis;
  const bool plus = reachable(type, t, tex.flags, i, j, di, dj);
  const bool minus = reachable(type, t, tex.flags, i, j, -di, -dj);
  double gp = 0, gm = 0, unused = 0;
  if (plus) axis_differences(type, t, tex, i + di, j + dj, other, gp, unused);
  if (minus) axis_differences(type, t, tex, i - di, j - dj, other, gm, unused);
  return detail::mixed_difference_rule(plus, minus, gp, gm, own_gradient);
}

}  // namespace

double texel_size(ElementType type, int resolution) {
  return (type == ElementType::quad8 ? 2.0 : 1.0) / resolution;
}

void texel_centre(ElementType type, int resolution, int i, int j, double xi[2]) {
  const double h = texel_size(type, resolution);
  const double origin = type == ElementType::quad8 ? -1.0 : 0.0;
  xi[0] = origin + (i + 0.5) * h;
  xi[1] = origin + (j + 0.5) * h;
}

bool texel_in_domain(ElementType type, int t, const std::uint8_t* flags, int i, int j) {
  if (i < 0 || j < 0 || i >= t || j >= t) return false;
  if (type == ElementType::tri6 && i + j > t - 1) return false;
  return !(flags[j * t + i] & inactive);
}

void containing_texel(ElementType type, int t, double xi1, double xi2, int& i, int& j) {
  double x[2];
  texel_coordinates(type, t, xi1, xi2, x);
  i = std::clamp(static_cast<int>(std::floor(x[0])), 0, t - 1);
  j = std::clamp(static_cast<int>(std::floor(x[1])), 0, t - 1);
  if (type == ElementType::tri6 && i + j > t - 1) j = t - 1 - i;
}

void texel_derivatives(ElementType type, int t, const TextureView& tex, int i, int j, TexelDerivatives& out) {
  out.value = tex.values[j * t + i];
  axis_differences(type, t, tex, i, j, 0, out.g[0], out.s[0]);
  axis_differences(type, t, tex, i, j, 1, out.g[1], out.s[1]);
  // S_12 = 1/2 (d/dx2 g_1 + d/dx1 g_2).
  out.s[2] = 0.5 * (mixed_part(type, t, tex, i, j, 1, out.g[0]) + mixed_part(type, t, tex, i, j, 0, out.g[1]));
}

void sample_texture_in_texel(ElementType type, int t, const TextureView& tex, int i, int j, double xi1, double xi2,
                             TextureSample& out) {
  TexelDerivatives fd;
  texel_derivatives(type, t, tex, i, j, fd);
  sample_texel_polynomial(type, t, fd, i, j, xi1, xi2, out);
}

void sample_texel_polynomial(ElementType type, int t, const TexelDerivatives& fd, int i, int j, double xi1, double xi2,
                             TextureSample& out) {
  double x[2];
  texel_coordinates(type, t, xi1, xi2, x);
  const double d1 = x[0] - (i + 0.5), d2 = x[1] - (j + 0.5);
  const double inv_h = 1.0 / texel_size(type, t);  // texel units per parametric unit
  out.value = fd.value + fd.g[0] * d1 + fd.g[1] * d2 + 0.5 * (fd.s[0] * d1 * d1 + fd.s[1] * d2 * d2) + fd.s[2] * d1 * d2;
  out.d[0] = (fd.g[0] + fd.s[0] * d1 + fd.s[2] * d2) * inv_h;
  out.d[1] = (fd.g[1] + fd.s[2] * d1 + fd.s[1] * d2) * inv_h;
  for (int k = 0; k < 3; ++k) out.d2[k] = fd.s[k] * inv_h * inv_h;
}

void sample_texture(ElementType type, int t, const TextureView& tex, double xi1, double xi2, TextureSample& out) {
  int i = 0, j = 0;
  containing_texel(type, t, xi1, xi2, i, j);
  sample_texture_in_texel(type, t, tex, i, j, xi1, xi2, out);
}

int enriched_basis_count(const EnrichedElementBatch& b, std::int64_t e) {
  const int npe = nodes_per_element(b.type);
  int n = npe;
  for (int k = b.enrichment_start[e]; k < b.enrichment_start[e + 1]; ++k)
    for (int a = 0; a < npe; ++a) n += b.enriched_node[k * npe + a] >= 0;
  return n;
}

void enriched_global_nodes(const EnrichedElementBatch& b, std::int64_t e, int* out) {
  const int npe = nodes_per_element(b.type);
  const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
  int n = 0;
  for (int a = 0; a < npe; ++a) out[n++] = nodes[a];
  for (int k = b.enrichment_start[e]; k < b.enrichment_start[e + 1]; ++k)
    for (int a = 0; a < npe; ++a)
      if (b.enriched_node[k * npe + a] >= 0) out[n++] = b.enriched_node[k * npe + a];
  for (; n < b.width; ++n) out[n] = -1;
}

void evaluate_enriched_shape(const EnrichedElementBatch& b, std::int64_t e, double xi1, double xi2,
                             const ShapeValues& s, EnrichedShapeValues& out) {
  const int npe = s.count;
  for (int a = 0; a < npe; ++a) {
    out.N[a] = s.N[a];
    for (int c = 0; c < 2; ++c) out.dN[a][c] = s.dN[a][c];
    for (int c = 0; c < 3; ++c) out.d2N[a][c] = s.d2N[a][c];
  }
  int n = npe;
  int ti = 0, tj = 0;
  containing_texel(b.type, b.resolution, xi1, xi2, ti, tj);
  for (int k = b.enrichment_start[e]; k < b.enrichment_start[e + 1]; ++k) {
    TextureSample h;
    sample_texture_in_texel(b.type, b.resolution, b.textures[k], ti, tj, xi1, xi2, h);
    for (int a = 0; a < npe; ++a) {
      if (b.enriched_node[k * npe + a] < 0) continue;
      // Product rule for (H - H(xi^a)) N^a.
      const double psi = h.value - b.node_shift[k * npe + a];
      const double* dN = s.dN[a];
      const double* d2N = s.d2N[a];
      out.N[n] = psi * s.N[a];
      out.dN[n][0] = h.d[0] * s.N[a] + psi * dN[0];
      out.dN[n][1] = h.d[1] * s.N[a] + psi * dN[1];
      out.d2N[n][0] = h.d2[0] * s.N[a] + 2 * h.d[0] * dN[0] + psi * d2N[0];
      out.d2N[n][1] = h.d2[1] * s.N[a] + 2 * h.d[1] * dN[1] + psi * d2N[1];
      out.d2N[n][2] = h.d2[2] * s.N[a] + h.d[0] * dN[1] + h.d[1] * dN[0] + psi * d2N[2];
      ++n;
    }
  }
  out.count = n;
}

}  // namespace dgtex::kernels

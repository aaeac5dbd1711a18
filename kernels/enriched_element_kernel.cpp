#include "dgtex/kernels/enriched_element_kernel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/symmetric_accumulator.h"
#include "dgtex/kernels/vec3.h"

namespace dgtex::kernels {
namespace {

// Corotational rest strain of the standard functions, B (X0 - R^T X0) (enriched DOFs rest
// at 0): membrane rows into strain[0..2], bending rows into strain[3..5] (added).
void rest_corotation_strain(const double* positions, const int* nodes, int npe, const double* R, const double* Bm,
                            const double* Bb, double strain[6]) {
  for (int a = 0; a < npe; ++a) {
    const double* x = positions + 3 * static_cast<std::int64_t>(nodes[a]);
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        strain[r] += Bm[9 * a + r * 3 + c] * d[c];
        strain[3 + r] += Bb[9 * a + r * 3 + c] * d[c];
      }
  }
}

// Everything about one quadrature point of an enriched element.
struct EnrichedPoint {
  ShapeValues standard;
  EnrichedShapeValues shape;
  RestPoint rest;
  double weight;  // reference weight times j0
};

void evaluate_point(const EnrichedElementBatch& b, std::int64_t e, const double* q, EnrichedPoint& p) {
  const int npe = nodes_per_element(b.type);
  evaluate_shape(b.type, q[0], q[1], p.standard);
  evaluate_enriched_shape(b, e, q[0], q[1], p.standard, p.shape);
  evaluate_rest_point(p.standard, b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe, b.positions, p.rest);
  p.weight = q[2] * p.rest.j0;
}

// Voigt rows v (3 components) -> L^T v with C = L L^T the plane-stress matrix of
// shell_point.h: C = [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]], so v^T C v = |L^T v|^2.
inline void half_constitutive(double nu, double scale, const double v[3], double out[3]) {
  out[0] = scale * (v[0] + nu * v[1]);
  out[1] = scale * std::sqrt(1 - nu * nu) * v[1];
  out[2] = scale * std::sqrt(0.5 * (1 - nu)) * v[2];
}

// The strain rows of n basis functions scaled by the square root of the constitutive
// matrix (sm, sb: membrane and bending weights): row[0..2] membrane, row[3..5] bending,
// 3 columns (x, y, z) per function, so that sum over rows of row^T row is B^T D B w.
void scaled_strain_rows(int n, const double* Bm, const double* Bb, double nu, double sm, double sb, double* const row[6]) {
  for (int a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c) {
      const double vm[3] = {Bm[9 * a + c], Bm[9 * a + 3 + c], Bm[9 * a + 6 + c]};
      const double vb[3] = {Bb[9 * a + c], Bb[9 * a + 3 + c], Bb[9 * a + 6 + c]};
      double om[3], ob[3];
      half_constitutive(nu, sm, vm, om);
      half_constitutive(nu, sb, vb, ob);
      for (int k = 0; k < 3; ++k) row[k][3 * a + c] = om[k], row[3 + k][3 * a + c] = ob[k];
    }
}

void element_stiffness(const EnrichedElementBatch& b, const EnrichedQuadrature& quad, std::int64_t e,
                       const double* rotations, double* blocks, double* forces) {
  const int npe = nodes_per_element(b.type);
  const int W = b.width;
  const int n = enriched_basis_count(b, e);
  const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
  const ShellSection& sec = b.sections[b.element[e]];
  const double nu = sec.poisson_ratio;
  const double dn = membrane_rigidity(sec.youngs_modulus, nu, sec.thickness);
  const double dm = bending_rigidity(sec.youngs_modulus, nu, sec.thickness);

  // K = sum_q S_q^T S_q with S_q = sqrt(w) [L^T Bm sqrt(dn); L^T Bb sqrt(dm)] (6 x 3n).
  SymmetricAccumulator K(3 * n);
  std::vector<double> f(3 * n, 0.0);
  std::vector<double> Bm(9 * n), Bb(9 * n);
  EnrichedPoint p;
  for (std::int64_t q = quad.start[e]; q < quad.start[e + 1]; ++q) {
    evaluate_point(b, e, quad.points + 3 * q, p);
    double e1[3], e2[3];
    frame_along(p.rest, p.rest.a1, e1, e2);
    for (int a = 0; a < n; ++a) {
      membrane_rows(p.rest, e1, e2, p.shape.dN[a], &Bm[9 * a]);
      bending_rows(p.rest, e1, e2, p.shape.dN[a], p.shape.d2N[a], &Bb[9 * a]);
    }
    const double* R = rotations ? rotations + 9 * q : nullptr;
    double strain[6] = {0, 0, 0, 0, 0, 0};  // B (X0 - R^T X0); enriched X0 = 0
    if (R && forces) rest_corotation_strain(b.positions, nodes, npe, R, Bm.data(), Bb.data(), strain);
    if (R)
      for (int a = 0; a < n; ++a) rotate_rows(&Bm[9 * a], R), rotate_rows(&Bb[9 * a], R);
    const double sm = std::sqrt(p.weight * dn), sb = std::sqrt(p.weight * dm);
    double rows[6][3 * max_enriched_basis];
    double* const row_starts[6] = {rows[0], rows[1], rows[2], rows[3], rows[4], rows[5]};
    scaled_strain_rows(n, Bm.data(), Bb.data(), nu, sm, sb, row_starts);
    for (int r = 0; r < 6; ++r) {
      double* row = K.next();
      for (int i = 0; i < 3 * n; ++i) row[i] = rows[r][i];
      K.push();
    }
    if (R && forces) {
      double s[6];
      half_constitutive(nu, sm, strain, s);
      half_constitutive(nu, sb, strain + 3, s + 3);
      for (int i = 0; i < 3 * n; ++i)
        for (int r = 0; r < 6; ++r) f[i] += rows[r][i] * s[r];
    }
  }
  K.flush();
  double* out = blocks + e * W * W * 9;
  for (int a = 0; a < W; ++a)
    for (int c = 0; c < W; ++c)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          out[(a * W + c) * 9 + i * 3 + j] = a < n && c < n ? K(3 * a + i, 3 * c + j) : 0.0;
  if (forces)
    for (int i = 0; i < 3 * W; ++i) forces[e * W * 3 + i] = i < 3 * n ? f[i] : 0.0;
}

// --- Fast form ---------------------------------------------------------------------------

// Fixed work items: (element, first point, end point), chunks of enriched_chunk_points.
struct Chunk {
  std::int64_t element, begin, end;
};

std::vector<Chunk> make_chunks(const EnrichedElementBatch& b, const EnrichedQuadrature& quad) {
  std::vector<Chunk> chunks;
  for (std::int64_t e = 0; e < b.count; ++e) {
    std::int64_t p = quad.start[e];
    do {
      const std::int64_t end = std::min(quad.start[e + 1], p + enriched_chunk_points);
      chunks.push_back({e, p, end});
      p = end;
    } while (p < quad.start[e + 1]);
  }
  return chunks;
}

// Per element: local basis slot and node shift of each (texture, node).
struct ElementLayout {
  int npe = 0, n = 0, first = 0, count = 0;
  int slot[max_enrichments_per_element][max_element_nodes];
  double shift[max_enrichments_per_element][max_element_nodes];

  ElementLayout(const EnrichedElementBatch& b, std::int64_t e) {
    npe = nodes_per_element(b.type);
    first = b.enrichment_start[e];
    count = b.enrichment_start[e + 1] - first;
    n = npe;
    for (int k = 0; k < count; ++k)
      for (int a = 0; a < npe; ++a) {
        const bool enriched = b.enriched_node[(first + k) * npe + a] >= 0;
        slot[k][a] = enriched ? n++ : -1;
        shift[k][a] = b.node_shift[(first + k) * npe + a];
      }
  }
};

// The textures' polynomials of the texel holding the current point (consecutive points
// mostly share a texel), and whether each is locally constant there.
struct TexelCache {
  int i = -1, j = -1;
  TexelDerivatives fd[max_enrichments_per_element];
  bool flat[max_enrichments_per_element];

  void at(const EnrichedElementBatch& b, const ElementLayout& L, double xi1, double xi2, int& ti, int& tj) {
    containing_texel(b.type, b.resolution, xi1, xi2, ti, tj);
    if (ti == i && tj == j) return;
    i = ti, j = tj;
    const double inv_h = 1.0 / texel_size(b.type, b.resolution);
    const double tol_g = enriched_flat_tolerance / inv_h, tol_s = tol_g / inv_h;
    for (int k = 0; k < L.count; ++k) {
      texel_derivatives(b.type, b.resolution, b.textures[L.first + k], i, j, fd[k]);
      const TexelDerivatives& d = fd[k];
      // |g| inv_h <= tol and |S| inv_h^2 <= tol over the texel (parametric units).
      flat[k] = std::abs(d.g[0]) <= tol_g && std::abs(d.g[1]) <= tol_g && std::abs(d.s[0]) <= tol_s &&
                std::abs(d.s[1]) <= tol_s && std::abs(d.s[2]) <= tol_s;
    }
  }
};

// Derivatives (dN, d2N) of the enriched function (H - shift) N^a from a texture sample.
inline void product_rule(const TextureSample& h, double shift, const ShapeValues& s, int a, double dN[2],
                         double d2N[3]) {
  const double psi = h.value - shift;
  const double* dn = s.dN[a];
  const double* d2n = s.d2N[a];
  dN[0] = h.d[0] * s.N[a] + psi * dn[0];
  dN[1] = h.d[1] * s.N[a] + psi * dn[1];
  d2N[0] = h.d2[0] * s.N[a] + 2 * h.d[0] * dn[0] + psi * d2n[0];
  d2N[1] = h.d2[1] * s.N[a] + 2 * h.d[1] * dn[1] + psi * d2n[1];
  d2N[2] = h.d2[2] * s.N[a] + h.d[0] * dn[1] + h.d[1] * dn[0] + psi * d2n[2];
}

// Points with the same varying textures (mask) and the same constant values: G = sum of
// S^T S over the group's reduced basis (standard functions, then the varying textures'
// enriched ones), upper triangle; g = sum of S^T s (corrective forces).
struct Group {
  std::uint32_t varying = 0;
  double value[max_enrichments_per_element];
  int m = 0;  // reduced basis functions
  std::vector<double> G, g;

  bool matches(std::uint32_t mask, const double* values, int count) const {
    if (mask != varying) return false;
    for (int k = 0; k < count; ++k)
      if (!(mask >> k & 1u) && !(std::abs(values[k] - value[k]) <= enriched_flat_tolerance)) return false;
    return true;
  }
};

// Sums the chunk's points into per-group matrices, then maps the groups onto the element's
// basis: Kc (n x n blocks, a <= c filled) and fc (3n).
void chunk_stiffness(const EnrichedElementBatch& b, const EnrichedQuadrature& quad, const Chunk& chunk,
                     const double* rotations, bool want_forces, std::vector<double>& Kc, std::vector<double>& fc) {
  const std::int64_t e = chunk.element;
  const ElementLayout L(b, e);
  const int npe = L.npe, n = L.n;
  const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
  const ShellSection& sec = b.sections[b.element[e]];
  const double nu = sec.poisson_ratio;
  const double dn = membrane_rigidity(sec.youngs_modulus, nu, sec.thickness);
  const double dm = bending_rigidity(sec.youngs_modulus, nu, sec.thickness);

  std::vector<Group> groups;
  int last = -1;
  TexelCache cache;
  ShapeValues s;
  RestPoint rest;
  double Bm[max_enriched_basis * 9], Bb[max_enriched_basis * 9];
  double values[max_enrichments_per_element];
  TextureSample samples[max_enrichments_per_element];  // constructed once: it zero-fills
  static thread_local std::vector<double> rows;
  rows.resize(6 * 3 * static_cast<std::size_t>(max_enriched_basis));
  for (std::int64_t q = chunk.begin; q < chunk.end; ++q) {
    const double* pt = quad.points + 3 * q;
    evaluate_shape(b.type, pt[0], pt[1], s);
    evaluate_rest_point(s, nodes, b.positions, rest);
    const double weight = pt[2] * rest.j0;
    int ti, tj;
    cache.at(b, L, pt[0], pt[1], ti, tj);
    std::uint32_t mask = 0;
    for (int k = 0; k < L.count; ++k) {
      sample_texel_polynomial(b.type, b.resolution, cache.fd[k], ti, tj, pt[0], pt[1], samples[k]);
      values[k] = samples[k].value;
      if (!cache.flat[k]) mask |= 1u << k;
    }
    int g = -1;
    if (last >= 0 && groups[last].matches(mask, values, L.count)) g = last;
    for (int c = 0; g < 0 && c < static_cast<int>(groups.size()); ++c)
      if (groups[c].matches(mask, values, L.count)) g = c;
    if (g < 0) {
      Group fresh;
      fresh.varying = mask;
      for (int k = 0; k < L.count; ++k) fresh.value[k] = values[k];
      fresh.m = npe;
      for (int k = 0; k < L.count; ++k)
        if (mask >> k & 1u)
          for (int a = 0; a < npe; ++a) fresh.m += L.slot[k][a] >= 0;
      fresh.G.assign(static_cast<std::size_t>(9) * fresh.m * fresh.m, 0.0);
      if (want_forces) fresh.g.assign(3 * static_cast<std::size_t>(fresh.m), 0.0);
      groups.push_back(std::move(fresh));
      g = static_cast<int>(groups.size()) - 1;
    }
    last = g;
    Group& group = groups[g];
    const int m = group.m, M = 3 * m;

    // Strain rows of the reduced basis.
    double e1[3], e2[3];
    frame_along(rest, rest.a1, e1, e2);
    for (int a = 0; a < npe; ++a) {
      membrane_rows(rest, e1, e2, s.dN[a], &Bm[9 * a]);
      bending_rows(rest, e1, e2, s.dN[a], s.d2N[a], &Bb[9 * a]);
    }
    int r = npe;
    for (int k = 0; k < L.count; ++k) {
      if (!(mask >> k & 1u)) continue;
      for (int a = 0; a < npe; ++a) {
        if (L.slot[k][a] < 0) continue;
        double dN[2], d2N[3];
        product_rule(samples[k], L.shift[k][a], s, a, dN, d2N);
        membrane_rows(rest, e1, e2, dN, &Bm[9 * r]);
        bending_rows(rest, e1, e2, dN, d2N, &Bb[9 * r]);
        ++r;
      }
    }
    const double* R = rotations ? rotations + 9 * q : nullptr;
    double strain[6] = {0, 0, 0, 0, 0, 0};  // B (X0 - R^T X0); enriched X0 = 0
    if (R && want_forces) rest_corotation_strain(b.positions, nodes, npe, R, Bm, Bb, strain);
    if (R)
      for (int a = 0; a < m; ++a) rotate_rows(&Bm[9 * a], R), rotate_rows(&Bb[9 * a], R);
    const double sm = std::sqrt(weight * dn), sb = std::sqrt(weight * dm);
    double* row[6];
    for (int k = 0; k < 6; ++k) row[k] = rows.data() + static_cast<std::size_t>(k) * M;
    scaled_strain_rows(m, Bm, Bb, nu, sm, sb, row);
    // G += S^T S (upper triangle), one rank-6 update.
    double* G = group.G.data();
    for (int i = 0; i < M; ++i) {
      const double r0 = row[0][i], r1 = row[1][i], r2 = row[2][i], r3 = row[3][i], r4 = row[4][i], r5 = row[5][i];
      double* out = G + static_cast<std::size_t>(i) * M;
      for (int j = i; j < M; ++j)
        out[j] += r0 * row[0][j] + r1 * row[1][j] + r2 * row[2][j] + r3 * row[3][j] + r4 * row[4][j] + r5 * row[5][j];
    }
    if (R && want_forces) {
      double sv[6];
      half_constitutive(nu, sm, strain, sv);
      half_constitutive(nu, sb, strain + 3, sv + 3);
      for (int i = 0; i < M; ++i)
        for (int k = 0; k < 6; ++k) group.g[i] += row[k][i] * sv[k];
    }
  }

  // K += T^T G T per group: basis function i of the element is reduced function red[i]
  // times scale[i] (1, or H_k - H_k(xi^a) for a constant texture k: a multiple of N^a).
  Kc.assign(static_cast<std::size_t>(9) * n * n, 0.0);
  fc.assign(want_forces ? 3 * static_cast<std::size_t>(n) : 0, 0.0);
  int red[max_enriched_basis];
  double scale[max_enriched_basis];
  for (const Group& group : groups) {
    for (int a = 0; a < npe; ++a) red[a] = a, scale[a] = 1;
    int r = npe;
    for (int k = 0; k < L.count; ++k)
      for (int a = 0; a < npe; ++a) {
        const int i = L.slot[k][a];
        if (i < 0) continue;
        if (group.varying >> k & 1u) red[i] = r++, scale[i] = 1;
        else red[i] = a, scale[i] = group.value[k] - L.shift[k][a];
      }
    const int M = 3 * group.m;
    const double* G = group.G.data();
    for (int i = 0; i < n; ++i) {
      if (scale[i] == 0) continue;
      for (int j = i; j < n; ++j) {
        if (scale[j] == 0) continue;
        const double f = scale[i] * scale[j];
        double* blk = Kc.data() + (static_cast<std::size_t>(i) * n + j) * 9;
        for (int c = 0; c < 3; ++c)
          for (int d = 0; d < 3; ++d) {
            const int x = 3 * red[i] + c, y = 3 * red[j] + d;
            blk[c * 3 + d] += f * (x <= y ? G[static_cast<std::size_t>(x) * M + y] : G[static_cast<std::size_t>(y) * M + x]);
          }
      }
      if (want_forces)
        for (int c = 0; c < 3; ++c) fc[3 * i + c] += scale[i] * group.g[3 * red[i] + c];
    }
  }
}

}  // namespace

void enriched_element_stiffness_reference(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                          const double* rotations, double* blocks, double* forces) {
  for (std::int64_t e = 0; e < batch.count; ++e) element_stiffness(batch, quadrature, e, rotations, blocks, forces);
}

void enriched_element_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                const double* rotations, double* blocks, double* forces, Execution execution) {
  const std::vector<Chunk> chunks = make_chunks(batch, quadrature);
  const bool want_forces = rotations && forces;
  std::vector<std::vector<double>> Kc(chunks.size()), fc(chunks.size());
  forall(
      static_cast<std::int64_t>(chunks.size()),
      [&](std::int64_t c) { chunk_stiffness(batch, quadrature, chunks[c], rotations, want_forces, Kc[c], fc[c]); },
      execution);
  // Per element: its chunks summed in order, then the padded symmetric layout.
  std::vector<std::int64_t> first_chunk(static_cast<std::size_t>(batch.count) + 1, 0);
  for (const Chunk& c : chunks) ++first_chunk[c.element + 1];
  for (std::int64_t e = 0; e < batch.count; ++e) first_chunk[e + 1] += first_chunk[e];
  const int W = batch.width;
  forall(
      batch.count,
      [&](std::int64_t e) {
        const int n = enriched_basis_count(batch, e);
        std::vector<double>& K = Kc[first_chunk[e]];
        std::vector<double>& f = fc[first_chunk[e]];
        for (std::int64_t c = first_chunk[e] + 1; c < first_chunk[e + 1]; ++c) {
          for (std::size_t i = 0; i < K.size(); ++i) K[i] += Kc[c][i];
          for (std::size_t i = 0; i < f.size(); ++i) f[i] += fc[c][i];
        }
        double* out = blocks + e * W * W * 9;
        for (int a = 0; a < W; ++a)
          for (int c = 0; c < W; ++c)
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) {
                double v = 0;
                if (a < n && c < n)
                  v = a <= c ? K[(static_cast<std::size_t>(a) * n + c) * 9 + i * 3 + j]
                             : K[(static_cast<std::size_t>(c) * n + a) * 9 + j * 3 + i];
                out[(a * W + c) * 9 + i * 3 + j] = v;
              }
        if (forces)
          for (int i = 0; i < 3 * W; ++i) forces[e * W * 3 + i] = want_forces && i < 3 * n ? f[i] : 0.0;
      },
      execution);
}

void enriched_element_deformation_gradients(const EnrichedElementBatch& b, const EnrichedQuadrature& quad,
                                            const double* current, double* F, Execution execution) {
  // Per point: the current tangents from the whole basis (the rest ones have no enriched
  // share). Chunks of points, the texture polynomials cached per texel; each point writes
  // only its own F, so any execution gives the same result.
  const std::vector<Chunk> chunks = make_chunks(b, quad);
  forall(
      static_cast<std::int64_t>(chunks.size()),
      [&](std::int64_t c) {
        const Chunk& chunk = chunks[c];
        const std::int64_t e = chunk.element;
        const ElementLayout L(b, e);
        const int npe = L.npe;
        const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
        int global[max_enriched_basis];
        enriched_global_nodes(b, e, global);
        TexelCache cache;
        ShapeValues s;
        RestPoint rest;
        for (std::int64_t q = chunk.begin; q < chunk.end; ++q) {
          const double* pt = quad.points + 3 * q;
          evaluate_shape(b.type, pt[0], pt[1], s);
          evaluate_rest_point(s, nodes, b.positions, rest);
          int ti, tj;
          cache.at(b, L, pt[0], pt[1], ti, tj);
          double a1[3] = {0, 0, 0}, a2[3] = {0, 0, 0};
          for (int a = 0; a < npe; ++a) {
            const double* x = current + 3 * static_cast<std::int64_t>(global[a]);
            for (int k = 0; k < 3; ++k) a1[k] += s.dN[a][0] * x[k], a2[k] += s.dN[a][1] * x[k];
          }
          for (int k = 0; k < L.count; ++k) {
            TextureSample h;
            sample_texel_polynomial(b.type, b.resolution, cache.fd[k], ti, tj, pt[0], pt[1], h);
            for (int a = 0; a < npe; ++a) {
              if (L.slot[k][a] < 0) continue;
              const double psi = h.value - L.shift[k][a];
              const double d0 = h.d[0] * s.N[a] + psi * s.dN[a][0], d1 = h.d[1] * s.N[a] + psi * s.dN[a][1];
              const double* x = current + 3 * static_cast<std::int64_t>(global[L.slot[k][a]]);
              for (int i = 0; i < 3; ++i) a1[i] += d0 * x[i], a2[i] += d1 * x[i];
            }
          }
          double t[3];
          cross3(a1, a2, t);
          normalize3(t);
          surface_deformation_gradient(rest.a1, rest.a2, rest.t0, a1, a2, t, F + 9 * q);
        }
      },
      execution);
}

void enriched_element_mass(const EnrichedElementBatch& b, const EnrichedQuadrature& quad, double* mass,
                           Execution execution) {
  const int W = b.width;
  forall(
      b.count,
      [&](std::int64_t e) {
        const int n = enriched_basis_count(b, e);
        const ShellSection& sec = b.sections[b.element[e]];
        const double rho_h = sec.density * sec.thickness;
        SymmetricAccumulator M(n);
        EnrichedPoint p;
        for (std::int64_t q = quad.start[e]; q < quad.start[e + 1]; ++q) {
          evaluate_point(b, e, quad.points + 3 * q, p);
          const double s = std::sqrt(p.weight * rho_h);
          double* row = M.next();
          for (int a = 0; a < n; ++a) row[a] = s * p.shape.N[a];
          M.push();
        }
        M.flush();
        double* out = mass + e * W * W;
        for (int a = 0; a < W; ++a)
          for (int c = 0; c < W; ++c) out[a * W + c] = a < n && c < n ? M(a, c) : 0.0;
      },
      execution);
}

void enriched_element_load_weights(const EnrichedElementBatch& b, const EnrichedQuadrature& quad,
                                   double* area_weights, double* mass_weights, Execution execution) {
  const int W = b.width;
  forall(
      b.count,
      [&](std::int64_t e) {
        const ShellSection& sec = b.sections[b.element[e]];
        const double rho_h = sec.density * sec.thickness;
        double* area = area_weights + e * W;
        double* m = mass_weights + e * W;
        for (int a = 0; a < W; ++a) area[a] = m[a] = 0;
        EnrichedPoint p;
        for (std::int64_t q = quad.start[e]; q < quad.start[e + 1]; ++q) {
          evaluate_point(b, e, quad.points + 3 * q, p);
          for (int a = 0; a < p.shape.count; ++a) {
            area[a] += p.weight * p.shape.N[a];
            m[a] += p.weight * rho_h * p.shape.N[a];
          }
        }
      },
      execution);
}

}  // namespace dgtex::kernels

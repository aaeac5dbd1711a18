#include "dgtex/kernels/enriched_element_kernel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "dgtex/kernels/gram_accumulation.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/symmetric_accumulator.h"
#include "dgtex/kernels/texel_derivative_tile.h"
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

// Fixed work items: (element, first point, end point). Each element's points are split
// into equal chunks of at least enriched_chunk_points, at most enriched_chunks_per_element
// of them: the split depends only on the quadrature, never on the thread count. With
// `points` set, the item is the listed points points[begin..end) instead of a range.
struct Chunk {
  std::int64_t element, begin, end;
  const std::int64_t* points = nullptr;

  std::int64_t point(std::int64_t k) const { return points ? points[k] : k; }
};

std::vector<Chunk> make_chunks(const EnrichedElementBatch& b, const EnrichedQuadrature& quad) {
  std::vector<Chunk> chunks;
  for (std::int64_t e = 0; e < b.count; ++e) {
    const std::int64_t first = quad.start[e], points = quad.start[e + 1] - first;
    const std::int64_t count = std::clamp<std::int64_t>((points + enriched_chunk_points - 1) / enriched_chunk_points, 1,
                                                        enriched_chunks_per_element);
    for (std::int64_t c = 0; c < count; ++c)
      chunks.push_back({e, first + points * c / count, first + points * (c + 1) / count});
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
      const TextureView& texture = b.textures[L.first + k];
      const TexelDerivativeTile* tile = b.derivatives ? b.derivatives[L.first + k] : nullptr;
      if (tile && texel_in_domain(b.type, b.resolution, texture.flags, i, j)) tile->at(i, j, fd[k]);
      else texel_derivatives(b.type, b.resolution, texture, i, j, fd[k]);
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

// Per-point factors of the strain rows. Membrane rows of a function lie in the tangent
// plane (e1, e2) and bending rows along t0 (the rest bending strain of report eq. 4 is
// rho_ab = -(N,ab - Gamma^c_ab N,c) t0: the normal change dt is tangential and phi0,ab
// . dt picks the Christoffel symbols Gamma^c_ab = phi0,ab . phi0^c), so a function's six
// rows are five numbers times the point's frame: the same rows as membrane_rows and
// bending_rows (shell_point.h), to round-off.
struct PointRows {
  double e[3][3];       // e1, e2, t0 (rest)
  double q[3][3];       // R e1, R e2, R t0: the frame the rows are written in
  double c[2][2];       // c[i][a] = phi0^a . e_i
  double gamma[3][2];   // Gamma^c_ab for ab = 11, 22, 12
  double bend[3][3];    // frame components [11, 22, 2 x 12] of the covariant rho_ab
  double sm, sb, nu, k1, k2;  // sqrt(w D_m), sqrt(w D_b), nu, sqrt(1 - nu^2), sqrt((1 - nu) / 2)

  void set(const RestPoint& p, const double* R, double weight, double dn, double dm, double poisson) {
    frame_along(p, p.a1, e[0], e[1]);
    for (int k = 0; k < 3; ++k) e[2][k] = p.t0[k];
    for (int f = 0; f < 3; ++f)
      for (int k = 0; k < 3; ++k)
        q[f][k] = R ? R[k * 3 + 0] * e[f][0] + R[k * 3 + 1] * e[f][1] + R[k * 3 + 2] * e[f][2] : e[f][k];
    c[0][0] = dot3(p.dual1, e[0]), c[0][1] = dot3(p.dual2, e[0]);
    c[1][0] = dot3(p.dual1, e[1]), c[1][1] = dot3(p.dual2, e[1]);
    const double* phi_ab[3] = {p.a11, p.a22, p.a12};
    for (int r = 0; r < 3; ++r) gamma[r][0] = dot3(phi_ab[r], p.dual1), gamma[r][1] = dot3(phi_ab[r], p.dual2);
    for (int i = 0; i < 2; ++i)  // rows 11 and 22: c_ia c_ib rho_ab
      bend[i][0] = c[i][0] * c[i][0], bend[i][1] = c[i][1] * c[i][1], bend[i][2] = c[i][0] * c[i][1] + c[i][1] * c[i][0];
    bend[2][0] = 2 * c[0][0] * c[1][0], bend[2][1] = 2 * c[0][1] * c[1][1];
    bend[2][2] = 2 * (c[0][0] * c[1][1] + c[0][1] * c[1][0]);
    sm = std::sqrt(weight * dn), sb = std::sqrt(weight * dm);
    nu = poisson, k1 = std::sqrt(1 - nu * nu), k2 = std::sqrt(0.5 * (1 - nu));
  }

  // Unscaled strains of one function: membrane g (eps11, eps22 parts) and bending beta.
  void strains(const double dN[2], const double d2N[3], double g[2], double beta[3]) const {
    g[0] = c[0][0] * dN[0] + c[0][1] * dN[1];
    g[1] = c[1][0] * dN[0] + c[1][1] * dN[1];
    double rho[3];
    for (int r = 0; r < 3; ++r) rho[r] = -(d2N[r] - gamma[r][0] * dN[0] - gamma[r][1] * dN[1]);
    for (int r = 0; r < 3; ++r) beta[r] = bend[r][0] * rho[0] + bend[r][1] * rho[1] + bend[r][2] * rho[2];
  }

  // A function's six scaled rows (L^T [Bm sqrt(w D_m); Bb sqrt(w D_b)], as
  // scaled_strain_rows) in the frame q: membrane u0 q0 + nu u1 q1, k1 u1 q1 and
  // k2 (u1 q0 + u0 q1); bending b_r q2. The factors are linear in the function's
  // derivatives d = (dN_1, dN_2, d2N_11, d2N_22, d2N_12): u = A d with u_i = sm c_ia dN_a,
  // and b = Bf d with b = diag(sb) [1 nu 0; 0 k1 0; 0 0 k2] bend rho, rho_r = -(d2N_r -
  // gamma_r . dN) (strains()).
  void split_factors(double A[2][2], double Bf[3][5]) const {
    for (int i = 0; i < 2; ++i)
      for (int a = 0; a < 2; ++a) A[i][a] = sm * c[i][a];
    const double scale[3][3] = {{sb, sb * nu, 0}, {0, sb * k1, 0}, {0, 0, sb * k2}};
    for (int t = 0; t < 3; ++t) {
      double phi[3];  // b_t = phi . rho
      for (int r = 0; r < 3; ++r)
        phi[r] = scale[t][0] * bend[0][r] + scale[t][1] * bend[1][r] + scale[t][2] * bend[2][r];
      Bf[t][0] = phi[0] * gamma[0][0] + phi[1] * gamma[1][0] + phi[2] * gamma[2][0];
      Bf[t][1] = phi[0] * gamma[0][1] + phi[1] * gamma[1][1] + phi[2] * gamma[2][1];
      for (int r = 0; r < 3; ++r) Bf[t][2 + r] = -phi[r];
    }
  }
};

// A point's rows split by global component k (x, y, z). Membrane row rho of function i,
// component k, is c[rho][k] . (u0_i, u1_i) (PointRows::split_factors) with, in the rotated frame
// q0, q1, q2: c[0][k] = (q0_k, nu q1_k), c[1][k] = (0, k1 q1_k), c[2][k] = (k2 q1_k,
// k2 q0_k); bending row r is q2_k b_r,i. So the (k, l) block of sum_rows row^T row is, over
// the functions, U^T W_kl U + q2_k q2_l B^T B with U the two membrane factors, B the three
// bending factors and W_kl = sum_rho c[rho][k] c[rho][l]^T (2 x 2). The diagonal blocks
// take W_kk = L_k L_k^T as two rows L_k^T U; the bending products are symmetric in every
// block, and all six (k <= l) are sums of the same B^T B weighted by q2_k q2_l: each entry
// forms a point's B^T B once and adds it with the six weights (accumulate_weighted_grams).
// Per point 13.5 m^2 multiply-adds over m functions instead of 27 m^2 for the six rows of
// 3 m columns. Six products of weighted bending rows (18 m^2) took as long for the bending
// sums as the membrane's products; the weighted Grams are 1.3-1.4x faster
// (bench_enriched_assembly BM_BendingSums*, AVX-512), the slinky's whole run at one thread
// 3-4 % (its probes move by 7e-12 relative).
constexpr int frame_split_pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};

struct FrameSplit {
  double L[3][3];  // per k: L00, L10, L11 (W_kk = L L^T, L lower)
  double W[3][4];  // per pair (x, y), (x, z), (y, z): W00, W01, W10, W11
  double t[3];     // q2
  double c[3][3][2];

  void set(const PointRows& pr) {
    for (int k = 0; k < 3; ++k) {
      const double q0 = pr.q[0][k], q1 = pr.q[1][k];
      c[0][k][0] = q0, c[0][k][1] = pr.nu * q1;
      c[1][k][0] = 0, c[1][k][1] = pr.k1 * q1;
      c[2][k][0] = pr.k2 * q1, c[2][k][1] = pr.k2 * q0;
      t[k] = pr.q[2][k];
    }
    const auto w = [&](int k, int l, int a, int b) {
      return c[0][k][a] * c[0][l][b] + c[1][k][a] * c[1][l][b] + c[2][k][a] * c[2][l][b];
    };
    for (int k = 0; k < 3; ++k) {
      // W_00 is 0 only with q0_k = q1_k = 0, and then W_kk = 0.
      const double w00 = w(k, k, 0, 0), w10 = w(k, k, 1, 0), w11 = w(k, k, 1, 1);
      const double l00 = std::sqrt(w00), l10 = l00 > 0 ? w10 / l00 : 0.0;
      L[k][0] = l00, L[k][1] = l10, L[k][2] = std::sqrt(std::max(0.0, w11 - l10 * l10));
    }
    for (int p = 0; p < 3; ++p) {
      const int k = frame_split_pairs[p][0], l = frame_split_pairs[p][1];
      W[p][0] = w(k, l, 0, 0), W[p][1] = w(k, l, 0, 1), W[p][2] = w(k, l, 1, 0), W[p][3] = w(k, l, 1, 1);
    }
  }
};

// Plane-stress membrane stiffness of function pair (i, j) along (E_a, E_b) from the sums of
// gradient products S_ab(i, j) = sum_q w D_m G_ia G_jb (s = S_11, S_12, S_21, S_22), in place:
// with c = (1 - nu) / 2, K_11 = S_11 + c S_22, K_12 = nu S_12 + c S_21, K_21 = nu S_21 + c S_12,
// K_22 = S_22 + c S_11 (eps = (G_1, 0, G_2) for a displacement along E1, (0, G_2, G_1) along
// E2, against C = [[1, nu, 0], [nu, 1, 0], [0, 0, c]]).
inline void membrane_from_gradient_products(double nu, double s[4]) {
  const double c = 0.5 * (1 - nu);
  const double k11 = s[0] + c * s[3], k12 = nu * s[1] + c * s[2], k21 = nu * s[2] + c * s[1], k22 = s[3] + c * s[0];
  s[0] = k11, s[1] = k12, s[2] = k21, s[3] = k22;
}

// A planar element's fixed frame (enriched_element_planar_frame): E1, E2, T.
struct PlanarFrame {
  double E[3][3];
};

// out[r] = f . (d[0][r], ..., d[4][r]) for the m functions: a factor linear in each
// function's derivatives (dN_1, dN_2, d2N_11, d2N_22, d2N_12), one loop over the functions.
inline void combine_derivatives(const double f[5], const double (*d)[max_enriched_basis], int m, double* out) {
  for (int r = 0; r < m; ++r) out[r] = f[0] * d[0][r] + f[1] * d[1][r] + f[2] * d[2][r] + f[3] * d[3][r] + f[4] * d[4][r];
}

// A planar element's rows of one point (see chunk_stiffness): the membrane row, two columns
// a function (2 r + a: Am d), and the three bending rows (f_t . d, bending_stride apart).
// The per-point loops, cloned per instruction set like the Gram products: every entry is
// the same expression in each clone and the file is compiled without contraction
// (cmake/areas/enriched_assembly.cmake), so all clones give the same bits.
__attribute__((target_clones("avx512f", "avx2", "default")))
void planar_point_rows(int m, const double (*d)[max_enriched_basis], const double Am[2][2], const double f[3][5],
                       double* __restrict membrane, double* __restrict bending, std::size_t bending_stride) {
  for (int r = 0; r < m; ++r) {
    membrane[2 * r] = Am[0][0] * d[0][r] + Am[0][1] * d[1][r];
    membrane[2 * r + 1] = Am[1][0] * d[0][r] + Am[1][1] * d[1][r];
  }
  for (int t = 0; t < 3; ++t) combine_derivatives(f[t], d, m, bending + t * bending_stride);
}

// A curved element's rows of one point (the frame split, FrameSplit): the factors U = A d
// (rows U0, U1), the three bending rows Bf d (S apart), and per frame component k the rows
// L_k U (at M[k] and M[k] + S) and W_k U (at Wu[k] and Wu[k] + S). Cloned like
// planar_point_rows.
__attribute__((target_clones("avx512f", "avx2", "default")))
void split_point_rows(int m, const double (*d)[max_enriched_basis], const double A[2][2], const double Bf[3][5],
                      const FrameSplit& fs, std::size_t S, double* __restrict U0, double* __restrict U1,
                      double* __restrict bending, double* const M[3], double* const Wu[3]) {
  for (int r = 0; r < m; ++r) U0[r] = A[0][0] * d[0][r] + A[0][1] * d[1][r];
  for (int r = 0; r < m; ++r) U1[r] = A[1][0] * d[0][r] + A[1][1] * d[1][r];
  for (int t = 0; t < 3; ++t) combine_derivatives(Bf[t], d, m, bending + t * S);
  for (int k = 0; k < 3; ++k) {
    double* __restrict M0 = M[k];
    double* __restrict M1 = M[k] + S;
    const double* l = fs.L[k];
    for (int r = 0; r < m; ++r) M0[r] = l[0] * U0[r] + l[1] * U1[r], M1[r] = l[2] * U1[r];
    double* __restrict W0 = Wu[k];
    double* __restrict W1 = Wu[k] + S;
    const double* w = fs.W[k];
    for (int r = 0; r < m; ++r) W0[r] = w[0] * U0[r] + w[1] * U1[r], W1[r] = w[2] * U0[r] + w[3] * U1[r];
  }
}

// Points with the same varying textures (mask) and the same constant values: G = sum of
// S^T S over the group's reduced basis (standard functions, then the varying textures'
// enriched ones), upper triangle; g = sum of S^T s (corrective forces). Curved or rotated
// elements sum the frame-split products of FrameSplit: the rows of up to
// group_block_points points are stacked and added in blocked products (fixed blocks: the
// points of the group in order, so the sums do not depend on threads), and G is formed
// from them once the chunk's points are in.
constexpr int group_block_points = 16;
// Planar groups stack 32 points: 32 membrane rows and 96 bending rows a block.
constexpr int planar_block_points = 32;

// Stacked rows of a block of P points (stride columns each), in units of P rows: U (the
// membrane factors u0, u1 of each point), M_k = L_k^T U, WU_p = W_p U (2 P rows each), and
// B (the three bending factors of each point, 3 P rows); with the bending weights of each
// point (split_bending_weights of them: q2_k q2_k for k = 0, 1, 2, then q2_k q2_l for the
// frame_split_pairs).
constexpr int split_row_units = 2 + 3 * 2 + 3 * 2 + 3;
constexpr int split_u = 0;
inline int split_m(int k) { return 2 + 2 * k; }
inline int split_wu(int p) { return 8 + 2 * p; }
constexpr int split_b = 14;
constexpr int split_bending_weights = 6;

struct Group {
  std::uint32_t varying = 0;
  double value[max_enrichments_per_element];
  int m = 0;                    // reduced basis functions
  double* G = nullptr;          // 3m x 3m, row stride 3m (upper part filled by finish_split)
  int pending = 0;              // points stacked, not yet summed
  bool written = false;         // the sums hold a first block
  // Frame-split sums, stride = m padded to gram_column_multiple: D_k (sum of the
  // (k, k) blocks, upper), O_p (membrane part of pair p, whole), Bs_p (bending part of pair
  // p, upper), each stride x stride; the stacked rows; g_k, the forces per component.
  int stride = 0;
  double* sums = nullptr;       // D_0..2, O_0..2, Bs_0..2
  double* rows = nullptr;       // split_row_units x group_block_points rows
  double* bending_weights = nullptr;  // split_bending_weights per stacked point
  std::vector<double> g;        // 3 x stride
  // Planar elements (PlanarFrame): the membrane sums from 1 row a point (gradient products,
  // padded length >= 2 m) and the bending sums from 3 rows (>= m).
  int membrane_stride = 0, bending_stride = 0;
  double *Gm = nullptr, *Gb = nullptr, *membrane_rows = nullptr, *bending_rows = nullptr;

  std::size_t square() const { return static_cast<std::size_t>(stride) * stride; }
  double* D(int k) const { return sums + k * square(); }
  double* O(int p) const { return sums + (3 + p) * square(); }
  double* Bs(int p) const { return sums + (6 + p) * square(); }
  double* row_block(int unit) const {
    return rows + static_cast<std::size_t>(unit) * group_block_points * stride;
  }

  bool matches(std::uint32_t mask, const double* values, int count) const {
    if (mask != varying) return false;
    for (int k = 0; k < count; ++k)
      if (!(mask >> k & 1u) && !(std::abs(values[k] - value[k]) <= enriched_flat_tolerance)) return false;
    return true;
  }
};

// Per thread, the i-th group of a chunk keeps its G and stacked rows in the i-th buffer
// (kept between chunks and calls, never copied nor zero-filled: G's first block stores).
// One growing arena instead moved and zero-filled ~25 MB whenever a chunk had more
// groups than any before, and paid page faults for it (~13% of accordion's assembly).
struct GroupStorage {
  std::unique_ptr<double[]> data;
  std::size_t capacity = 0;

  double* take(std::size_t size) {
    if (capacity < size) data.reset(new double[size]), capacity = size;
    return data.get();
  }
};

// Adds the group's stacked points to its sums, in point order.
void flush(Group& group) {
  if (group.pending == 0) return;
  if (group.Gm) {  // planar: no forces (unrotated)
    accumulate_gram_upper(group.pending, group.membrane_stride, group.membrane_rows, group.Gm, !group.written);
    accumulate_gram_upper(3 * group.pending, group.bending_stride, group.bending_rows, group.Gb, !group.written);
    group.written = true;
    group.pending = 0;
    return;
  }
  const int S = group.stride, two = 2 * group.pending;
  const bool first = !group.written;
  const double* U = group.row_block(split_u);
  for (int k = 0; k < 3; ++k) {
    const double* M = group.row_block(split_m(k));
    accumulate_product(two, S, M, M, group.D(k), first, true);
  }
  for (int p = 0; p < 3; ++p) accumulate_product(two, S, U, group.row_block(split_wu(p)), group.O(p), first, false);
  // The bending parts: D_k += sum q2_k^2 B^T B (after the membrane part), Bs_p = sum q2_k q2_l B^T B.
  double* const bending_sums[split_bending_weights] = {group.D(0),  group.D(1),  group.D(2),
                                                       group.Bs(0), group.Bs(1), group.Bs(2)};
  const bool overwrite[split_bending_weights] = {false, false, false, first, first, first};
  accumulate_weighted_grams(group.pending, 3, S, group.row_block(split_b), group.bending_weights,
                            split_bending_weights, bending_sums, overwrite);
  group.written = true;
  group.pending = 0;
}

// G (3m x 3m, entry (3 i + k, 3 j + l)) of a frame-split group from its sums, upper part
// (GroupMap mirrors the lower entries it reads): D_k for k = l, O_p + Bs_p for the pair
// p = (k, l), k < l, and for k > l (i < j) the transposed entries of pair (l, k).
void finish_split(Group& group) {
  const int m = group.m, S = group.stride;
  const std::size_t N = 3 * static_cast<std::size_t>(m);
  const auto at = [S](const double* X, int i, int j) { return X[static_cast<std::size_t>(i) * S + j]; };
  int pair_of[3][3] = {};
  for (int p = 0; p < 3; ++p) pair_of[frame_split_pairs[p][0]][frame_split_pairs[p][1]] = p;
  for (int i = 0; i < m; ++i)
    for (int j = i; j < m; ++j) {
      double* out = group.G + 3 * i * N + 3 * j;
      for (int k = 0; k < 3; ++k)
        for (int l = i == j ? k : 0; l < 3; ++l) {
          double v = 0;
          if (group.written) {
            if (k == l) v = at(group.D(k), i, j);
            else if (k < l) v = at(group.O(pair_of[k][l]), i, j) + at(group.Bs(pair_of[k][l]), i, j);
            else v = at(group.O(pair_of[l][k]), j, i) + at(group.Bs(pair_of[l][k]), i, j);
          }
          out[k * N + l] = v;
        }
    }
}

// Zeroes block rows a <= c (each w x w block whole) of an (w n) x (w n) row-major matrix:
// the part the group maps write and the readers read (Kc persists between calls).
void zero_upper_block_rows(double* K, int n, int w) {
  const std::size_t N = static_cast<std::size_t>(w) * n;
  for (std::size_t x = 0; x < N; ++x) std::fill(K + x * N + x / w * w, K + (x + 1) * N, 0.0);
}

// K += T^T G T for one group, w columns per function (3: x, y, z; planar 2: E1, E2, or 1: T):
// element function i is reduced function red[i] times scale[i]. Element functions with
// consecutive reduced functions form runs, so each K row takes contiguous stretches of a G
// row. K: (w n) x (w n) row-major, block rows a <= c. Entries of G below the diagonal are
// read only in the standard functions' columns (red < npe) and in diagonal w x w blocks:
// those are mirrored first (G is the group's, scratch below the diagonal).
struct GroupMap {
  int n, npe, m;
  const int* red;
  const double* scale;
  const std::vector<int>& run_start;
  const std::vector<int>& run_of;

  void add(double* G, std::size_t S, int w, double* K) const {
    const std::size_t M = static_cast<std::size_t>(w) * m, standard_columns = static_cast<std::size_t>(w) * npe;
    for (std::size_t x = 1; x < M; ++x) {
      for (std::size_t y = 0; y < std::min(x, standard_columns); ++y) G[x * S + y] = G[y * S + x];
      for (std::size_t y = std::max(x / w * w, standard_columns); y < x; ++y) G[x * S + y] = G[y * S + x];
    }
    const std::size_t N = static_cast<std::size_t>(w) * n;
    double column_scale[3 * max_enriched_basis];
    for (int j = 0; j < n; ++j)
      for (int d = 0; d < w; ++d) column_scale[w * j + d] = scale[j];
    for (int i = 0; i < n; ++i) {
      if (scale[i] == 0) continue;
      for (int c = 0; c < w; ++c) {
        const double* Grow = G + (static_cast<std::size_t>(w) * red[i] + c) * S;
        double* Krow = K + (static_cast<std::size_t>(w) * i + c) * N;
        for (int run = run_of[i]; run + 1 < static_cast<int>(run_start.size()); ++run) {
          const int j0 = std::max(run_start[run], i), j1 = run_start[run + 1];
          const std::size_t J0 = static_cast<std::size_t>(w) * j0, J1 = static_cast<std::size_t>(w) * j1;
          add_scaled_row(static_cast<int>(J1 - J0), scale[i], column_scale + J0,
                         Grow + static_cast<std::size_t>(w) * red[j0], Krow + J0);
        }
      }
    }
  }
};

// Calls write(dN, d2N, r) for the reduced basis of a point, r = 0, 1, ...: the standard
// functions, then the enriched ones of the textures that vary there (mask).
template <class Write>
void for_reduced_functions(const ElementLayout& L, std::uint32_t mask, const ShapeValues& s,
                           const TextureSample* samples, Write&& write) {
  for (int a = 0; a < L.npe; ++a) write(s.dN[a], s.d2N[a], a);
  int r = L.npe;
  for (int k = 0; k < L.count; ++k) {
    if (!(mask >> k & 1u)) continue;
    for (int a = 0; a < L.npe; ++a) {
      if (L.slot[k][a] < 0) continue;
      double dN[2], d2N[3];
      product_rule(samples[k], L.shift[k][a], s, a, dN, d2N);
      write(dN, d2N, r++);
    }
  }
}

// F at one point from the whole basis (the rest tangents have no enriched share), the
// textures sampled at the point: the arithmetic of enriched_element_deformation_gradients.
void point_deformation_gradient(const ElementLayout& L, const ShapeValues& s, const RestPoint& rest,
                                const TextureSample* samples, const int* global, const double* current, double F[9]) {
  const int npe = L.npe;
  double a1[3] = {0, 0, 0}, a2[3] = {0, 0, 0};
  for (int a = 0; a < npe; ++a) {
    const double* x = current + 3 * static_cast<std::int64_t>(global[a]);
    for (int k = 0; k < 3; ++k) a1[k] += s.dN[a][0] * x[k], a2[k] += s.dN[a][1] * x[k];
  }
  for (int k = 0; k < L.count; ++k) {
    const TextureSample& h = samples[k];
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
  surface_deformation_gradient(rest.a1, rest.a2, rest.t0, a1, a2, t, F);
}

// Sums the chunk's points into per-group matrices, then maps the groups onto the element's
// basis: Kc (3n x 3n, row-major over DOFs, block rows a <= c filled) and fc (3n).
// Rotations: given per point (`rotations`), or computed here from `current` exactly as
// enriched_element_deformation_gradients and polar_rotation would (the fused form), or none.
// tangent_weights (may be null): receives D_f = sum_q w_q dN_f(q) over the chunk's points
// for every element function f (2 n slots; the arithmetic of evaluate_enriched_shape).
void chunk_stiffness(const EnrichedElementBatch& b, const EnrichedQuadrature& quad, const Chunk& chunk,
                     const double* rotations, const double* current, bool want_forces, std::vector<double>& Kc,
                     std::vector<double>& fc, double* tangent_weights = nullptr) {
  const std::int64_t e = chunk.element;
  const ElementLayout L(b, e);
  int global[max_enriched_basis];
  if (current) enriched_global_nodes(b, e, global);
  const int npe = L.npe, n = L.n;
  const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
  const ShellSection& sec = b.sections[b.element[e]];
  const double nu = sec.poisson_ratio;
  const double dn = membrane_rigidity(sec.youngs_modulus, nu, sec.thickness);
  const double dm = bending_rigidity(sec.youngs_modulus, nu, sec.thickness);

  // Per thread: G and stacked rows of every group (G is never zero-filled: the first block
  // stores, later ones add).
  static thread_local std::vector<GroupStorage> storage;
  std::vector<Group> groups;
  int last = -1;
  TexelCache cache;
  ShapeValues s;
  RestPoint rest;
  PointRows pr;
  double values[max_enrichments_per_element];
  TextureSample samples[max_enrichments_per_element];  // constructed once: it zero-fills
  // Unrotated rows of a planar element take the split membrane / bending sums.
  PlanarFrame frame;
  const bool planar = !rotations && !current && enriched_element_planar_frame(b, e, &frame.E[0][0]);
  if (tangent_weights) std::fill(tangent_weights, tangent_weights + 2 * n, 0.0);
  for (std::int64_t k = chunk.begin; k < chunk.end; ++k) {
    const std::int64_t q = chunk.point(k);
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
      const auto padded = [](int columns) {
        return (columns + gram_column_multiple - 1) / gram_column_multiple * gram_column_multiple;
      };
      if (storage.size() <= groups.size()) storage.emplace_back();
      GroupStorage& space = storage[groups.size()];
      // Padding columns of the stacked rows stay 0.
      const auto zero_padding = [](double* rows, int count, int used, int stride) {
        for (int k = 0; k < count; ++k)
          for (int i = used; i < stride; ++i) rows[static_cast<std::size_t>(k) * stride + i] = 0;
      };
      if (planar) {
        const std::size_t Sm = padded(2 * fresh.m), Sb = padded(fresh.m), points = planar_block_points;
        fresh.membrane_stride = static_cast<int>(Sm), fresh.bending_stride = static_cast<int>(Sb);
        fresh.Gm = space.take(Sm * Sm + Sb * Sb + points * Sm + 3 * points * Sb);
        fresh.Gb = fresh.Gm + Sm * Sm;
        fresh.membrane_rows = fresh.Gb + Sb * Sb;
        fresh.bending_rows = fresh.membrane_rows + points * Sm;
        zero_padding(fresh.membrane_rows, static_cast<int>(points), 2 * fresh.m, fresh.membrane_stride);
        zero_padding(fresh.bending_rows, static_cast<int>(3 * points), fresh.m, fresh.bending_stride);
      } else {
        fresh.stride = padded(fresh.m);
        const std::size_t N = 3 * static_cast<std::size_t>(fresh.m);
        const int row_count = split_row_units * group_block_points;
        fresh.sums = space.take(9 * fresh.square() + static_cast<std::size_t>(row_count) * fresh.stride + N * N +
                                split_bending_weights * group_block_points);
        fresh.rows = fresh.sums + 9 * fresh.square();
        fresh.G = fresh.rows + static_cast<std::size_t>(row_count) * fresh.stride;
        fresh.bending_weights = fresh.G + N * N;
        zero_padding(fresh.rows, row_count, fresh.m, fresh.stride);
        if (want_forces) fresh.g.assign(3 * static_cast<std::size_t>(fresh.stride), 0.0);
      }
      groups.push_back(std::move(fresh));
      g = static_cast<int>(groups.size()) - 1;
    }
    last = g;
    Group& group = groups[g];

    // This point's rows of the reduced basis, stacked under the group's pending ones.
    double fused_rotation[9];
    const double* R = rotations ? rotations + 9 * q : nullptr;
    if (current) {
      double F[9];
      point_deformation_gradient(L, s, rest, samples, global, current, F);
      polar_rotation(F, fused_rotation);
      R = fused_rotation;
    }
    pr.set(rest, R, weight, dn, dm, nu);
    // The derivatives d = (dN_1, dN_2, d2N_11, d2N_22, d2N_12) of the point's reduced
    // basis, one array each: the rows are linear in them (PointRows::split_factors), and
    // forming them by loops over the functions vectorises.
    const int m = group.m;
    double d[5][max_enriched_basis];
    for_reduced_functions(L, mask, s, samples, [&](const double* dN, const double* d2N, int r) {
      d[0][r] = dN[0], d[1][r] = dN[1], d[2][r] = d2N[0], d[3][r] = d2N[1], d[4][r] = d2N[2];
    });
    if (tangent_weights) {
      // Every element function's dN: a varying texture's are among the reduced ones just
      // formed (the same product rule, so the same bits), a constant one's formed here.
      double* D = tangent_weights;
      for (int a = 0; a < npe; ++a) D[2 * a] += weight * s.dN[a][0], D[2 * a + 1] += weight * s.dN[a][1];
      for (int k = 0, r = npe; k < L.count; ++k)
        for (int a = 0; a < npe; ++a) {
          const int f = L.slot[k][a];
          if (f < 0) continue;
          if (mask >> k & 1u) {
            D[2 * f] += weight * d[0][r], D[2 * f + 1] += weight * d[1][r];
            ++r;
            continue;
          }
          double dN[2], d2N[3];
          product_rule(samples[k], L.shift[k][a], s, a, dN, d2N);
          D[2 * f] += weight * dN[0], D[2 * f + 1] += weight * dN[1];
        }
    }
    double A[2][2], Bf[3][5];
    pr.split_factors(A, Bf);
    if (planar) {
      // A planar element's rows in its fixed frame (E1, E2, T; see PlanarFrame). Membrane:
      // one row, sqrt(w D_m) times the function's gradient along E1 and E2 (2 columns per
      // function, at 2 r + a), u_1 (e1 . E_a) + u_2 (e2 . E_a); its Gram sums are the
      // gradient products S_ab, from which membrane_from_gradient_products forms the
      // plane-stress stiffness. Bending: the three rows b_t (t0 . T) along T (1 column per
      // function).
      double in_plane[2][2];
      for (int f = 0; f < 2; ++f)
        for (int a = 0; a < 2; ++a) in_plane[f][a] = dot3(pr.e[f], frame.E[a]);
      const double normal = dot3(pr.e[2], frame.E[2]);
      double Am[2][2];
      for (int a = 0; a < 2; ++a)
        for (int j = 0; j < 2; ++j) Am[a][j] = A[0][j] * in_plane[0][a] + A[1][j] * in_plane[1][a];
      const std::size_t Sm = group.membrane_stride, Sb = group.bending_stride;
      double f[3][5];
      for (int t = 0; t < 3; ++t)
        for (int j = 0; j < 5; ++j) f[t][j] = Bf[t][j] * normal;
      planar_point_rows(m, d, Am, f, group.membrane_rows + group.pending * Sm,
                        group.bending_rows + 3 * group.pending * Sb, Sb);
      if (++group.pending == planar_block_points) flush(group);
      continue;
    }
    // Corrective forces g += S^T s: s, the scaled rest corotation strain B (X0 - R^T X0)
    // over the standard functions (enriched X0 = 0); per component k of function i,
    // alpha_k . (u0_i, u1_i) + q2_k beta_i with alpha_k = sum_rho s_rho c[rho][k] and
    // beta_i = sum_r s_(3+r) b_r,i.
    const bool point_forces = R && want_forces;
    double sv[6];
    if (point_forces) {
      double strain[6] = {0, 0, 0, 0, 0, 0};
      for (int a = 0; a < npe; ++a) {
        const double* x = b.positions + 3 * static_cast<std::int64_t>(nodes[a]);
        double d[3], xf[3];
        for (int k = 0; k < 3; ++k) d[k] = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
        for (int f = 0; f < 3; ++f) xf[f] = dot3(pr.e[f], d);
        double gm[2], beta[3];
        pr.strains(s.dN[a], s.d2N[a], gm, beta);
        strain[0] += gm[0] * xf[0];
        strain[1] += gm[1] * xf[1];
        strain[2] += gm[1] * xf[0] + gm[0] * xf[1];
        for (int k = 0; k < 3; ++k) strain[3 + k] += beta[k] * xf[2];
      }
      half_constitutive(nu, pr.sm, strain, sv);
      half_constitutive(nu, pr.sb, strain + 3, sv + 3);
    }
    FrameSplit fs;
    fs.set(pr);
    double alpha[3][2];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 2; ++a)
        alpha[k][a] = point_forces ? sv[0] * fs.c[0][k][a] + sv[1] * fs.c[1][k][a] + sv[2] * fs.c[2][k][a] : 0.0;
    // This point's rows, stacked under the group's pending ones: first the factors u0, u1
    // (into U) and b (scratch) of every function, then the combinations row by row.
    const std::size_t S = group.stride;
    double* const U0 = group.row_block(split_u) + 2 * group.pending * S;
    double* const U1 = U0 + S;
    double* const bending = group.row_block(split_b) + 3 * group.pending * S;  // the point's 3 rows
    double* M[3];
    double* Wu[3];
    for (int k = 0; k < 3; ++k) {
      M[k] = group.row_block(split_m(k)) + 2 * group.pending * S;
      Wu[k] = group.row_block(split_wu(k)) + 2 * group.pending * S;
    }
    split_point_rows(m, d, A, Bf, fs, S, U0, U1, bending, M, Wu);
    double* const weights = group.bending_weights + split_bending_weights * group.pending;
    for (int k = 0; k < 3; ++k) weights[k] = fs.t[k] * fs.t[k];
    for (int p = 0; p < 3; ++p) weights[3 + p] = fs.t[frame_split_pairs[p][0]] * fs.t[frame_split_pairs[p][1]];
    if (point_forces)
      for (int r = 0; r < m; ++r) {
        const double beta = sv[3] * bending[r] + sv[4] * bending[S + r] + sv[5] * bending[2 * S + r];
        for (int k = 0; k < 3; ++k)
          group.g[k * S + r] += alpha[k][0] * U0[r] + alpha[k][1] * U1[r] + fs.t[k] * beta;
      }
    if (++group.pending == group_block_points) flush(group);
  }
  for (Group& group : groups) {
    flush(group);
    if (!planar) finish_split(group);
  }

  // K += T^T G T per group: basis function i of the element is reduced function red[i]
  // times scale[i] (1, or H_k - H_k(xi^a) for a constant texture k: a multiple of N^a).
  // Planar elements map their membrane sums (2 columns per function) and bending sums
  // (1 column) alike into Kc = [Km (2n x 2n) | Kb (n x n)]; the others G (3 columns).
  int red[max_enriched_basis];
  double scale[max_enriched_basis];
  std::vector<int> run_start, run_of(n);  // runs: first element function; run of each function
  const std::size_t N3 = 3 * static_cast<std::size_t>(n), n2 = static_cast<std::size_t>(n) * n;
  if (planar) {
    Kc.resize(5 * n2);
    zero_upper_block_rows(Kc.data(), n, 2);
    zero_upper_block_rows(Kc.data() + 4 * n2, n, 1);
  } else {
    Kc.resize(N3 * N3);
    zero_upper_block_rows(Kc.data(), n, 3);
  }
  fc.assign(want_forces ? N3 : 0, 0.0);
  for (Group& group : groups) {
    for (int a = 0; a < npe; ++a) red[a] = a, scale[a] = 1;
    int r = npe;
    for (int k = 0; k < L.count; ++k)
      for (int a = 0; a < npe; ++a) {
        const int i = L.slot[k][a];
        if (i < 0) continue;
        if (group.varying >> k & 1u) red[i] = r++, scale[i] = 1;
        else red[i] = a, scale[i] = group.value[k] - L.shift[k][a];
      }
    run_start.clear();
    for (int j = 0; j < n; ++j) {
      if (j == 0 || red[j] != red[j - 1] + 1) run_start.push_back(j);
      run_of[j] = static_cast<int>(run_start.size()) - 1;
    }
    run_start.push_back(n);
    const GroupMap map{n, npe, group.m, red, scale, run_start, run_of};
    if (planar) {
      map.add(group.Gm, group.membrane_stride, 2, Kc.data());
      map.add(group.Gb, group.bending_stride, 1, Kc.data() + 4 * n2);
      continue;
    }
    map.add(group.G, 3 * static_cast<std::size_t>(group.m), 3, Kc.data());
    if (want_forces)
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
          fc[3 * i + c] += scale[i] * group.g[static_cast<std::size_t>(c) * group.stride + red[i]];
  }
  if (!planar) return;
  // The membrane sums are gradient products so far: the stiffness of each upper 2 x 2 block.
  const std::size_t N2 = 2 * static_cast<std::size_t>(n);
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i)
    for (std::size_t j = i; j < static_cast<std::size_t>(n); ++j) {
      double* top = Kc.data() + 2 * i * N2 + 2 * j;
      double block[4] = {top[0], top[1], top[N2], top[N2 + 1]};
      membrane_from_gradient_products(nu, block);
      top[0] = block[0], top[1] = block[1], top[N2] = block[2], top[N2 + 1] = block[3];
    }
}

}  // namespace

bool enriched_element_planar_frame(const EnrichedElementBatch& batch, std::int64_t e, double frame[9]) {
  const int npe = nodes_per_element(batch.type);
  const int* nodes = batch.connectivity + static_cast<std::int64_t>(batch.element[e]) * npe;
  const double centre = batch.type == ElementType::quad8 ? 0.0 : 1.0 / 3.0;
  ShapeValues s;
  RestPoint p;
  evaluate_shape(batch.type, centre, centre, s);
  evaluate_rest_point(s, nodes, batch.positions, p);
  frame_along(p, p.a1, frame, frame + 3);
  for (int k = 0; k < 3; ++k) frame[6 + k] = p.t0[k];
  const double* x0 = batch.positions + 3 * static_cast<std::int64_t>(nodes[0]);
  double size = 0, off = 0;
  for (int a = 1; a < npe; ++a) {
    const double* x = batch.positions + 3 * static_cast<std::int64_t>(nodes[a]);
    const double d[3] = {x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]};
    size = std::max(size, std::sqrt(dot3(d, d)));
    off = std::max(off, std::abs(dot3(d, frame + 6)));
  }
  return off <= enriched_planar_tolerance * size;
}

void enriched_planar_frame_products(const double frame[9], const double* R, double products[45]) {
  double r[3][3];  // R E1, R E2, R T
  for (int f = 0; f < 3; ++f)
    for (int i = 0; i < 3; ++i)
      r[f][i] = R ? R[i * 3] * frame[3 * f] + R[i * 3 + 1] * frame[3 * f + 1] + R[i * 3 + 2] * frame[3 * f + 2]
                  : frame[3 * f + i];
  for (int k = 0; k < 5; ++k)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        products[9 * k + i * 3 + j] = r[enriched_planar_pairs[k][0]][i] * r[enriched_planar_pairs[k][1]][j];
}

void enriched_planar_sum_offsets(int n, std::size_t a, std::size_t c, std::size_t at[5]) {
  const std::size_t N2 = 2 * static_cast<std::size_t>(n);
  at[0] = 2 * a * N2 + 2 * c, at[1] = 2 * a * N2 + 2 * c + 1;
  at[2] = (2 * a + 1) * N2 + 2 * c, at[3] = (2 * a + 1) * N2 + 2 * c + 1;
  at[4] = N2 * N2 + a * n + c;
}

void enriched_element_stiffness_reference(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                          const double* rotations, double* blocks, double* forces) {
  for (std::int64_t e = 0; e < batch.count; ++e) element_stiffness(batch, quadrature, e, rotations, blocks, forces);
}

namespace {

// Block (lo, hi), lo <= hi, of a planar element from its chunks' membrane and bending sums
// (Kc = [Km | Kb], chunk_stiffness), summed over the chunks in order, then
// sum_ab Km(2 lo + a, 2 hi + b) E_a E_b^T + Kb(lo, hi) T T^T (O: enriched_planar_frame_products).
void planar_block(const std::vector<std::vector<double>>& Kc, std::int64_t c0, std::int64_t c1, int n, std::size_t lo,
                  std::size_t hi, const double O[45], double block[9]) {
  std::size_t at[5];
  enriched_planar_sum_offsets(n, lo, hi, at);
  double g[5];
  for (int k = 0; k < 5; ++k) {
    g[k] = Kc[c0][at[k]];
    for (std::int64_t ch = c0 + 1; ch < c1; ++ch) g[k] += Kc[ch][at[k]];
  }
  for (int ij = 0; ij < 9; ++ij)
    block[ij] = g[0] * O[ij] + g[1] * O[9 + ij] + g[2] * O[18 + ij] + g[3] * O[27 + ij] + g[4] * O[36 + ij];
}

// The fast form with rotations given per point, computed from `current`, or none.
void stiffness_by_chunks(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                         const double* rotations, const double* current, double* blocks, double* forces,
                         Execution execution) {
  const std::vector<Chunk> chunks = make_chunks(batch, quadrature);
  const bool want_forces = (rotations || current) && forces;
  // The chunks' sums persist with the calling thread (the workers write distinct entries
  // through these references; naming the thread_local inside the loops would give each
  // worker its own): a fresh 3n x 3n matrix per chunk and call costs page faults every step.
  static thread_local std::vector<std::vector<double>> chunk_matrices, chunk_forces;
  std::vector<std::vector<double>>& Kc = chunk_matrices;
  std::vector<std::vector<double>>& fc = chunk_forces;
  if (Kc.size() < chunks.size()) Kc.resize(chunks.size()), fc.resize(chunks.size());
  // Chunks differ in cost (points, varying textures): handed out dynamically; each writes
  // only its own Kc, fc, so the result does not depend on which thread ran it.
  const std::int64_t num_chunks = static_cast<std::int64_t>(chunks.size());
  auto run = [&](std::int64_t c) {
    chunk_stiffness(batch, quadrature, chunks[c], rotations, current, want_forces, Kc[c], fc[c]);
  };
  forall_dynamic(num_chunks, run, execution);
  // Per element: its chunks summed in order, then the padded symmetric layout; one work
  // item per block row (a single element with hundreds of functions uses every thread).
  std::vector<std::int64_t> first_chunk(static_cast<std::size_t>(batch.count) + 1, 0);
  for (const Chunk& c : chunks) ++first_chunk[c.element + 1];
  for (std::int64_t e = 0; e < batch.count; ++e) first_chunk[e + 1] += first_chunk[e];
  const int W = batch.width;
  // Unrotated planar elements' chunks hold membrane and bending sums (chunk_stiffness).
  std::vector<char> planar(static_cast<std::size_t>(batch.count), 0);
  std::vector<double> products(45 * static_cast<std::size_t>(batch.count));
  for (std::int64_t e = 0; !rotations && !current && e < batch.count; ++e) {
    double frame[9];
    planar[e] = enriched_element_planar_frame(batch, e, frame);
    enriched_planar_frame_products(frame, nullptr, &products[45 * e]);
  }
  forall(
      batch.count * W,
      [&](std::int64_t item) {
        const std::int64_t e = item / W;
        const int a = static_cast<int>(item % W);
        const int n = enriched_basis_count(batch, e);
        const std::int64_t c0 = first_chunk[e], c1 = first_chunk[e + 1];
        double* out = blocks + (e * W + a) * W * 9;
        // A planar element's item a expands blocks (a, c >= a) once and writes their mirrors
        // (c, a) too (the expansion is the costly part there); the others read both from Kc.
        for (int c = planar[e] ? a : 0; c < W; ++c) {
          double* blk = out + c * 9;
          double* mirror = blocks + ((e * W + c) * W + a) * 9;
          if (a >= n || c >= n) {
            for (int i = 0; i < 9; ++i) blk[i] = 0;
            if (planar[e])
              for (int i = 0; i < 9; ++i) mirror[i] = 0;
            continue;
          }
          const bool upper = a <= c;
          const std::size_t lo = upper ? a : c, hi = upper ? c : a;
          double sum[9];  // block (lo, hi)
          if (planar[e]) {
            planar_block(Kc, c0, c1, n, lo, hi, &products[45 * e], sum);
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) mirror[i * 3 + j] = sum[j * 3 + i];
          } else {
            // Kc holds block (lo, hi) row-major over DOFs: (3 lo + i) * 3n + 3 hi + j.
            const std::size_t N3 = 3 * static_cast<std::size_t>(n);
            const std::size_t at = 3 * lo * N3 + 3 * hi;
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) sum[i * 3 + j] = Kc[c0][at + i * N3 + j];
            for (std::int64_t ch = c0 + 1; ch < c1; ++ch)
              for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) sum[i * 3 + j] += Kc[ch][at + i * N3 + j];
          }
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) blk[i * 3 + j] = upper ? sum[i * 3 + j] : sum[j * 3 + i];
        }
        if (forces) {
          double* fo = forces + (e * W + a) * 3;
          for (int i = 0; i < 3; ++i) {
            double sum = 0;
            if (want_forces && a < n) {
              sum = fc[c0][3 * a + i];
              for (std::int64_t ch = c0 + 1; ch < c1; ++ch) sum += fc[ch][3 * a + i];
            }
            fo[i] = sum;
          }
        }
      },
      execution);
}

}  // namespace

void enriched_element_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                const double* rotations, double* blocks, double* forces, Execution execution) {
  stiffness_by_chunks(batch, quadrature, rotations, nullptr, blocks, forces, execution);
}

void enriched_element_corotated_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                          const double* current, double* blocks, double* forces,
                                          Execution execution) {
  stiffness_by_chunks(batch, quadrature, nullptr, current, blocks, forces, execution);
}

void enriched_element_point_set_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                          std::int64_t e, const std::int64_t* points, std::int64_t count,
                                          std::vector<double>& K, double* tangent_weights) {
  std::vector<double> unused_forces;
  chunk_stiffness(batch, quadrature, Chunk{e, 0, count, points}, nullptr, nullptr, false, K, unused_forces,
                  tangent_weights);
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
        TextureSample samples[max_enrichments_per_element];  // constructed once: it zero-fills
        for (std::int64_t q = chunk.begin; q < chunk.end; ++q) {
          const double* pt = quad.points + 3 * q;
          evaluate_shape(b.type, pt[0], pt[1], s);
          evaluate_rest_point(s, nodes, b.positions, rest);
          int ti, tj;
          cache.at(b, L, pt[0], pt[1], ti, tj);
          for (int k = 0; k < L.count; ++k)
            sample_texel_polynomial(b.type, b.resolution, cache.fd[k], ti, tj, pt[0], pt[1], samples[k]);
          point_deformation_gradient(L, s, rest, samples, global, current, F + 9 * q);
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
        GramAccumulator M(n);
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

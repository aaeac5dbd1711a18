#include "dgtex/kernels/enriched_element_kernel.h"

#include <cmath>
#include <vector>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/symmetric_accumulator.h"
#include "dgtex/kernels/vec3.h"

namespace dgtex::kernels {
namespace {

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

// B' = B R^T for a 3x3 row block (rows: Voigt components, columns: x, y, z).
inline void rotate_rows(double B[9], const double R[9]) {
  double out[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out[r * 3 + c] = B[r * 3 + 0] * R[c * 3 + 0] + B[r * 3 + 1] * R[c * 3 + 1] + B[r * 3 + 2] * R[c * 3 + 2];
  for (int i = 0; i < 9; ++i) B[i] = out[i];
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
    if (R && forces) {
      for (int a = 0; a < npe; ++a) {
        const double* x = b.positions + 3 * static_cast<std::int64_t>(nodes[a]);
        double d[3];
        for (int k = 0; k < 3; ++k) d[k] = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) {
            strain[r] += Bm[9 * a + r * 3 + c] * d[c];
            strain[3 + r] += Bb[9 * a + r * 3 + c] * d[c];
          }
      }
    }
    if (R)
      for (int a = 0; a < n; ++a) rotate_rows(&Bm[9 * a], R), rotate_rows(&Bb[9 * a], R);
    const double sm = std::sqrt(p.weight * dn), sb = std::sqrt(p.weight * dm);
    double rows[6][3 * max_enriched_basis];
    for (int a = 0; a < n; ++a)
      for (int c = 0; c < 3; ++c) {
        const double vm[3] = {Bm[9 * a + c], Bm[9 * a + 3 + c], Bm[9 * a + 6 + c]};
        const double vb[3] = {Bb[9 * a + c], Bb[9 * a + 3 + c], Bb[9 * a + 6 + c]};
        double om[3], ob[3];
        half_constitutive(nu, sm, vm, om);
        half_constitutive(nu, sb, vb, ob);
        for (int r = 0; r < 3; ++r) rows[r][3 * a + c] = om[r], rows[3 + r][3 * a + c] = ob[r];
      }
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


}  // namespace

void enriched_element_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                const double* rotations, double* blocks, double* forces, Execution execution) {
  forall(batch.count, [&](std::int64_t e) { element_stiffness(batch, quadrature, e, rotations, blocks, forces); },
         execution);
}

void enriched_element_deformation_gradients(const EnrichedElementBatch& b, const EnrichedQuadrature& quad,
                                            const double* current, double* F, Execution execution) {
  forall(
      b.count,
      [&](std::int64_t e) {
        int global[max_enriched_basis];
        enriched_global_nodes(b, e, global);
        EnrichedPoint p;
        for (std::int64_t q = quad.start[e]; q < quad.start[e + 1]; ++q) {
          evaluate_point(b, e, quad.points + 3 * q, p);
          // Current tangents from the whole basis; the rest ones have no enriched share.
          double a1[3] = {0, 0, 0}, a2[3] = {0, 0, 0};
          for (int a = 0; a < p.shape.count; ++a) {
            const double* x = current + 3 * static_cast<std::int64_t>(global[a]);
            for (int k = 0; k < 3; ++k) a1[k] += p.shape.dN[a][0] * x[k], a2[k] += p.shape.dN[a][1] * x[k];
          }
          double t[3];
          cross3(a1, a2, t);
          normalize3(t);
          const RestPoint& r = p.rest;
          surface_deformation_gradient(r.a1, r.a2, r.t0, a1, a2, t, F + 9 * q);
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

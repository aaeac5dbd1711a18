#include "dgtex/kernels/shell_element_kernel.h"

#include <cmath>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/vec3.h"
#include "plane_stress.h"
#include "shell_point_rows.h"

namespace dgtex::kernels {
namespace {


// Most quadrature points of any element rule (quad8: 3x3 Gauss, tri6: 7 points).
constexpr int max_element_points = 9;
// Strain rows per point: 3 membrane + 3 bending (Voigt).
constexpr int rows_per_point = 6;
constexpr int max_element_dofs = 3 * max_element_nodes;

// K = sum over points of w B^T D B, evaluated as one product of stacked matrices:
// B (k = point * 6 + strain row, column = 3 a + component) and DB = w D B, so each row of
// K is a contiguous, vectorisable sum over k. Only the upper block triangle (b >= a) is
// computed; block (b, a) is written as the transpose of (a, b), which keeps K exactly
// symmetric and halves the work (flops per element: 2 * (6 nq) * 3 npe * (3 npe + 3) / 2,
// i.e. 17.5k multiply-adds for quad8).
// Upper block triangle of K = Bs^T DBs (fast_rows::symmetric_stacked_product), compiled
// for AVX-512, AVX2 and baseline x86-64 and chosen at run time (portable). This file is
// compiled with -ffp-contract=off (cmake/areas/shell_performance.cmake), so every clone
// gives bitwise the same K.
__attribute__((target_clones("avx512f", "avx2", "default")))
void stacked_product(int npe, int nk, const double (*Bs)[max_element_dofs], const double (*DBs)[max_element_dofs],
                     double* K) {
  fast_rows::symmetric_stacked_product<max_element_dofs>(npe, nk, Bs, DBs, npe, K);
}

// Shape values of every quadrature point of an element rule: the same for all elements.
struct ElementRuleShapes {
  QuadratureRule rule;
  ShapeValues shape[max_element_points];
  explicit ElementRuleShapes(ElementType type) : rule(element_quadrature(type)) {
    for (int q = 0; q < rule.count; ++q) evaluate_shape(type, rule.xi1[q], rule.xi2[q], shape[q]);
  }
};

// Rest rows of point q of element e: the weight w = quadrature weight x j0 and the
// membrane and bending rows Bm, Bb of every basis function (depend on the rest geometry only).
void element_point_rows(const ElementBatch& b, const ElementRuleShapes& shapes, std::int64_t e, int q, double& w,
                        double (*Bm)[9], double (*Bb)[9]) {
  const int npe = nodes_per_element(b.type);
  const double j0 = fast_rows::rest_strain_rows(shapes.shape[q], b.connectivity + e * npe, b.positions, npe, Bm, Bb);
  w = shapes.rule.weight[q] * j0;
}

// Stiffness of element e; its rest rows come from `rest_rows` (the layout of
// shell_element_rest_rows, this element's first point) or, if null, are evaluated here.
void element_stiffness(const ElementBatch& b, const ElementRuleShapes& shapes, std::int64_t e, const double* rest_rows,
                       const double* rotations, double* blocks, double* forces) {
  const int npe = nodes_per_element(b.type);
  const int ndof = 3 * npe;
  const int* nodes = b.connectivity + e * npe;
  const ShellSection& sec = b.sections[e];
  const double nu = sec.poisson_ratio;
  const double dn = membrane_rigidity(sec.youngs_modulus, nu, sec.thickness);
  const double dm = bending_rigidity(sec.youngs_modulus, nu, sec.thickness);
  const QuadratureRule& rule = shapes.rule;
  const int nk = rule.count * rows_per_point;

  double* f = forces ? forces + e * npe * 3 : nullptr;
  if (f)
    for (int i = 0; i < npe * 3; ++i) f[i] = 0;

  alignas(64) double Bs[max_element_points * rows_per_point][max_element_dofs];
  alignas(64) double DBs[max_element_points * rows_per_point][max_element_dofs];
  if (ndof < max_element_dofs)  // tri6: the product's last tile reads the padding columns
    for (int k = 0; k < nk; ++k)
      for (int c = ndof; c < max_element_dofs; ++c) Bs[k][c] = DBs[k][c] = 0;
  for (int q = 0; q < rule.count; ++q) {
    double w;
    double Bm[max_element_nodes][9], Bb[max_element_nodes][9];
    if (rest_rows) {
      const double* row = rest_rows + q * (1 + 18 * npe);
      w = row[0];
      for (int a = 0; a < npe; ++a)
        for (int i = 0; i < 9; ++i) Bm[a][i] = row[1 + 9 * a + i], Bb[a][i] = row[1 + 9 * (npe + a) + i];
    } else {
      element_point_rows(b, shapes, e, q, w, Bm, Bb);
    }
    const double* R = rotations ? rotations + (e * rule.count + q) * 9 : nullptr;
    double strain_m[3] = {0, 0, 0}, strain_b[3] = {0, 0, 0};
    if (R && f) {
      // Strain of the corrective term: B (X0 - R^T X0).
      for (int a = 0; a < npe; ++a) {
        const double* x = b.positions + 3 * static_cast<long>(nodes[a]);
        double d[3];
        for (int k = 0; k < 3; ++k) d[k] = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
        for (int r = 0; r < 3; ++r) {
          strain_m[r] += Bm[a][r * 3 + 0] * d[0] + Bm[a][r * 3 + 1] * d[1] + Bm[a][r * 3 + 2] * d[2];
          strain_b[r] += Bb[a][r * 3 + 0] * d[0] + Bb[a][r * 3 + 1] * d[1] + Bb[a][r * 3 + 2] * d[2];
        }
      }
    }
    if (R) {
      for (int a = 0; a < npe; ++a) {
        double tmp[9];
        rotate_rows(Bm[a], R, tmp);
        for (int i = 0; i < 9; ++i) Bm[a][i] = tmp[i];
        rotate_rows(Bb[a], R, tmp);
        for (int i = 0; i < 9; ++i) Bb[a][i] = tmp[i];
      }
    }
    // Stacked rows of this point: B and w D B, column by column (x, y, z of each node).
    double* B0 = Bs[q * rows_per_point];
    double* D0 = DBs[q * rows_per_point];
    for (int a = 0; a < npe; ++a)
      for (int c = 0; c < 3; ++c) {
        const double vm[3] = {Bm[a][0 * 3 + c], Bm[a][1 * 3 + c], Bm[a][2 * 3 + c]};
        const double vb[3] = {Bb[a][0 * 3 + c], Bb[a][1 * 3 + c], Bb[a][2 * 3 + c]};
        double om[3], ob[3];
        apply_plane_stress(nu, w * dn, vm, om);
        apply_plane_stress(nu, w * dm, vb, ob);
        for (int r = 0; r < 3; ++r) {
          B0[r * max_element_dofs + 3 * a + c] = vm[r];
          B0[(3 + r) * max_element_dofs + 3 * a + c] = vb[r];
          D0[r * max_element_dofs + 3 * a + c] = om[r];
          D0[(3 + r) * max_element_dofs + 3 * a + c] = ob[r];
        }
      }
    if (R && f) {
      double sm[3], sb[3];
      apply_plane_stress(nu, dn, strain_m, sm);
      apply_plane_stress(nu, dm, strain_b, sb);
      add_corrective_force(npe, Bm, Bb, sm, sb, w, f);
    }
  }

  stacked_product(npe, nk, Bs, DBs, blocks + e * npe * npe * 9);
}


}  // namespace

void shell_element_stiffness(const ElementBatch& batch, const double* rotations, double* blocks, double* forces,
                             Execution execution) {
  const ElementRuleShapes shapes(batch.type);
  forall(
      batch.count, [&](std::int64_t e) { element_stiffness(batch, shapes, e, nullptr, rotations, blocks, forces); },
      execution);
}

std::int64_t shell_element_rest_row_stride(const ElementBatch& batch) {
  return 1 + 18 * nodes_per_element(batch.type);
}

void shell_element_rest_rows(const ElementBatch& batch, double* rest_rows, Execution execution) {
  const ElementRuleShapes shapes(batch.type);
  const int npe = nodes_per_element(batch.type);
  const std::int64_t stride = shell_element_rest_row_stride(batch);
  forall(
      batch.count,
      [&](std::int64_t e) {
        for (int q = 0; q < shapes.rule.count; ++q) {
          double* row = rest_rows + (e * shapes.rule.count + q) * stride;
          double Bm[max_element_nodes][9], Bb[max_element_nodes][9];
          element_point_rows(batch, shapes, e, q, row[0], Bm, Bb);
          for (int a = 0; a < npe; ++a)
            for (int i = 0; i < 9; ++i) row[1 + 9 * a + i] = Bm[a][i], row[1 + 9 * (npe + a) + i] = Bb[a][i];
        }
      },
      execution);
}

void shell_element_stiffness_cached(const ElementBatch& batch, const double* rest_rows, const double* rotations,
                                    double* blocks, double* forces, Execution execution) {
  const ElementRuleShapes shapes(batch.type);
  const std::int64_t per_element = shapes.rule.count * shell_element_rest_row_stride(batch);
  forall(
      batch.count,
      [&](std::int64_t e) {
        element_stiffness(batch, shapes, e, rest_rows + e * per_element, rotations, blocks, forces);
      },
      execution);
}

void shell_element_deformation_gradients(const ElementBatch& b, const double* current, double* F,
                                         Execution execution) {
  const int npe = nodes_per_element(b.type);
  const QuadratureRule rule = element_quadrature(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* nodes = b.connectivity + e * npe;
        for (int q = 0; q < rule.count; ++q) {
          ShapeValues s;
          evaluate_shape(b.type, rule.xi1[q], rule.xi2[q], s);
          fast_rows::SurfaceFrame p0, p;  // only first derivatives are needed
          fast_rows::evaluate_surface_frame(s, nodes, b.positions, p0);
          fast_rows::evaluate_surface_frame(s, nodes, current, p);
          surface_deformation_gradient(p0.a1, p0.a2, p0.t0, p.a1, p.a2, p.t0, F + (e * rule.count + q) * 9);
        }
      },
      execution);
}

void shell_element_mass(const ElementBatch& b, double* mass, Execution execution) {
  const int npe = nodes_per_element(b.type);
  const QuadratureRule rule = element_quadrature(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* nodes = b.connectivity + e * npe;
        const double rho_h = b.sections[e].density * b.sections[e].thickness;
        double* m = mass + e * npe * npe;
        for (int i = 0; i < npe * npe; ++i) m[i] = 0;
        for (int q = 0; q < rule.count; ++q) {
          ShapeValues s;
          evaluate_shape(b.type, rule.xi1[q], rule.xi2[q], s);
          RestPoint p;
          evaluate_rest_point(s, nodes, b.positions, p);
          const double w = rule.weight[q] * p.j0 * rho_h;
          for (int a = 0; a < npe; ++a)
            for (int c = 0; c < npe; ++c) m[a * npe + c] += w * s.N[a] * s.N[c];
        }
      },
      execution);
}

void shell_element_load_weights(const ElementBatch& b, double* area_weights, double* mass_weights,
                                Execution execution) {
  const int npe = nodes_per_element(b.type);
  const QuadratureRule rule = element_quadrature(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* nodes = b.connectivity + e * npe;
        const double rho_h = b.sections[e].density * b.sections[e].thickness;
        for (int a = 0; a < npe; ++a) area_weights[e * npe + a] = mass_weights[e * npe + a] = 0;
        for (int q = 0; q < rule.count; ++q) {
          ShapeValues s;
          evaluate_shape(b.type, rule.xi1[q], rule.xi2[q], s);
          RestPoint p;
          evaluate_rest_point(s, nodes, b.positions, p);
          const double w = rule.weight[q] * p.j0;
          for (int a = 0; a < npe; ++a) {
            area_weights[e * npe + a] += w * s.N[a];
            mass_weights[e * npe + a] += w * rho_h * s.N[a];
          }
        }
      },
      execution);
}

}  // namespace dgtex::kernels

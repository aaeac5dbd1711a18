#include "dgtex/kernels/material_texture_kernel.h"

#include <algorithm>
#include <stdexcept>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/vec3.h"
#include "shell_point_rows.h"

namespace dgtex::kernels {
namespace {

// Visits the uniform quadtree cells of texels [i0, i1) x [j0, j1) in a fixed order:
// visit(i0, i1, j0, j1) for each cell whose texels all share E and h.
template <class Visit>
void for_each_uniform_cell(const MaterialTextureView& t, int i0, int i1, int j0, int j1, Visit&& visit) {
  const double e0 = t.youngs_modulus[j0 * t.width + i0], h0 = t.thickness[j0 * t.width + i0];
  bool uniform = true;
  for (int j = j0; j < j1 && uniform; ++j)
    for (int i = i0; i < i1 && uniform; ++i)
      uniform = t.youngs_modulus[j * t.width + i] == e0 && t.thickness[j * t.width + i] == h0;
  if (uniform) {
    visit(i0, i1, j0, j1);
    return;
  }
  const int im = i1 - i0 > 1 ? (i0 + i1) / 2 : i1;
  const int jm = j1 - j0 > 1 ? (j0 + j1) / 2 : j1;
  for (int jj = 0; jj < 2; ++jj)
    for (int ii = 0; ii < 2; ++ii) {
      const int a0 = ii ? im : i0, a1 = ii ? i1 : im, b0 = jj ? jm : j0, b1 = jj ? j1 : jm;
      if (a0 < a1 && b0 < b1) for_each_uniform_cell(t, a0, a1, b0, b1, visit);
    }
}

void check_texture(const MaterialTextureView& t) {
  if (t.width < 1 || t.height < 1) throw std::invalid_argument("material textures: empty texture");
}

bool reduced_rule(const MaterialTextureView& t, int i0, int i1, int j0, int j1, double reduced_rule_cell) {
  return std::max(static_cast<double>(i1 - i0) / t.width, static_cast<double>(j1 - j0) / t.height) <= reduced_rule_cell;
}

// Appends the rule of each uniform cell, mapped onto it (points, sections).
void emit_cells(const MaterialTextureView& t, const ShellSection& base, double reduced_rule_cell,
                std::vector<double>& points, std::vector<ShellSection>& sections) {
  const QuadratureRule rule = element_quadrature(ElementType::quad8);
  const LineRule line = gauss_legendre(2);
  for_each_uniform_cell(t, 0, t.width, 0, t.height, [&](int i0, int i1, int j0, int j1) {
    // Cell in xi: [x0, x1] x [y0, y1]; the whole element maps with mid 0, half 1 exactly.
    const double x0 = -1 + 2.0 * i0 / t.width, x1 = -1 + 2.0 * i1 / t.width;
    const double y1 = 1 - 2.0 * j0 / t.height, y0 = 1 - 2.0 * j1 / t.height;
    const double mx = 0.5 * (x0 + x1), hx = 0.5 * (x1 - x0), my = 0.5 * (y0 + y1), hy = 0.5 * (y1 - y0);
    const ShellSection section{t.youngs_modulus[j0 * t.width + i0], base.poisson_ratio,
                               t.thickness[j0 * t.width + i0], base.density};
    if (reduced_rule(t, i0, i1, j0, j1, reduced_rule_cell)) {
      for (int b = 0; b < line.count; ++b)
        for (int a = 0; a < line.count; ++a) {
          const double weight = line.weight[a] * line.weight[b] * hx * hy;
          points.insert(points.end(), {mx + hx * line.t[a], my + hy * line.t[b], weight});
          sections.push_back(section);
        }
      return;
    }
    for (int q = 0; q < rule.count; ++q) {
      points.insert(points.end(), {mx + hx * rule.xi1[q], my + hy * rule.xi2[q], rule.weight[q] * hx * hy});
      sections.push_back(section);
    }
  });
}

inline void apply_plane_stress(double nu, double scale, const double in[3], double out[3]) {
  out[0] = scale * (in[0] + nu * in[1]);
  out[1] = scale * (nu * in[0] + in[1]);
  out[2] = scale * 0.5 * (1 - nu) * in[2];
}

void element_stiffness(const PointSectionBatch& b, std::int64_t e, const double* rotations, double* blocks,
                       double* forces) {
  const int npe = nodes_per_element(b.type);
  const int* nodes = b.connectivity + e * npe;
  double* K = blocks + e * npe * npe * 9;
  for (int i = 0; i < npe * npe * 9; ++i) K[i] = 0;
  double* f = forces ? forces + e * npe * 3 : nullptr;
  if (f)
    for (int i = 0; i < npe * 3; ++i) f[i] = 0;
  for (std::int64_t q = b.start[e]; q < b.start[e + 1]; ++q) {
    const double* pt = b.points + 3 * q;
    const ShellSection& sec = b.sections[q];
    const double nu = sec.poisson_ratio;
    const double dn = membrane_rigidity(sec.youngs_modulus, nu, sec.thickness);
    const double dm = bending_rigidity(sec.youngs_modulus, nu, sec.thickness);
    ShapeValues s;
    evaluate_shape(b.type, pt[0], pt[1], s);
    double Bm[max_element_nodes][9], Bb[max_element_nodes][9];
    const double w = pt[2] * fast_rows::rest_strain_rows(s, nodes, b.positions, npe, Bm, Bb);
    const double* R = rotations ? rotations + q * 9 : nullptr;
    if (R && f) {
      // Corrective term: B^T D B (X0 - R^T X0), B rotated afterwards (eq. 48).
      double strain_m[3] = {0, 0, 0}, strain_b[3] = {0, 0, 0};
      for (int a = 0; a < npe; ++a) {
        const double* x = b.positions + 3 * static_cast<long>(nodes[a]);
        double d[3];
        for (int k = 0; k < 3; ++k) d[k] = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
        for (int r = 0; r < 3; ++r)
          for (int k = 0; k < 3; ++k) {
            strain_m[r] += Bm[a][r * 3 + k] * d[k];
            strain_b[r] += Bb[a][r * 3 + k] * d[k];
          }
      }
      double sm[3], sb[3];
      apply_plane_stress(nu, dn, strain_m, sm);
      apply_plane_stress(nu, dm, strain_b, sb);
      for (int a = 0; a < npe; ++a) {
        double Rm[9], Rb[9];
        for (int i = 0; i < 9; ++i) Rm[i] = Bm[a][i], Rb[i] = Bb[a][i];
        rotate_rows(Rm, R);
        rotate_rows(Rb, R);
        for (int i = 0; i < 3; ++i) {
          double v = 0;
          for (int r = 0; r < 3; ++r) v += Rm[r * 3 + i] * sm[r] + Rb[r * 3 + i] * sb[r];
          f[a * 3 + i] += w * v;
        }
      }
    }
    if (R)
      for (int a = 0; a < npe; ++a) rotate_rows(Bm[a], R), rotate_rows(Bb[a], R);
    // K_ab += w (Bm_a^T Dn Bm_b + Bb_a^T Dm Bb_b), upper block triangle, mirrored below.
    for (int bb = 0; bb < npe; ++bb) {
      double DBm[9], DBb[9];  // D times the rows of node b, column by column
      for (int c = 0; c < 3; ++c) {
        const double vm[3] = {Bm[bb][c], Bm[bb][3 + c], Bm[bb][6 + c]};
        const double vb[3] = {Bb[bb][c], Bb[bb][3 + c], Bb[bb][6 + c]};
        double om[3], ob[3];
        apply_plane_stress(nu, w * dn, vm, om);
        apply_plane_stress(nu, w * dm, vb, ob);
        for (int r = 0; r < 3; ++r) DBm[r * 3 + c] = om[r], DBb[r * 3 + c] = ob[r];
      }
      for (int a = 0; a <= bb; ++a)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            double v = 0;
            for (int r = 0; r < 3; ++r) v += Bm[a][r * 3 + i] * DBm[r * 3 + j] + Bb[a][r * 3 + i] * DBb[r * 3 + j];
            K[(a * npe + bb) * 9 + i * 3 + j] += v;
          }
    }
  }
  for (int a = 0; a < npe; ++a)
    for (int bb = a + 1; bb < npe; ++bb)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) K[(bb * npe + a) * 9 + j * 3 + i] = K[(a * npe + bb) * 9 + i * 3 + j];
}


}  // namespace

std::int64_t material_texture_point_count(const MaterialTextureView& texture, double reduced_rule_cell) {
  check_texture(texture);
  const LineRule line = gauss_legendre(2);
  const std::int64_t full = element_quadrature(ElementType::quad8).count, reduced = line.count * line.count;
  std::int64_t points = 0;
  for_each_uniform_cell(texture, 0, texture.width, 0, texture.height, [&](int i0, int i1, int j0, int j1) {
    points += reduced_rule(texture, i0, i1, j0, j1, reduced_rule_cell) ? reduced : full;
  });
  return points;
}

void material_texture_quadrature(ElementType type, std::int64_t count, const MaterialTextureView* textures,
                                 const ShellSection* base, std::vector<std::int64_t>& start,
                                 std::vector<double>& points, std::vector<ShellSection>& sections,
                                 double reduced_rule_cell) {
  if (type != ElementType::quad8) throw std::invalid_argument("material textures: only quad8 elements are supported");
  // Counted first, so the arrays are allocated once at their size: growing them doubled
  // the memory of a texture whose texels all differ (~120 instead of 56 bytes a point).
  std::int64_t total = static_cast<std::int64_t>(sections.size());
  for (std::int64_t e = 0; e < count; ++e) total += material_texture_point_count(textures[e], reduced_rule_cell);
  points.reserve(3 * static_cast<std::size_t>(total));
  sections.reserve(static_cast<std::size_t>(total));
  if (start.empty()) start.push_back(0);
  for (std::int64_t e = 0; e < count; ++e) {
    emit_cells(textures[e], base[e], reduced_rule_cell, points, sections);
    start.push_back(static_cast<std::int64_t>(sections.size()));
  }
}

void point_section_stiffness(const PointSectionBatch& batch, const double* rotations, double* blocks, double* forces,
                             Execution execution) {
  forall(batch.count, [&](std::int64_t e) { element_stiffness(batch, e, rotations, blocks, forces); }, execution);
}

void point_section_deformation_gradients(const PointSectionBatch& b, const double* current, double* F,
                                         Execution execution) {
  const int npe = nodes_per_element(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* nodes = b.connectivity + e * npe;
        for (std::int64_t q = b.start[e]; q < b.start[e + 1]; ++q) {
          ShapeValues s;
          evaluate_shape(b.type, b.points[3 * q], b.points[3 * q + 1], s);
          fast_rows::SurfaceFrame p0, p;
          fast_rows::evaluate_surface_frame(s, nodes, b.positions, p0);
          fast_rows::evaluate_surface_frame(s, nodes, current, p);
          surface_deformation_gradient(p0.a1, p0.a2, p0.t0, p.a1, p.a2, p.t0, F + q * 9);
        }
      },
      execution);
}

void point_section_mass(const PointSectionBatch& b, double* mass, Execution execution) {
  const int npe = nodes_per_element(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* nodes = b.connectivity + e * npe;
        double* m = mass + e * npe * npe;
        for (int i = 0; i < npe * npe; ++i) m[i] = 0;
        for (std::int64_t q = b.start[e]; q < b.start[e + 1]; ++q) {
          ShapeValues s;
          evaluate_shape(b.type, b.points[3 * q], b.points[3 * q + 1], s);
          RestPoint p;
          evaluate_rest_point(s, nodes, b.positions, p);
          const double w = b.points[3 * q + 2] * p.j0 * b.sections[q].density * b.sections[q].thickness;
          for (int a = 0; a < npe; ++a)
            for (int c = 0; c < npe; ++c) m[a * npe + c] += w * s.N[a] * s.N[c];
        }
      },
      execution);
}

void point_section_load_weights(const PointSectionBatch& b, double* area_weights, double* mass_weights,
                                Execution execution) {
  const int npe = nodes_per_element(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* nodes = b.connectivity + e * npe;
        for (int a = 0; a < npe; ++a) area_weights[e * npe + a] = mass_weights[e * npe + a] = 0;
        for (std::int64_t q = b.start[e]; q < b.start[e + 1]; ++q) {
          ShapeValues s;
          evaluate_shape(b.type, b.points[3 * q], b.points[3 * q + 1], s);
          RestPoint p;
          evaluate_rest_point(s, nodes, b.positions, p);
          const double w = b.points[3 * q + 2] * p.j0;
          const double rho_h = b.sections[q].density * b.sections[q].thickness;
          for (int a = 0; a < npe; ++a) {
            area_weights[e * npe + a] += w * s.N[a];
            mass_weights[e * npe + a] += w * rho_h * s.N[a];
          }
        }
      },
      execution);
}

}  // namespace dgtex::kernels

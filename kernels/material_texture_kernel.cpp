#include "dgtex/kernels/material_texture_kernel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/gram_accumulation.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/vec3.h"
#include "plane_stress.h"
#include "shell_point_rows.h"
#include "shell_point_rows_batch.h"

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

// The corrective force of shell report eq. 48, B_R^T D B (X0 - R^T X0) times the weight w
// (B the point's unrotated rows, B_R the rotated ones), in two halves around the rotation
// of the rows: first the stresses D B (X0 - R^T X0) from the unrotated rows (bm(a, i),
// bb(a, i): entry i of node a's membrane and bending rows); add_corrective_force
// (plane_stress.h) then adds w B_R^T times them.
template <class MembraneRow, class BendingRow>
void corrective_stresses(const PointSectionBatch& b, const int* nodes, int npe, MembraneRow&& bm, BendingRow&& bb,
                         const double* R, double nu, double dn, double dm, double sm[3], double sb[3]) {
  double strain_m[3] = {0, 0, 0}, strain_b[3] = {0, 0, 0};
  for (int a = 0; a < npe; ++a) {
    const double* x = b.positions + 3 * static_cast<long>(nodes[a]);
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) {
        strain_m[r] += bm(a, r * 3 + k) * d[k];
        strain_b[r] += bb(a, r * 3 + k) * d[k];
      }
  }
  apply_plane_stress(nu, dn, strain_m, sm);
  apply_plane_stress(nu, dm, strain_b, sb);
}

// A point's strain rows (rotated, for a corotated point) with the rigidities and weight of
// its section: what both stiffness forms sum.
struct PointRows {
  double Bm[max_element_nodes][9], Bb[max_element_nodes][9];
  double nu, dn, dm, w;
};

// The rigidities and weight of point q (j0: its area element).
void set_section(const PointSectionBatch& b, std::int64_t q, double j0, PointRows& p) {
  const ShellSection& sec = b.sections[q];
  p.nu = sec.poisson_ratio;
  p.dn = membrane_rigidity(sec.youngs_modulus, p.nu, sec.thickness);
  p.dm = bending_rigidity(sec.youngs_modulus, p.nu, sec.thickness);
  p.w = b.points[3 * q + 2] * j0;
}

// Point q's PointRows (s: its shape values), rotated by R when given, one point at a time
// (the reference form); adds the corrective force to f (when both R and f are given).
void point_rows(const PointSectionBatch& b, const int* nodes, int npe, std::int64_t q, const ShapeValues& s,
                const double* R, double* f, PointRows& p) {
  set_section(b, q, fast_rows::rest_strain_rows(s, nodes, b.positions, npe, p.Bm, p.Bb), p);
  if (!R) return;
  double sm[3] = {0, 0, 0}, sb[3] = {0, 0, 0};
  if (f)
    corrective_stresses(
        b, nodes, npe, [&](int a, int i) { return p.Bm[a][i]; }, [&](int a, int i) { return p.Bb[a][i]; }, R, p.nu,
        p.dn, p.dm, sm, sb);
  for (int a = 0; a < npe; ++a) rotate_rows(p.Bm[a], R), rotate_rows(p.Bb[a], R);
  if (f) add_corrective_force(npe, p.Bm, p.Bb, sm, sb, p.w, f);
}

// The reference form: K_ab += w (Bm_a^T Dn Bm_b + Bb_a^T Dm Bb_b) point by point, block by
// block, upper block triangle, mirrored below.
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
    ShapeValues s;
    evaluate_shape(b.type, b.points[3 * q], b.points[3 * q + 1], s);
    PointRows p;
    point_rows(b, nodes, npe, q, s, rotations ? rotations + 9 * q : nullptr, f, p);
    for (int bb = 0; bb < npe; ++bb) {
      double DBm[9], DBb[9];  // D times the rows of node b, column by column
      for (int c = 0; c < 3; ++c) {
        const double vm[3] = {p.Bm[bb][c], p.Bm[bb][3 + c], p.Bm[bb][6 + c]};
        const double vb[3] = {p.Bb[bb][c], p.Bb[bb][3 + c], p.Bb[bb][6 + c]};
        double om[3], ob[3];
        apply_plane_stress(p.nu, p.w * p.dn, vm, om);
        apply_plane_stress(p.nu, p.w * p.dm, vb, ob);
        for (int r = 0; r < 3; ++r) DBm[r * 3 + c] = om[r], DBb[r * 3 + c] = ob[r];
      }
      for (int a = 0; a <= bb; ++a)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            double v = 0;
            for (int r = 0; r < 3; ++r) v += p.Bm[a][r * 3 + i] * DBm[r * 3 + j] + p.Bb[a][r * 3 + i] * DBb[r * 3 + j];
            K[(a * npe + bb) * 9 + i * 3 + j] += v;
          }
    }
  }
  for (int a = 0; a < npe; ++a)
    for (int bb = a + 1; bb < npe; ++bb)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) K[(bb * npe + a) * 9 + j * 3 + i] = K[(a * npe + bb) * 9 + i * 3 + j];
}

// Points per work item of point_section_stiffness: a fixed split of each element's points,
// so the sums (and their bits) do not depend on the thread count, and one element with a
// large texture still keeps every thread busy.
constexpr std::int64_t kStiffnessChunkPoints = 4096;

// Appends a point's six rows whose Gram is its stiffness: with D = c P(nu) and
// P = L L^T, L = [1 0 0; nu s 0; 0 0 t] (s = sqrt(1 - nu^2), t = sqrt((1 - nu) / 2)),
// B^T D B = (sqrt(c) L^T B)^T (sqrt(c) L^T B); c = w dn for the membrane rows, w dm for
// the bending rows. Needs c >= 0 and |nu| < 1 (point_section_stiffness checks).
void push_gram_rows(const PointRows& p, int npe, GramAccumulator& gram) {
  const double s = std::sqrt(1 - p.nu * p.nu), t = std::sqrt(0.5 * (1 - p.nu));
  for (int part = 0; part < 2; ++part) {
    const double(*B)[9] = part == 0 ? p.Bm : p.Bb;
    const double r = std::sqrt(p.w * (part == 0 ? p.dn : p.dm));
    double* row0 = gram.next();
    for (int a = 0; a < npe; ++a)
      for (int k = 0; k < 3; ++k) row0[3 * a + k] = r * (B[a][k] + p.nu * B[a][3 + k]);
    gram.push();
    double* row1 = gram.next();
    for (int a = 0; a < npe; ++a)
      for (int k = 0; k < 3; ++k) row1[3 * a + k] = r * s * B[a][3 + k];
    gram.push();
    double* row2 = gram.next();
    for (int a = 0; a < npe; ++a)
      for (int k = 0; k < 3; ++k) row2[3 * a + k] = r * t * B[a][6 + k];
    gram.push();
  }
}

// The shape values of points first .. min(first + kRestRowLanes, end) - 1 (a batch of the
// *_batch forms of shell_point_rows_batch.h); returns their count.
int batch_shapes(const PointSectionBatch& b, std::int64_t first, std::int64_t end, ShapeValues* s) {
  const int count = static_cast<int>(std::min<std::int64_t>(fast_rows::kRestRowLanes, end - first));
  for (int l = 0; l < count; ++l)
    evaluate_shape(b.type, b.points[3 * (first + l)], b.points[3 * (first + l) + 1], s[l]);
  return count;
}

// The surface deformation gradient at a point (s: its shape values) between the rest and
// current positions.
void point_deformation_gradient(const PointSectionBatch& b, const int* nodes, const ShapeValues& s,
                                const double* current, double F[9]) {
  fast_rows::SurfaceFrame p0, p;
  fast_rows::evaluate_surface_frame(s, nodes, b.positions, p0);
  fast_rows::evaluate_surface_frame(s, nodes, current, p);
  surface_deformation_gradient(p0.a1, p0.a2, p0.t0, p.a1, p.a2, p.t0, F);
}

void check_sections(const PointSectionBatch& b) {
  for (std::int64_t q = b.start[0]; q < b.start[b.count]; ++q) {
    const ShellSection& s = b.sections[q];
    if (!(s.youngs_modulus >= 0 && s.thickness >= 0 && std::abs(s.poisson_ratio) < 1 && b.points[3 * q + 2] >= 0))
      throw std::invalid_argument("point_section_stiffness: point " + std::to_string(q) + " has E = " +
                                  std::to_string(s.youngs_modulus) + ", h = " + std::to_string(s.thickness) +
                                  ", nu = " + std::to_string(s.poisson_ratio) + ", weight " +
                                  std::to_string(b.points[3 * q + 2]) +
                                  "; expected E >= 0, h >= 0, -1 < nu < 1 and a weight >= 0");
  }
}

// point_section_stiffness and its corotated form: rotations per point from `rotations`, or
// formed here from `current` (one of them or neither).
void gram_stiffness(const PointSectionBatch& batch, const double* rotations, const double* current, double* blocks,
                    double* forces, Execution execution) {
  check_sections(batch);
  const int npe = nodes_per_element(batch.type), n = 3 * npe;
  // Work items: each element's points in chunks of kStiffnessChunkPoints (at least one
  // item an element, so an element without points gets zeros).
  std::vector<std::int64_t> first_item(static_cast<std::size_t>(batch.count) + 1, 0);
  for (std::int64_t e = 0; e < batch.count; ++e) {
    const std::int64_t points = batch.start[e + 1] - batch.start[e];
    const std::int64_t chunks = (points + kStiffnessChunkPoints - 1) / kStiffnessChunkPoints;
    first_item[e + 1] = first_item[e] + std::max<std::int64_t>(1, chunks);
  }
  const std::int64_t items = first_item[batch.count];
  std::vector<std::int64_t> item_element(static_cast<std::size_t>(items));
  for (std::int64_t e = 0; e < batch.count; ++e)
    for (std::int64_t i = first_item[e]; i < first_item[e + 1]; ++i) item_element[i] = e;
  // Each item's sums: the upper triangle of its n x n Gram (row-major) and its forces.
  std::vector<double> item_gram(static_cast<std::size_t>(items) * n * n), item_force(forces ? items * n : 0);
  forall_then(
      items,
      [&](std::int64_t item) {
        const std::int64_t e = item_element[item];
        const int* nodes = batch.connectivity + e * npe;
        const std::int64_t q0 = batch.start[e] + (item - first_item[e]) * kStiffnessChunkPoints;
        const std::int64_t q1 = std::min(q0 + kStiffnessChunkPoints, batch.start[e + 1]);
        double* f = forces ? item_force.data() + item * n : nullptr;
        if (f) std::fill(f, f + n, 0.0);
        GramAccumulator gram(n, 6 * std::max<std::int64_t>(1, q1 - q0));
        constexpr int lanes = fast_rows::kRestRowLanes;
        for (std::int64_t first = q0; first < q1; first += lanes) {
          ShapeValues s[lanes];
          const int count = batch_shapes(batch, first, q1, s);
          fast_rows::RestRowsBatch rest;
          fast_rows::rest_strain_rows_batch(s, count, nodes, batch.positions, npe, rest);
          // The same steps as point_rows, each over the batch's points.
          PointRows p[lanes];
          for (int l = 0; l < count; ++l) set_section(batch, first + l, rest.j0[l], p[l]);
          const bool rotated = rotations || current;
          double R[lanes][9], sm[lanes][3], sb[lanes][3], F[lanes][9];
          if (current) fast_rows::deformation_gradient_batch(s, count, nodes, batch.positions, current, npe, F);
          for (int l = 0; rotated && l < count; ++l) {
            if (current) polar_rotation(F[l], R[l]);
            else std::copy(rotations + 9 * (first + l), rotations + 9 * (first + l + 1), R[l]);
            if (f)
              corrective_stresses(
                  batch, nodes, npe, [&](int a, int i) { return rest.Bm[a][i][l]; },
                  [&](int a, int i) { return rest.Bb[a][i][l]; }, R[l], p[l].nu, p[l].dn, p[l].dm, sm[l], sb[l]);
          }
          if (rotated) fast_rows::rotate_rows_batch(R, count, npe, rest);
          for (int l = 0; l < count; ++l) {
            rest.lane(l, npe, p[l].Bm, p[l].Bb);
            if (rotated && f) add_corrective_force(npe, p[l].Bm, p[l].Bb, sm[l], sb[l], p[l].w, f);
            push_gram_rows(p[l], npe, gram);
          }
        }
        gram.flush();
        double* G = item_gram.data() + item * n * n;
        for (int i = 0; i < n; ++i)
          for (int j = i; j < n; ++j) G[i * n + j] = gram(i, j);
      },
      batch.count,
      [&](std::int64_t e) {
        // The items' sums in order, into the element's blocks (mirrored) and forces.
        double* K = blocks + e * npe * npe * 9;
        for (int i = 0; i < n; ++i)
          for (int j = i; j < n; ++j) {
            double v = 0;
            for (std::int64_t item = first_item[e]; item < first_item[e + 1]; ++item)
              v += item_gram[(item * n + i) * n + j];
            K[((i / 3) * npe + j / 3) * 9 + (i % 3) * 3 + j % 3] = v;
            K[((j / 3) * npe + i / 3) * 9 + (j % 3) * 3 + i % 3] = v;
          }
        if (!forces) return;
        for (int i = 0; i < n; ++i) {
          double v = 0;
          for (std::int64_t item = first_item[e]; item < first_item[e + 1]; ++item) v += item_force[item * n + i];
          forces[e * n + i] = v;
        }
      },
      execution);
}

// visit(q, shape values, area element j0) for element e's points in order, their j0 formed
// several at a time (bitwise evaluate_rest_point's).
template <class Visit>
void for_each_point_area(const PointSectionBatch& b, std::int64_t e, Visit&& visit) {
  const int npe = nodes_per_element(b.type);
  const int* nodes = b.connectivity + e * npe;
  constexpr int lanes = fast_rows::kRestRowLanes;
  for (std::int64_t first = b.start[e]; first < b.start[e + 1]; first += lanes) {
    ShapeValues s[lanes];
    const int count = batch_shapes(b, first, b.start[e + 1], s);
    double j0[lanes];
    fast_rows::rest_area_factor_batch(s, count, nodes, b.positions, npe, j0);
    for (int l = 0; l < count; ++l) visit(first + l, s[l], j0[l]);
  }
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
  gram_stiffness(batch, rotations, nullptr, blocks, forces, execution);
}

void point_section_corotated_stiffness(const PointSectionBatch& batch, const double* current_positions,
                                       double* blocks, double* forces, Execution execution) {
  gram_stiffness(batch, nullptr, current_positions, blocks, forces, execution);
}

void point_section_stiffness_reference(const PointSectionBatch& batch, const double* rotations, double* blocks,
                                       double* forces) {
  for (std::int64_t e = 0; e < batch.count; ++e) element_stiffness(batch, e, rotations, blocks, forces);
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
          point_deformation_gradient(b, nodes, s, current, F + q * 9);
        }
      },
      execution);
}

void point_section_mass(const PointSectionBatch& b, double* mass, Execution execution) {
  const int npe = nodes_per_element(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        double* m = mass + e * npe * npe;
        for (int i = 0; i < npe * npe; ++i) m[i] = 0;
        for_each_point_area(b, e, [&](std::int64_t q, const ShapeValues& s, double j0) {
          const double w = b.points[3 * q + 2] * j0 * b.sections[q].density * b.sections[q].thickness;
          for (int a = 0; a < npe; ++a)
            for (int c = 0; c < npe; ++c) m[a * npe + c] += w * s.N[a] * s.N[c];
        });
      },
      execution);
}

void point_section_load_weights(const PointSectionBatch& b, double* area_weights, double* mass_weights,
                                Execution execution) {
  const int npe = nodes_per_element(b.type);
  forall(
      b.count,
      [&](std::int64_t e) {
        for (int a = 0; a < npe; ++a) area_weights[e * npe + a] = mass_weights[e * npe + a] = 0;
        for_each_point_area(b, e, [&](std::int64_t q, const ShapeValues& s, double j0) {
          const double w = b.points[3 * q + 2] * j0;
          const double rho_h = b.sections[q].density * b.sections[q].thickness;
          for (int a = 0; a < npe; ++a) {
            area_weights[e * npe + a] += w * s.N[a];
            mass_weights[e * npe + a] += w * rho_h * s.N[a];
          }
        });
      },
      execution);
}

}  // namespace dgtex::kernels

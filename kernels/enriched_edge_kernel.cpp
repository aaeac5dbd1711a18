#include "dgtex/kernels/enriched_edge_kernel.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <stdexcept>
#include <cmath>
#include <vector>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/edge_frame.h"
#include "dgtex/kernels/vec3.h"
#include "dgtex/kernels/gram_accumulation.h"

namespace dgtex::kernels {
namespace {

// One side of an edge at parameter t (in the plus element's direction).
struct Side {
  int element = -1;
  std::int64_t enriched = -1;  // index in the element batch, or -1
  ShapeValues standard;
  EnrichedShapeValues shape;   // whole local basis (just the standard one if not enriched)
  RestPoint point;
  double tangent[3];           // dphi0/dt in this side's own edge direction
  double dxi_dt[2];
};

void evaluate_side(const EnrichedEdgeBatch& b, int element, int local_edge, double t, Side& s) {
  const int npe = nodes_per_element(b.type);
  double xi[2];
  local_edge_point(b.type, local_edge, t, xi, s.dxi_dt);
  s.element = element;
  s.enriched = b.enriched_index[element];
  evaluate_shape(b.type, xi[0], xi[1], s.standard);
  evaluate_rest_point(s.standard, b.connectivity + static_cast<std::int64_t>(element) * npe, b.positions, s.point);
  tangent_along(s.point, s.dxi_dt, s.tangent);
  if (s.enriched >= 0) {
    evaluate_enriched_shape(*b.elements, s.enriched, xi[0], xi[1], s.standard, s.shape);
  } else {
    s.shape.count = npe;
    for (int a = 0; a < npe; ++a) {
      s.shape.N[a] = s.standard.N[a];
      for (int c = 0; c < 2; ++c) s.shape.dN[a][c] = s.standard.dN[a][c];
      for (int c = 0; c < 3; ++c) s.shape.d2N[a][c] = s.standard.d2N[a][c];
    }
  }
}

void side_global_nodes(const EnrichedEdgeBatch& b, int element, int* out) {
  const int W = b.elements->width;
  if (element < 0) {
    for (int a = 0; a < W; ++a) out[a] = -1;
    return;
  }
  const std::int64_t enriched = b.enriched_index[element];
  if (enriched >= 0) {
    enriched_global_nodes(*b.elements, enriched, out);
    return;
  }
  const int npe = nodes_per_element(b.type);
  for (int a = 0; a < W; ++a) out[a] = a < npe ? b.connectivity[static_cast<std::int64_t>(element) * npe + a] : -1;
}

// A side's basis count: its enriched element's, else the element's standard functions.
int side_basis_count(const EnrichedEdgeBatch& b, int element) {
  const std::int64_t enriched = b.enriched_index[element];
  return enriched >= 0 ? enriched_basis_count(*b.elements, enriched) : nodes_per_element(b.type);
}

// One side of an edge point as the stiffness passes read it: its rest frame and tangent and
// the first derivatives of its local basis, from a Side just evaluated or from the records
// of enriched_edge_rest_sides (the same numbers).
struct SideView {
  int count = 0;
  const double* tangent = nullptr;  // [3]
  const double* t0 = nullptr;       // [3]
  const double* a1 = nullptr;       // [3]
  const double* a2 = nullptr;       // [3]
  double j0 = 0;
  const double* dxi_dt = nullptr;   // [2]
  const double* dN = nullptr;       // count x 2
};

SideView view_of(const Side& s) {
  return {s.shape.count, s.tangent, s.point.t0, s.point.a1, s.point.a2, s.point.j0, s.dxi_dt, &s.shape.dN[0][0]};
}

// A side's record in EnrichedEdgeRestSides::data: tangent, t0, a1, a2 (3 each), j0,
// dxi_dt (2), then dN (count x 2).
constexpr int side_record_head = 15;
int side_record_size(int count) { return side_record_head + 2 * count; }

void write_side_record(const Side& s, double* out) {
  std::copy_n(s.tangent, 3, out);
  std::copy_n(s.point.t0, 3, out + 3);
  std::copy_n(s.point.a1, 3, out + 6);
  std::copy_n(s.point.a2, 3, out + 9);
  out[12] = s.point.j0;
  std::copy_n(s.dxi_dt, 2, out + 13);
  std::copy_n(&s.shape.dN[0][0], 2 * s.shape.count, out + side_record_head);
}

SideView view_of_record(int count, const double* r) {
  return {count, r, r + 3, r + 6, r + 9, r[12], r + 13, r + side_record_head};
}

// --- Quadrature ------------------------------------------------------------------------

struct SegmentBuilder {
  const EnrichedEdgeBatch& b;
  const EnrichedQuadratureOptions& options;
  const int* edge;  // 4 entries
  std::vector<double>& out;
  std::vector<int> texels;

  // Border texel of piece `piece` on one side.
  void piece_texel(int side, int piece, int ij[2]) const {
    const int t = b.elements->resolution;
    const double tm = -1 + (piece + 0.5) * 2.0 / t;
    double xi[2], dxi[2];
    local_edge_point(b.type, edge[2 * side + 1], side == 0 ? tm : -tm, xi, dxi);
    containing_texel(b.type, t, xi[0], xi[1], ij[0], ij[1]);
  }

  bool uniform(int p0, int length) {
    for (int side = 0; side < 2; ++side) {
      const int element = edge[2 * side];
      if (element < 0 || b.enriched_index[element] < 0) continue;
      const EnrichedElementBatch& eb = *b.elements;
      const std::int64_t e = b.enriched_index[element];
      const int first = eb.enrichment_start[e], count = eb.enrichment_start[e + 1] - first;
      texels.resize(2 * static_cast<std::size_t>(length));
      for (int p = 0; p < length; ++p) piece_texel(side, p0 + p, &texels[2 * p]);
      int reference[2];
      piece_texel(side, p0 + length / 2, reference);
      if (!texels_share_one_quadratic(b.type, eb.resolution, eb.textures + first, count, texels.data(), length,
                                      reference, length, options.merge_tolerance))
        return false;
    }
    return true;
  }

  void emit(int p0, int length, int n) {
    const int t = b.elements->resolution;
    const double a = -1 + p0 * 2.0 / t, half = length * 1.0 / t;
    const LineRule g = gauss_legendre(n);
    for (int q = 0; q < g.count; ++q) out.insert(out.end(), {a + half * (1 + g.t[q]), half * g.weight[q]});
  }

  void visit(int p0, int length) {
    if (length == 1) return emit(p0, 1, 2);
    if (options.adaptive && uniform(p0, length)) return emit(p0, length, b.quadrature_points);
    const int first = (length + 1) / 2;
    visit(p0, first);
    visit(p0 + first, length - first);
  }
};

void edge_points(const EnrichedEdgeBatch& b, std::int64_t e, const EnrichedQuadratureOptions& options,
                 std::vector<double>& out) {
  out.clear();
  SegmentBuilder builder{b, options, b.edges + 4 * e, out, {}};
  const int t = b.elements->resolution;
  if (options.adaptive && builder.uniform(0, t)) {
    const LineRule g = gauss_legendre(b.quadrature_points);  // the standard edge rule
    for (int q = 0; q < g.count; ++q) out.insert(out.end(), {g.t[q], g.weight[q]});
    return;
  }
  builder.visit(0, t);
}

// --- Stiffness -------------------------------------------------------------------------

// Current unit normal of one side from its whole basis.
void current_normal(const SideView& s, const int* global, const double* current, double tangent[3], double normal[3]) {
  double a1[3] = {0, 0, 0}, a2[3] = {0, 0, 0};
  for (int a = 0; a < s.count; ++a) {
    const double* x = current + 3 * static_cast<std::int64_t>(global[a]);
    for (int k = 0; k < 3; ++k) a1[k] += s.dN[2 * a] * x[k], a2[k] += s.dN[2 * a + 1] * x[k];
  }
  for (int k = 0; k < 3; ++k) tangent[k] = a1[k] * s.dxi_dt[0] + a2[k] * s.dxi_dt[1];
  cross3(a1, a2, normal);
  normalize3(normal);
}

// R = Cur Rest^T of one point: the edge frame (tangent, averaged normal) from rest to
// current, each side's current normal from its whole basis (global: the edge's 2W slots).
// A clamped boundary edge (no minus side) keeps R = I: its prescribed normal is fixed in
// space (shell_edge_rotations says why).
void edge_point_rotation(const SideView& plus, const SideView* minus, const int* global, int W,
                         const double* current, double* R) {
  if (!minus) {
    for (int i = 0; i < 9; ++i) R[i] = i % 4 == 0 ? 1.0 : 0.0;
    return;
  }
  double rest[9], cur[9], tangent[3], n_plus[3], n_minus[3], unused[3];
  edge_frame(plus.tangent, plus.t0, minus->t0, rest);
  current_normal(plus, global, current, tangent, n_plus);
  current_normal(*minus, global + W, current, unused, n_minus);
  edge_frame(tangent, n_plus, n_minus, cur);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      R[i * 3 + j] = cur[i * 3 + 0] * rest[j * 3 + 0] + cur[i * 3 + 1] * rest[j * 3 + 1] + cur[i * 3 + 2] * rest[j * 3 + 2];
}

// rotations: one per point, or null; current (with rotations null): each point's rotation
// formed here from the sides this pass evaluates anyway (edge_point_rotation), or null: linear.
// rest_sides: the sides' records (enriched_edge_rest_sides) read instead of evaluating them.
void edge_stiffness(const EnrichedEdgeBatch& b, const EdgeQuadrature& quad, const EnrichedEdgeLocalLayout& layout,
                    std::int64_t e, const double* rotations, const double* current, double* blocks, double* forces,
                    const EnrichedEdgeRestSides* rest_sides = nullptr) {
  const int npe = nodes_per_element(b.type);
  const int W = b.elements->width;
  const int nb = 2 * W;
  const int* ed = b.edges + 4 * e;
  const bool interior = ed[2] >= 0;
  const int sides = interior ? 2 : 1;

  const ShellSection& sp = b.sections[ed[0]];
  const ShellSection& sm = b.sections[interior ? ed[2] : ed[0]];
  const double dm_plus = bending_rigidity(sp.youngs_modulus, sp.poisson_ratio, sp.thickness);
  const double dm_minus = bending_rigidity(sm.youngs_modulus, sm.poisson_ratio, sm.thickness);
  const double penalty = b.penalty / b.edge_size[e] * (interior ? 0.5 * (dm_plus + dm_minus) : dm_plus);

  // Edges next to enriched elements couple the normals by the penalty alone
  // (Babuska-Zlamal style), without the consistency and symmetry terms of the plain edges:
  // enriched second derivatives come from the texture and are texel-sharp next to a cut,
  // so their moment on the edge is not bounded by the element energy as for polynomials,
  // and no eta / h^e makes the consistent form coercive (a fractured tri6 mesh gave K an
  // eigenvalue of -6% of its largest; dropping the terms of the enriched functions alone
  // still left -4e-4). Penalty-only coupling is positive semi-definite by construction; it
  // is not consistent, an error controlled by eta on these few edges. A departure from the
  // thesis, which does not discuss it.
  // Compact numbering of the used local slots: side 0's functions, then side 1's.
  Side side_data[2];
  int counts[2] = {0, 0};
  for (int s = 0; s < sides; ++s) counts[s] = side_basis_count(b, ed[2 * s]);
  const int m = counts[0] + counts[1];
  // K = sum_q ds penalty G_q G_q^T: rows sqrt(ds penalty) G_q, summed by blocked products.
  // An edge whose points all lie on a cut (drop_cut_edge_points) has none: K stays null and
  // its blocks are written as 0.
  const std::int64_t points = quad.start[e + 1] - quad.start[e];
  std::unique_ptr<GramAccumulator> K = points > 0 ? std::make_unique<GramAccumulator>(3 * m, points) : nullptr;
  std::vector<double> G(3 * static_cast<std::size_t>(m)), f(3 * static_cast<std::size_t>(m), 0.0);
  std::vector<int> global;
  if (current) {
    global.resize(static_cast<std::size_t>(nb));
    enriched_edge_global_nodes(b, e, global.data());
  }
  SideView side_view[2];
  for (std::int64_t q = quad.start[e]; q < quad.start[e + 1]; ++q) {
    const double t = quad.points[2 * q], wt = quad.points[2 * q + 1];
    if (rest_sides) {
      const int* c = rest_sides->counts.data() + 2 * e;
      const double* record = rest_sides->data.data() + rest_sides->offset[e] +
                             (q - quad.start[e]) * (side_record_size(c[0]) + (interior ? side_record_size(c[1]) : 0));
      side_view[0] = view_of_record(c[0], record);
      if (interior) side_view[1] = view_of_record(c[1], record + side_record_size(c[0]));
    } else {
      evaluate_side(b, ed[0], ed[1], t, side_data[0]);
      side_view[0] = view_of(side_data[0]);
      if (interior) {
        evaluate_side(b, ed[2], ed[3], -t, side_data[1]);
        side_view[1] = view_of(side_data[1]);
      }
    }
    const SideView& plus = side_view[0];
    const double ds = std::sqrt(dot3(plus.tangent, plus.tangent)) * wt;
    double tau[3] = {plus.tangent[0], plus.tangent[1], plus.tangent[2]};
    normalize3(tau);
    for (int s = 0; s < sides; ++s) {
      const SideView& sd = side_view[s];
      const double sign = s == 0 ? 1.0 : -1.0;
      double nu_vec[3];
      cross3(sd.t0, tau, nu_vec);
      // nu . dt for a displacement along each axis, without forming normal_change_operator's
      // T = ([w]x - t0 t0^T [w]x) / j0, w = a1 dN_2 - a2 dN_1: nu = t0 x tau is normal to
      // t0, so nu^T T = (nu x w)^T / j0 = dN_2 (nu x a1) / j0 - dN_1 (nu x a2) / j0. Two
      // vectors per side and point, 6 multiply-adds a function (the operator's form took
      // ~5 % of fracture's run).
      double c1[3], c2[3];
      cross3(nu_vec, sd.a1, c1);
      cross3(nu_vec, sd.a2, c2);
      for (int c = 0; c < 3; ++c) c1[c] = sign * c1[c] / sd.j0, c2[c] = sign * c2[c] / sd.j0;
      for (int a = 0; a < counts[s]; ++a) {
        const int i = s == 0 ? a : counts[0] + a;
        const double* dN = sd.dN + 2 * a;
        for (int c = 0; c < 3; ++c) G[3 * i + c] = dN[1] * c1[c] - dN[0] * c2[c];
      }
    }
    double fused_rotation[9];
    const double* R = rotations ? rotations + 9 * q : nullptr;
    if (current) {
      edge_point_rotation(side_view[0], interior ? &side_view[1] : nullptr, global.data(), W, current, fused_rotation);
      R = fused_rotation;
    }
    double gd = 0;  // over the standard functions; enriched X0 = 0
    if (R && forces) {
      for (int s = 0; s < sides; ++s) {
        const int* nodes = b.connectivity + static_cast<std::int64_t>(ed[2 * s]) * npe;
        for (int a = 0; a < npe; ++a) {
          const double* x = b.positions + 3 * static_cast<std::int64_t>(nodes[a]);
          const int i = s == 0 ? a : counts[0] + a;
          for (int k = 0; k < 3; ++k)
            gd += G[3 * i + k] * (x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]));
        }
      }
    }
    if (R) {
      for (int i = 0; i < m; ++i) {
        double g2[3];
        for (int c = 0; c < 3; ++c)
          g2[c] = G[3 * i + 0] * R[c * 3 + 0] + G[3 * i + 1] * R[c * 3 + 1] + G[3 * i + 2] * R[c * 3 + 2];
        for (int c = 0; c < 3; ++c) G[3 * i + c] = g2[c];
      }
    }
    const int n3 = 3 * m;
    const double root = std::sqrt(ds * penalty);
    double* row = K->next();
    for (int i = 0; i < n3; ++i) row[i] = root * G[i];
    if (R && forces) {
      const double s = root * gd;
      for (int i = 0; i < n3; ++i) f[i] += row[i] * s;
    }
    K->push();
  }
  if (K) K->flush();
  // The edge's compact local matrix (enriched_edge_local_layout: side 0's functions, then
  // side 1's), 0 on an edge without points.
  double* out = blocks + layout.block_start[e] * 9;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      double* blk = out + (static_cast<std::int64_t>(i) * m + j) * 9;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) blk[r * 3 + c] = K ? (*K)(3 * i + r, 3 * j + c) : 0.0;
    }
  if (forces) std::copy(f.begin(), f.end(), forces + layout.function_start[e] * 3);
}

}  // namespace

void enriched_edge_quadrature(const EnrichedEdgeBatch& batch, const EnrichedQuadratureOptions& options,
                              std::vector<std::int64_t>& start, std::vector<double>& points, Execution execution) {
  std::vector<std::vector<double>> per_edge(static_cast<std::size_t>(batch.count));
  forall(batch.count, [&](std::int64_t e) { edge_points(batch, e, options, per_edge[e]); }, execution);
  start.assign(static_cast<std::size_t>(batch.count) + 1, 0);
  for (std::int64_t e = 0; e < batch.count; ++e)
    start[e + 1] = start[e] + static_cast<std::int64_t>(per_edge[e].size() / 2);
  points.resize(static_cast<std::size_t>(start[batch.count]) * 2);
  forall(batch.count, [&](std::int64_t e) { std::copy(per_edge[e].begin(), per_edge[e].end(), points.begin() + start[e] * 2); },
         execution);
}

void enriched_edge_global_nodes(const EnrichedEdgeBatch& b, std::int64_t e, int* out) {
  const int W = b.elements->width;
  side_global_nodes(b, b.edges[4 * e], out);
  side_global_nodes(b, b.edges[4 * e + 2], out + W);
}

EnrichedEdgeLocalLayout enriched_edge_local_layout(const EnrichedEdgeBatch& b) {
  EnrichedEdgeLocalLayout layout;
  layout.widths.resize(static_cast<std::size_t>(b.count));
  layout.function_start.assign(static_cast<std::size_t>(b.count) + 1, 0);
  layout.block_start.assign(static_cast<std::size_t>(b.count) + 1, 0);
  for (std::int64_t e = 0; e < b.count; ++e) {
    const int* ed = b.edges + 4 * e;
    const int width = side_basis_count(b, ed[0]) + (ed[2] >= 0 ? side_basis_count(b, ed[2]) : 0);
    layout.widths[e] = width;
    layout.function_start[e + 1] = layout.function_start[e] + width;
    layout.block_start[e + 1] = layout.block_start[e] + static_cast<std::int64_t>(width) * width;
  }
  return layout;
}

void enriched_edge_local_global_nodes(const EnrichedEdgeBatch& b, std::int64_t e, int* out) {
  const int W = b.elements->width;
  std::vector<int> padded(2 * static_cast<std::size_t>(W));
  enriched_edge_global_nodes(b, e, padded.data());
  const int* ed = b.edges + 4 * e;
  const int plus = side_basis_count(b, ed[0]), minus = ed[2] >= 0 ? side_basis_count(b, ed[2]) : 0;
  std::copy_n(padded.begin(), plus, out);
  std::copy_n(padded.begin() + W, minus, out + plus);
}

// The edge passes below hand out their edges dynamically (forall_dynamic): a few edges of
// very different cost (two sides or one, texel-resolving points beside a cut or the
// standard rule). The slinky's eight took 2.0 ms a step on 2 threads with static chunks,
// 1.35 dynamically (1 thread: 2.4). Each edge writes only its own blocks, forces or records.
void enriched_edge_stiffness(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature, const double* rotations,
                             double* blocks, double* forces, Execution execution) {
  const EnrichedEdgeLocalLayout layout = enriched_edge_local_layout(batch);
  forall_dynamic(
      batch.count,
      [&](std::int64_t e) { edge_stiffness(batch, quadrature, layout, e, rotations, nullptr, blocks, forces); },
      execution);
}

void enriched_edge_corotated_stiffness(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                                       const double* current, double* blocks, double* forces, Execution execution) {
  const EnrichedEdgeLocalLayout layout = enriched_edge_local_layout(batch);
  forall_dynamic(
      batch.count,
      [&](std::int64_t e) { edge_stiffness(batch, quadrature, layout, e, nullptr, current, blocks, forces); },
      execution);
}

void enriched_edge_rest_sides(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                              EnrichedEdgeRestSides& out, Execution execution) {
  // Sizes first (a side's count is its element's basis count, the same at every point).
  out.counts.assign(2 * static_cast<std::size_t>(batch.count), 0);
  out.offset.assign(static_cast<std::size_t>(batch.count) + 1, 0);
  for (std::int64_t e = 0; e < batch.count; ++e) {
    const int* ed = batch.edges + 4 * e;
    std::int64_t record = 0;
    for (int s = 0; s < 2; ++s) {
      const int element = ed[2 * s];
      if (element < 0) continue;
      const int count = side_basis_count(batch, element);
      out.counts[2 * e + s] = count;
      record += side_record_size(count);
    }
    out.offset[e + 1] = out.offset[e] + record * (quadrature.start[e + 1] - quadrature.start[e]);
  }
  out.data.resize(static_cast<std::size_t>(out.offset[batch.count]));
  // An evaluated side whose count is not its element's would break the layout: reported after
  // the loop (nothing may be thrown out of a parallel region).
  std::atomic<bool> mismatch{false};
  forall_dynamic(
      batch.count,
      [&](std::int64_t e) {
        const int* ed = batch.edges + 4 * e;
        const bool interior = ed[2] >= 0;
        double* record = out.data.data() + out.offset[e];
        Side side;
        for (std::int64_t q = quadrature.start[e]; q < quadrature.start[e + 1]; ++q) {
          const double t = quadrature.points[2 * q];
          for (int s = 0; s < (interior ? 2 : 1); ++s) {
            evaluate_side(batch, ed[2 * s], ed[2 * s + 1], s == 0 ? t : -t, side);
            if (side.shape.count != out.counts[2 * e + s]) {
              mismatch = true;
              return;
            }
            write_side_record(side, record);
            record += side_record_size(side.shape.count);
          }
        }
      },
      execution);
  if (mismatch)
    throw std::logic_error("enriched_edge_rest_sides: a side's basis count differs from its element's");
}

void enriched_edge_corotated_stiffness(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                                       const EnrichedEdgeRestSides& rest_sides, const double* current,
                                       double* blocks, double* forces, Execution execution) {
  const EnrichedEdgeLocalLayout layout = enriched_edge_local_layout(batch);
  forall_dynamic(
      batch.count,
      [&](std::int64_t e) { edge_stiffness(batch, quadrature, layout, e, nullptr, current, blocks, forces, &rest_sides); },
      execution);
}

void enriched_edge_rotations(const EnrichedEdgeBatch& b, const EdgeQuadrature& quad, const double* current,
                             double* rotations, Execution execution) {
  const int W = b.elements->width;
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* ed = b.edges + 4 * e;
        const bool interior = ed[2] >= 0;
        std::vector<int> global(2 * static_cast<std::size_t>(W));
        enriched_edge_global_nodes(b, e, global.data());
        Side plus, minus;
        for (std::int64_t q = quad.start[e]; q < quad.start[e + 1]; ++q) {
          const double t = quad.points[2 * q];
          evaluate_side(b, ed[0], ed[1], t, plus);
          if (interior) evaluate_side(b, ed[2], ed[3], -t, minus);
          const SideView plus_view = view_of(plus);
          SideView minus_view;
          if (interior) minus_view = view_of(minus);
          edge_point_rotation(plus_view, interior ? &minus_view : nullptr, global.data(), W, current,
                              rotations + 9 * q);
        }
      },
      execution);
}

}  // namespace dgtex::kernels

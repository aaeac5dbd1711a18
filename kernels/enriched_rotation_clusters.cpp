#include "dgtex/kernels/enriched_rotation_clusters.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/kernels/flood_fill.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/texel_grid.h"
#include "dgtex/kernels/vec3.h"

namespace dgtex::kernels {
namespace {

// Packed blocks per work item of the rotated sum, at most: its 9 partial sums (144 KB) stay
// in L2 while every cluster streams its stretch of the 9 planes.
constexpr std::int64_t cluster_tile_blocks = 2048;
// Functions per work item of the corrective forces.
constexpr int cluster_force_tile = 32;

// Where row a of the packed upper blocks of n functions starts.
std::int64_t packed_row_start(int n, int a) {
  return static_cast<std::int64_t>(a) * n - static_cast<std::int64_t>(a) * (a - 1) / 2;
}

// Cut tips of one element: texel corners (x, y) inside the tile where exactly one wall edge
// ends (corners on the tile border or next to an inactive texel are not tips: cuts end
// there on the border, not inside the shell).
std::vector<std::pair<int, int>> cut_tips(ElementType type, int T, const std::uint8_t* flags) {
  auto flag = [&](int i, int j, std::uint8_t bit) {
    return i >= 0 && j >= 0 && i < T && j < T && (flags[j * T + i] & bit);
  };
  std::vector<std::pair<int, int>> tips;
  for (int y = 1; y < T; ++y)
    for (int x = 1; x < T; ++x) {
      bool inside = true;
      for (int dj = -1; dj <= 0; ++dj)
        for (int di = -1; di <= 0; ++di) inside = inside && texel_in_domain(type, T, flags, x + di, y + dj);
      if (!inside) continue;
      // Edges at the corner: up and down (east walls of the texels left of it), left and
      // right (north walls of the texels below it).
      const int degree = flag(x - 1, y, wall_east) + flag(x - 1, y - 1, wall_east) + flag(x - 1, y - 1, wall_north) +
                         flag(x, y - 1, wall_north);
      if (degree == 1) tips.emplace_back(x, y);
    }
  return tips;
}

// The same from a mask of the texels in the domain (texel_in_domain per texel), row by row
// without a call per texel: the fast kernel's form.
std::vector<std::pair<int, int>> cut_tips(int T, const std::uint8_t* flags, const std::uint8_t* inside) {
  std::vector<std::pair<int, int>> tips;
  for (int y = 1; y < T; ++y) {
    const std::uint8_t *below = flags + (y - 1) * T, *above = flags + y * T;
    const std::uint8_t *in_below = inside + (y - 1) * T, *in_above = inside + y * T;
    for (int x = 1; x < T; ++x) {
      if (!(in_below[x - 1] & in_below[x] & in_above[x - 1] & in_above[x])) continue;
      const int degree = !!(above[x - 1] & wall_east) + !!(below[x - 1] & wall_east) + !!(below[x - 1] & wall_north) +
                         !!(below[x] & wall_north);
      if (degree == 1) tips.emplace_back(x, y);
    }
  }
  return tips;
}

// The block of each texel: blocks of B x B texels, and where one holds a cut tip (on its
// closed outline) it is split in four, again while a quarter holds the tip and is larger
// than tip_B. Returned as one id per texel (the block's size and position).
std::vector<std::int64_t> texel_blocks(int T, const std::vector<std::pair<int, int>>& tips, int B, int tip_B) {
  // Per block size B, B/2, ... above tip_B: which blocks hold a tip.
  struct Level {
    int size, count;  // block size, blocks per row
    std::vector<char> holds_tip;
  };
  std::vector<Level> levels;
  for (int s = B; s > tip_B; s = std::max(s / 2, tip_B)) {
    Level level{s, (T + s - 1) / s, {}};
    level.holds_tip.assign(static_cast<std::size_t>(level.count) * level.count, 0);
    for (const auto& [x, y] : tips)  // x, y >= 1: a corner on a block border is in both
      for (int bj = (y - 1) / s; bj <= std::min(y / s, level.count - 1); ++bj)
        for (int bi = (x - 1) / s; bi <= std::min(x / s, level.count - 1); ++bi) level.holds_tip[bj * level.count + bi] = 1;
    levels.push_back(std::move(level));
  }
  std::vector<std::int64_t> block(static_cast<std::size_t>(T) * T);
  for (int j = 0; j < T; ++j) {
    std::int64_t* row = block.data() + static_cast<std::size_t>(j) * T;
    for (int i0 = 0; i0 < T; i0 += B) {
      const int i1 = std::min(i0 + B, T);
      if (levels.empty() || !levels[0].holds_tip[(j / B) * levels[0].count + i0 / B]) {  // a whole block
        std::fill(row + i0, row + i1, (static_cast<std::int64_t>(B) * T + j / B) * T + i0 / B);
        continue;
      }
      for (int i = i0; i < i1; ++i) {
        int s = B;
        for (const Level& level : levels) {  // sizes in order: s is level.size here
          if (!level.holds_tip[(j / s) * level.count + i / s]) break;
          s = std::max(s / 2, tip_B);
        }
        row[i] = (static_cast<std::int64_t>(s) * T + j / s) * T + i / s;
      }
    }
  }
  return block;
}

// Labels the texels of one element by the wall-connected part of their block (canonical
// labels of label_components, flood_fill.h: numbered in row-major order of their first
// texel; texels outside the domain -1): the element's walls plus walls between blocks.
// `count` receives the number of labels.
std::vector<int> block_components(ElementType type, int T, const std::uint8_t* flags, int B, int tip_B, int& count) {
  const std::vector<std::int64_t> block = texel_blocks(T, cut_tips(type, T, flags), B, tip_B);
  TexelTile tile(T, T);
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) {
      const int t = j * T + i;
      std::uint8_t f = flags[t];
      if (!texel_in_domain(type, T, flags, i, j)) f |= inactive;
      if (i + 1 < T && block[t] != block[t + 1]) f |= wall_east;
      if (j + 1 < T && block[t] != block[t + T]) f |= wall_north;
      tile.flags[t] = f;
    }
  std::vector<int> label;
  count = label_components(tile, label);
  return label;
}

// The same labels without a tile and label_components: one serial union-find over a mask of
// the domain (several elements run side by side instead). Couplings are those of
// label_components on block_components' tile: both texels in the domain, no wall between
// them, the same block. Runs of east-coupled texels point to their first texel, and a
// union hangs the larger root below the smaller, so each part's root is its first texel
// and numbering roots in texel order gives the canonical labels.
std::vector<int> block_components_fast(ElementType type, int T, const std::uint8_t* flags, int B, int tip_B,
                                       int& count) {
  const std::size_t n = static_cast<std::size_t>(T) * T;
  std::vector<std::uint8_t> inside(n);
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) {
      const int t = j * T + i;
      inside[t] = (type != ElementType::tri6 || i + j <= T - 1) && !(flags[t] & inactive);
    }
  const std::vector<std::int64_t> block = texel_blocks(T, cut_tips(T, flags, inside.data()), B, tip_B);
  std::vector<int> parent(n);
  std::vector<char> joins_west(n);  // coupled to the texel before it in its row
  for (int j = 0; j < T; ++j) {
    int run_start = j * T;
    for (int i = 0; i < T; ++i) {
      const int t = j * T + i;
      joins_west[t] = i > 0 && inside[t - 1] && inside[t] && !(flags[t - 1] & wall_east) && block[t - 1] == block[t];
      if (!joins_west[t]) run_start = t;
      parent[t] = run_start;
    }
  }
  for (int j = 0; j + 1 < T; ++j) {
    bool previous_coupled = false;
    for (int i = 0; i < T; ++i) {
      const int t = j * T + i;
      const bool coupled = inside[t] && inside[t + T] && !(flags[t] & wall_north) && block[t] == block[t + T];
      // Where both texels continue the runs of the pair before them, which is coupled, their
      // sets are joined already (a block's rows: one union instead of B).
      if (coupled && !(previous_coupled && joins_west[t] && joins_west[t + T])) unite_smaller_root(parent, t, t + T);
      previous_coupled = coupled;
    }
  }
  std::vector<int> label(n, -1);
  count = 0;
  for (std::size_t t = 0; t < n; ++t) {
    if (!inside[t]) continue;
    const int r = find_root_halving(parent, static_cast<int>(t));
    label[t] = r == static_cast<int>(t) ? count++ : label[r];
  }
  return label;
}

// One element's clusters: its points bucketed by label (stable), empty labels dropped.
struct ElementClusters {
  std::vector<std::int64_t> sizes;   // points per cluster
  std::vector<std::int64_t> points;  // by cluster
  std::string error;                 // a point outside the domain (thrown by the caller)
};

ElementClusters bucket_points(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature, std::int64_t e,
                              const std::vector<int>& label, int labels) {
  const int T = batch.resolution;
  ElementClusters out;
  const std::int64_t first = quadrature.start[e], last = quadrature.start[e + 1];
  std::vector<int> point_label(static_cast<std::size_t>(last - first));
  std::vector<std::int64_t> bucket(static_cast<std::size_t>(labels) + 1, 0);
  for (std::int64_t q = first; q < last; ++q) {
    int i, j;
    containing_texel(batch.type, T, quadrature.points[3 * q], quadrature.points[3 * q + 1], i, j);
    point_label[q - first] = label[j * T + i];
    if (point_label[q - first] < 0) {  // containing_texel keeps points inside the domain
      out.error = "enriched_rotation_clusters: quadrature point " + std::to_string(q) + " lies in texel (" +
                  std::to_string(i) + ", " + std::to_string(j) + "), outside the domain";
      return out;
    }
    ++bucket[point_label[q - first] + 1];
  }
  for (int l = 0; l < labels; ++l) {
    if (bucket[l + 1] > 0) out.sizes.push_back(bucket[l + 1]);
    bucket[l + 1] += bucket[l];
  }
  out.points.resize(static_cast<std::size_t>(last - first));
  for (std::int64_t q = first; q < last; ++q) out.points[bucket[point_label[q - first]]++] = q;
  return out;
}

// The walls (and inactive texels) of all of element e's textures: their flags or'ed
// together, in `merged` unless the element has one texture (its own flags then).
const std::uint8_t* element_flags(const EnrichedElementBatch& batch, std::int64_t e,
                                  std::vector<std::uint8_t>& merged) {
  const int first = batch.enrichment_start[e], last = batch.enrichment_start[e + 1];
  if (last - first == 1) return batch.textures[first].flags;
  merged.assign(batch.textures[first].flags,
                batch.textures[first].flags + static_cast<std::size_t>(batch.resolution) * batch.resolution);
  for (int k = first + 1; k < last; ++k)
    for (std::size_t t = 0; t < merged.size(); ++t) merged[t] |= batch.textures[k].flags[t];
  return merged.data();
}

void check_block_sizes(int block_texels, int tip_block_texels) {
  if (block_texels < 1)
    throw std::invalid_argument("enriched_rotation_clusters: block_texels is " + std::to_string(block_texels) +
                                "; it must be >= 1");
  if (tip_block_texels < 1)
    throw std::invalid_argument("enriched_rotation_clusters: tip_block_texels is " +
                                std::to_string(tip_block_texels) + "; it must be >= 1");
}

EnrichedRotationClusters concatenate(const std::vector<ElementClusters>& elements) {
  EnrichedRotationClusters out;
  out.element_start.push_back(0);
  out.point_start.push_back(0);
  for (const ElementClusters& element : elements) {
    if (!element.error.empty()) throw std::logic_error(element.error);
    for (std::int64_t size : element.sizes) out.point_start.push_back(out.point_start.back() + size);
    out.points.insert(out.points.end(), element.points.begin(), element.points.end());
    out.element_start.push_back(out.count());
  }
  return out;
}

int rest_planes(bool planar) { return planar ? 5 : 9; }
// Doubles of one cluster's rest data: the planes of packed blocks, then D_f.
std::int64_t rest_stride(bool planar, int n) {
  return rest_planes(planar) * enriched_cluster_packed_blocks(n) + 2 * static_cast<std::int64_t>(n);
}

// The rest data's layout, each element's planarity tested once per call: per element
// whether it is planar and its frame (enriched_element_planar_frame), per cluster where its
// rest data starts (#clusters + 1; the last: the size of them all).
struct RestLayout {
  std::vector<char> planar;
  std::vector<double> frames;  // 9 per element
  std::vector<std::int64_t> start;

  RestLayout(const EnrichedElementBatch& batch, const EnrichedRotationClusters& clusters)
      : planar(static_cast<std::size_t>(batch.count)), frames(9 * static_cast<std::size_t>(batch.count)), start(1, 0) {
    for (std::int64_t e = 0; e < batch.count; ++e) {
      planar[e] = enriched_element_planar_frame(batch, e, &frames[9 * e]);
      const std::int64_t stride = rest_stride(planar[e], enriched_basis_count(batch, e));
      for (std::int64_t c = clusters.element_start[e]; c < clusters.element_start[e + 1]; ++c)
        start.push_back(start.back() + stride);
    }
  }
};

// Mean-tangent weights D_f = sum_q w_q dN_f(q) of one cluster (2 per function, W slots).
void tangent_weights(const EnrichedElementBatch& b, const EnrichedQuadrature& quad, std::int64_t e,
                     const std::int64_t* points, std::int64_t count, double* D) {
  const int W = b.width;
  const int npe = nodes_per_element(b.type);
  const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
  std::fill(D, D + 2 * W, 0.0);
  ShapeValues s;
  EnrichedShapeValues shape;
  RestPoint rest;
  for (std::int64_t k = 0; k < count; ++k) {
    const double* pt = quad.points + 3 * points[k];
    evaluate_shape(b.type, pt[0], pt[1], s);
    evaluate_enriched_shape(b, e, pt[0], pt[1], s, shape);
    evaluate_rest_point(s, nodes, b.positions, rest);
    const double w = pt[2] * rest.j0;
    for (int f = 0; f < shape.count; ++f) D[2 * f] += w * shape.dN[f][0], D[2 * f + 1] += w * shape.dN[f][1];
  }
}

// R_c: the polar rotation of the mean F, [a1 a2 t][A1 A2 T0]^-1 from the mean tangents.
void cluster_rotation(const EnrichedElementBatch& b, std::int64_t e, const double* D, const double* current,
                      double R[9]) {
  const int npe = nodes_per_element(b.type);
  const int n = enriched_basis_count(b, e);
  const int* nodes = b.connectivity + static_cast<std::int64_t>(b.element[e]) * npe;
  int global[max_enriched_basis];
  enriched_global_nodes(b, e, global);
  double A1[3] = {0, 0, 0}, A2[3] = {0, 0, 0}, a1[3] = {0, 0, 0}, a2[3] = {0, 0, 0};
  for (int f = 0; f < n; ++f) {
    const double* x = current + 3 * static_cast<std::int64_t>(global[f]);
    for (int k = 0; k < 3; ++k) a1[k] += D[2 * f] * x[k], a2[k] += D[2 * f + 1] * x[k];
    if (f >= npe) continue;
    const double* X = b.positions + 3 * static_cast<std::int64_t>(nodes[f]);
    for (int k = 0; k < 3; ++k) A1[k] += D[2 * f] * X[k], A2[k] += D[2 * f + 1] * X[k];
  }
  double T0[3], t[3], F[9];
  cross3(A1, A2, T0);
  normalize3(T0);
  cross3(a1, a2, t);
  normalize3(t);
  surface_deformation_gradient(A1, A2, T0, a1, a2, t, F);
  polar_rotation(F, R);
}

// acc[ij][p] += sum_kl R_ik B_kl[p] R_jl over a stretch of packed blocks (planes of stride
// `plane`): one cluster's share of `count` blocks. Compiled for AVX-512, AVX2 and baseline
// x86-64 without FMA contraction (cmake/areas/enriched_assembly.cmake): every clone rounds
// alike, so K does not depend on the machine's vector unit.
__attribute__((target_clones("avx512f", "avx2", "default")))
void add_rotated_blocks(int count, const double* B, std::int64_t plane, const double R[9], double* acc,
                        int acc_plane) {
  for (int p = 0; p < count; ++p) {
    double T[9];  // T = B R^T
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        T[k * 3 + j] = B[(k * 3 + 0) * plane + p] * R[j * 3 + 0] + B[(k * 3 + 1) * plane + p] * R[j * 3 + 1] +
                       B[(k * 3 + 2) * plane + p] * R[j * 3 + 2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        acc[(i * 3 + j) * acc_plane + p] += R[i * 3 + 0] * T[0 * 3 + j] + R[i * 3 + 1] * T[1 * 3 + j] +
                                            R[i * 3 + 2] * T[2 * 3 + j];
  }
}

// The same for planar rest data: acc[ij][p] += sum_k P_k[p] O[k][ij] over the five planes
// P_k (E1 B E1, E1 B E2, E2 B E1, E2 B E2, T B T) and the rotated frame products O[k]
// ((R E1)(R E1)^T, (R E1)(R E2)^T, (R E2)(R E1)^T, (R E2)(R E2)^T, (R T)(R T)^T); then the
// same for a second cluster (B2, O2) where given, its sum added after the first's as a
// second call would (the same bits). The planes are read once per stretch of
// planar_stretch blocks and kept in registers for the nine products, acc once per pair of
// clusters. As nine passes over the planes, one product each, this function was ~70 % of
// the accordion's step; paired, bench_enriched_assembly BM_EnrichedStiffnessClustered/6/1
// (338 clusters, one thread) takes 2.6 ms instead of 3.1-3.5.
constexpr int planar_stretch = 16;
__attribute__((target_clones("avx512f", "avx2", "default")))
void add_rotated_planar_blocks(int count, const double* B, const double O[5][9], const double* B2,
                               const double O2[5][9], std::int64_t plane, double* acc, int acc_plane) {
  const auto planes_at = [plane](const double* P, int p, const double o[5]) {
    return P[p] * o[0] + P[plane + p] * o[1] + P[2 * plane + p] * o[2] + P[3 * plane + p] * o[3] +
           P[4 * plane + p] * o[4];
  };
  int p0 = 0;
  for (; p0 + planar_stretch <= count; p0 += planar_stretch) {
    double b[5][planar_stretch], b2[5][planar_stretch];
    for (int k = 0; k < 5; ++k)
      for (int q = 0; q < planar_stretch; ++q) b[k][q] = B[k * plane + p0 + q];
    if (B2)
      for (int k = 0; k < 5; ++k)
        for (int q = 0; q < planar_stretch; ++q) b2[k][q] = B2[k * plane + p0 + q];
    for (int ij = 0; ij < 9; ++ij) {
      const double o0 = O[0][ij], o1 = O[1][ij], o2 = O[2][ij], o3 = O[3][ij], o4 = O[4][ij];
      double* a = acc + ij * acc_plane + p0;
      if (!B2) {
        for (int q = 0; q < planar_stretch; ++q)
          a[q] += b[0][q] * o0 + b[1][q] * o1 + b[2][q] * o2 + b[3][q] * o3 + b[4][q] * o4;
        continue;
      }
      const double r0 = O2[0][ij], r1 = O2[1][ij], r2 = O2[2][ij], r3 = O2[3][ij], r4 = O2[4][ij];
      for (int q = 0; q < planar_stretch; ++q) {
        const double first = a[q] + (b[0][q] * o0 + b[1][q] * o1 + b[2][q] * o2 + b[3][q] * o3 + b[4][q] * o4);
        a[q] = first + (b2[0][q] * r0 + b2[1][q] * r1 + b2[2][q] * r2 + b2[3][q] * r3 + b2[4][q] * r4);
      }
    }
  }
  for (int ij = 0; ij < 9; ++ij) {  // the last blocks, fewer than a stretch
    double o[5], o2[5];
    for (int k = 0; k < 5; ++k) o[k] = O[k][ij], o2[k] = B2 ? O2[k][ij] : 0.0;
    double* a = acc + ij * acc_plane;
    for (int p = p0; p < count; ++p) {
      a[p] += planes_at(B, p, o);
      if (B2) a[p] += planes_at(B2, p, o2);
    }
  }
}

}  // namespace

std::int64_t enriched_cluster_packed_blocks(int functions) {
  const std::int64_t blocks = static_cast<std::int64_t>(functions) * (functions + 1) / 2;
  return (blocks + 7) / 8 * 8;
}

int enriched_cluster_rest_planes(const EnrichedElementBatch& batch, std::int64_t e) {
  double frame[9];
  return rest_planes(enriched_element_planar_frame(batch, e, frame));
}

std::int64_t enriched_cluster_rest_stride(const EnrichedElementBatch& batch, std::int64_t e) {
  return rest_stride(enriched_cluster_rest_planes(batch, e) == 5, enriched_basis_count(batch, e));
}

std::int64_t enriched_cluster_rest_size(const EnrichedElementBatch& batch, const EnrichedRotationClusters& clusters) {
  return RestLayout(batch, clusters).start.back();
}

EnrichedRotationClusters enriched_rotation_clusters(const EnrichedElementBatch& batch,
                                                    const EnrichedQuadrature& quadrature, int block_texels,
                                                    int tip_block_texels, Execution execution) {
  check_block_sizes(block_texels, tip_block_texels);
  // Elements side by side, each labelled serially (chad's 4 tiles of 256^2 texels: 9.5 -> 3.9
  // ms a basis change against the reference form; spiral6's one: 2.3 -> 1.3 ms).
  std::vector<ElementClusters> elements(static_cast<std::size_t>(batch.count));
  forall(
      batch.count,
      [&](std::int64_t e) {
        int labels = 0;
        std::vector<std::uint8_t> merged;
        const std::vector<int> label = block_components_fast(batch.type, batch.resolution,
                                                             element_flags(batch, e, merged), block_texels,
                                                             tip_block_texels, labels);
        elements[e] = bucket_points(batch, quadrature, e, label, labels);
      },
      execution);
  return concatenate(elements);
}

EnrichedRotationClusters enriched_rotation_clusters_reference(const EnrichedElementBatch& batch,
                                                              const EnrichedQuadrature& quadrature, int block_texels,
                                                              int tip_block_texels) {
  check_block_sizes(block_texels, tip_block_texels);
  std::vector<ElementClusters> elements;
  for (std::int64_t e = 0; e < batch.count; ++e) {
    int labels = 0;
    std::vector<std::uint8_t> merged;
    const std::vector<int> label = block_components(batch.type, batch.resolution, element_flags(batch, e, merged),
                                                    block_texels, tip_block_texels, labels);
    elements.push_back(bucket_points(batch, quadrature, e, label, labels));
  }
  return concatenate(elements);
}

void enriched_cluster_rest_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                     const EnrichedRotationClusters& clusters, double* rest, Execution execution) {
  enriched_cluster_rest_stiffness(batch, quadrature, clusters, rest, nullptr, execution);
}

std::vector<std::int64_t> enriched_cluster_rest_element_start(const EnrichedElementBatch& batch,
                                                              const EnrichedRotationClusters& clusters) {
  const RestLayout layout(batch, clusters);
  std::vector<std::int64_t> start(static_cast<std::size_t>(batch.count) + 1);
  for (std::int64_t e = 0; e <= batch.count; ++e) start[e] = layout.start[clusters.element_start[e]];
  return start;
}

void enriched_cluster_rest_reshift(int planes, std::int64_t clusters, int old_functions, const double* old_rest,
                                   int functions, const int* from, const int* standard, const double* delta,
                                   double* rest, Execution execution) {
  if (planes != 5 && planes != 9) throw std::invalid_argument("enriched_cluster_rest_reshift: planes must be 5 or 9");
  const int n = functions, n_old = old_functions;
  const std::int64_t plane = enriched_cluster_packed_blocks(n), old_plane = enriched_cluster_packed_blocks(n_old);
  const std::int64_t stride = rest_stride(planes == 5, n), old_stride = rest_stride(planes == 5, n_old);
  // Plane k of block (b, a) is plane transposed[k] of block (a, b): 3 x 3 entries (i, j) ->
  // (j, i); planar g_12 <-> g_21.
  int transposed[9];
  for (int k = 0; k < planes; ++k) transposed[k] = planes == 9 ? k % 3 * 3 + k / 3 : (k == 1 ? 2 : k == 2 ? 1 : k);
  forall(
      clusters,
      [&](std::int64_t c) {
        const double* in = old_rest + c * old_stride;
        double* out = rest + c * stride;
        // Plane k of old block (a, b), any order.
        const auto old_block = [&](int k, int a, int b) {
          return a <= b ? in[k * old_plane + packed_row_start(n_old, a) + (b - a)]
                        : in[transposed[k] * old_plane + packed_row_start(n_old, b) + (a - b)];
        };
        for (int f = 0; f < n; ++f)
          for (int g = f; g < n; ++g) {
            const int F = from[f], G = from[g];
            const std::int64_t p = packed_row_start(n, f) + (g - f);
            for (int k = 0; k < planes; ++k) {
              double v = old_block(k, F, G);
              if (delta[g] != 0) v -= delta[g] * old_block(k, F, standard[g]);
              if (delta[f] != 0) v -= delta[f] * old_block(k, standard[f], G);
              if (delta[f] != 0 && delta[g] != 0) v += delta[f] * delta[g] * old_block(k, standard[f], standard[g]);
              out[k * plane + p] = v;
            }
          }
        for (std::int64_t p = packed_row_start(n, n); p < plane; ++p)  // padding
          for (int k = 0; k < planes; ++k) out[k * plane + p] = 0;
        const double* old_D = in + planes * old_plane;
        double* D = out + planes * plane;
        for (int f = 0; f < n; ++f)
          for (int d = 0; d < 2; ++d) D[2 * f + d] = old_D[2 * from[f] + d] - delta[f] * old_D[2 * standard[f] + d];
      },
      execution);
}

void enriched_cluster_rest_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                     const EnrichedRotationClusters& clusters, double* rest, const char* compute,
                                     Execution execution) {
  const RestLayout layout(batch, clusters);
  const std::vector<char>& planar = layout.planar;
  // Clusters differ much in cost (tip blocks hold few points): handed out dynamically, the
  // costliest (points x functions^2) first, so that no large one is left for the end while
  // the other threads wait (the slinky's sums ended with a core idle). Each writes only its
  // own rest data, so the result does not depend on the threads or the order.
  struct Todo {
    std::int64_t cluster, element, cost;
  };
  std::vector<Todo> todo;
  for (std::int64_t e = 0; e < batch.count; ++e) {
    if (compute && !compute[e]) continue;
    const std::int64_t n = enriched_basis_count(batch, e);
    for (std::int64_t c = clusters.element_start[e]; c < clusters.element_start[e + 1]; ++c)
      todo.push_back({c, e, (clusters.point_start[c + 1] - clusters.point_start[c]) * n * n});
  }
  std::stable_sort(todo.begin(), todo.end(), [](const Todo& a, const Todo& b) { return a.cost > b.cost; });
  auto cluster = [&](std::int64_t i) {
    const std::int64_t c = todo[i].cluster, e = todo[i].element;
    const int n = enriched_basis_count(batch, e);
    const int planes = rest_planes(planar[e]);
    const std::int64_t plane = enriched_cluster_packed_blocks(n);
    const std::int64_t* points = clusters.points.data() + clusters.point_start[c];
    const std::int64_t count = clusters.point_start[c + 1] - clusters.point_start[c];
    static thread_local std::vector<double> K;
    double* out = rest + layout.start[c];
    enriched_element_point_set_stiffness(batch, quadrature, e, points, count, K, out + planes * plane);
    std::fill(out, out + planes * plane, 0.0);
    const std::size_t N3 = 3 * static_cast<std::size_t>(n);
    for (std::size_t a = 0; a < static_cast<std::size_t>(n); ++a)
      for (std::size_t b = a; b < static_cast<std::size_t>(n); ++b) {
        const std::int64_t p = packed_row_start(n, static_cast<int>(a)) + static_cast<std::int64_t>(b - a);
        if (planar[e]) {  // K = [Km | Kb] (enriched_element_point_set_stiffness)
          std::size_t at[5];
          enriched_planar_sum_offsets(n, a, b, at);
          for (int k = 0; k < 5; ++k) out[k * plane + p] = K[at[k]];
          continue;
        }
        for (std::size_t i = 0; i < 3; ++i)
          for (std::size_t j = 0; j < 3; ++j) out[(i * 3 + j) * plane + p] = K[(3 * a + i) * N3 + 3 * b + j];
      }
  };
  forall_dynamic(static_cast<std::int64_t>(todo.size()), cluster, execution);
}

void enriched_cluster_rotations(const EnrichedElementBatch& batch, const EnrichedRotationClusters& clusters,
                                const double* rest, const double* current, double* rotations, Execution execution) {
  const RestLayout layout(batch, clusters);
  forall(
      batch.count,
      [&](std::int64_t e) {
        const std::int64_t weights =
            rest_planes(layout.planar[e]) * enriched_cluster_packed_blocks(enriched_basis_count(batch, e));
        for (std::int64_t c = clusters.element_start[e]; c < clusters.element_start[e + 1]; ++c)
          cluster_rotation(batch, e, rest + layout.start[c] + weights, current, rotations + 9 * c);
      },
      execution);
}

void enriched_element_clustered_stiffness(const EnrichedElementBatch& batch, const EnrichedRotationClusters& clusters,
                                          const double* rest, const double* rotations, double* blocks,
                                          double* forces, Execution execution) {
  const int W = batch.width;
  const int npe = nodes_per_element(batch.type);
  const RestLayout layout(batch, clusters);
  const std::vector<char>& planar = layout.planar;
  const std::vector<double>& frames = layout.frames;
  const std::vector<std::int64_t>& rest_start = layout.start;
  const std::int64_t widest = static_cast<std::int64_t>(W) * (W + 1) / 2;
  // Tiles small enough for two per thread where the elements are fewer than that (spiral6's
  // one element, 1.6k blocks, ran on one thread of two). Every block sums the clusters in
  // order whatever its tile, so the tiling does not change the bits.
  const std::int64_t wanted_items = execution == Execution::parallel ? 2 * parallel_team_size() : 1;
  const std::int64_t tile_blocks =
      std::clamp<std::int64_t>((widest * batch.count + wanted_items - 1) / wanted_items, 16, cluster_tile_blocks);
  const std::int64_t tiles = (widest + tile_blocks - 1) / tile_blocks;
  // Blocks: one work item per tile of an element's packed upper blocks; every cluster adds
  // its rotated stretch of the tile, in cluster order, to a sum that stays in cache, which
  // is then written as blocks (a, c) and their mirrors (c, a). The blocks of the slots
  // beyond the element's n functions are 0.
  forall(
      batch.count * tiles,
      [&](std::int64_t item) {
        const std::int64_t e = item / tiles;
        const int n = enriched_basis_count(batch, e);
        const std::int64_t packed = static_cast<std::int64_t>(n) * (n + 1) / 2;
        const std::int64_t plane = enriched_cluster_packed_blocks(n);
        const std::int64_t p0 = item % tiles * tile_blocks;
        if (p0 == 0)
          for (int a = 0; a < W; ++a)
            for (int c = a < n ? n : 0; c < W; ++c) {
              std::fill_n(blocks + ((e * W + a) * W + c) * 9, 9, 0.0);
              std::fill_n(blocks + ((e * W + c) * W + a) * 9, 9, 0.0);
            }
        if (p0 >= packed) return;
        const int length = static_cast<int>(std::min(packed - p0, tile_blocks));
        static thread_local std::vector<double> acc;
        acc.assign(static_cast<std::size_t>(9) * length, 0.0);
        const std::int64_t first = clusters.element_start[e], end = clusters.element_start[e + 1];
        if (planar[e]) {
          for (std::int64_t c = first; c < end; c += 2) {  // two clusters a call
            const bool pair = c + 1 < end;
            double O[2][5][9];
            enriched_planar_frame_products(&frames[9 * e], rotations + 9 * c, &O[0][0][0]);
            if (pair) enriched_planar_frame_products(&frames[9 * e], rotations + 9 * (c + 1), &O[1][0][0]);
            add_rotated_planar_blocks(length, rest + rest_start[c] + p0, O[0],
                                      pair ? rest + rest_start[c + 1] + p0 : nullptr, O[1], plane, acc.data(), length);
          }
        } else {
          for (std::int64_t c = first; c < end; ++c)
            add_rotated_blocks(length, rest + rest_start[c] + p0, plane, rotations + 9 * c, acc.data(), length);
        }
        int a = 0;
        while (packed_row_start(n, a + 1) <= p0) ++a;
        for (std::int64_t p = p0; p < p0 + length; ++p) {
          if (p == packed_row_start(n, a + 1)) ++a;
          const std::int64_t c = a + (p - packed_row_start(n, a));
          double* upper = blocks + ((e * W + a) * W + c) * 9;
          double* lower = blocks + ((e * W + c) * W + a) * 9;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) upper[i * 3 + j] = lower[j * 3 + i] = acc[(i * 3 + j) * length + (p - p0)];
        }
      },
      execution);
  if (!forces) return;
  // Forces: f_a = sum_c R_c sum_b K0_c(a, b) z_b, z = X0 - R_c^T X0 on the standard functions.
  // z per cluster first (planar: its frame components E_y . z, the rest sums' own basis).
  std::vector<double> z(static_cast<std::size_t>(clusters.count()) * npe * 3);
  forall(
      batch.count,
      [&](std::int64_t e) {
        const int* nodes = batch.connectivity + static_cast<std::int64_t>(batch.element[e]) * npe;
        const double* E = &frames[9 * e];
        for (std::int64_t c = clusters.element_start[e]; c < clusters.element_start[e + 1]; ++c) {
          const double* R = rotations + 9 * c;
          for (int b = 0; b < npe; ++b) {
            const double* X = batch.positions + 3 * static_cast<std::int64_t>(nodes[b]);
            double d[3];
            for (int k = 0; k < 3; ++k) d[k] = X[k] - (R[0 * 3 + k] * X[0] + R[1 * 3 + k] * X[1] + R[2 * 3 + k] * X[2]);
            double* out = &z[(c * npe + b) * 3];
            for (int y = 0; y < 3; ++y)
              out[y] = planar[e] ? E[3 * y] * d[0] + E[3 * y + 1] * d[1] + E[3 * y + 2] * d[2] : d[y];
          }
        }
      },
      execution);
  // Planes k = (x, y) of the frame pairs; a stored block (b, a) read as (a, b) swaps them.
  const auto& pair = enriched_planar_pairs;
  const int transposed[5] = {0, 2, 1, 3, 4};
  // Work items: tiles of functions a of one element. Cluster by cluster and b by b, the
  // tile reads blocks (a, b < npe), which for a >= b lie contiguously in row b of every
  // plane (one function at a time strode across the planes of all clusters: ~16 % of the
  // accordion's step). Each f_a still sums b in order, then clusters in order.
  const std::int64_t force_tiles = (W + cluster_force_tile - 1) / cluster_force_tile;
  forall(
      batch.count * force_tiles,
      [&](std::int64_t item) {
        const std::int64_t e = item / force_tiles;
        const int a0 = static_cast<int>(item % force_tiles) * cluster_force_tile;
        const int a1 = std::min(W, a0 + cluster_force_tile);
        const int n = enriched_basis_count(batch, e);
        const int used = std::max(a0, std::min(a1, n));
        const std::int64_t plane = enriched_cluster_packed_blocks(n);
        const bool is_planar = planar[e];
        double f[cluster_force_tile][3] = {};
        const double* E = &frames[9 * e];
        for (std::int64_t c = clusters.element_start[e]; c < clusters.element_start[e + 1]; ++c) {
          const double* B = rest + rest_start[c];
          const double* R = rotations + 9 * c;
          // planar: h[k][a] = sum_b g_k(a, b) (E_y . z_b); else h[i][a] = sum_b K0_c(a, b) z_b.
          double h[5][cluster_force_tile] = {};
          for (int b = 0; b < npe; ++b) {
            const double* zb = &z[(c * npe + b) * 3];
            // a <= b: block (a, b) is stored, in row a.
            for (int a = a0; a < std::min(used, b + 1); ++a) {
              const std::int64_t p = packed_row_start(n, a) + (b - a);
              for (int k = 0; k < 5 && is_planar; ++k) h[k][a - a0] += B[k * plane + p] * zb[pair[k][1]];
              for (int i = 0; i < 3 && !is_planar; ++i)
                for (int j = 0; j < 3; ++j) h[i][a - a0] += B[(i * 3 + j) * plane + p] * zb[j];
            }
            // a > b: the stored block (b, a), contiguous in row b, transposed.
            const int first = std::max(a0, b + 1);
            const double* row = B + packed_row_start(n, b) - b;  // row[a]: block (b, a)
            if (is_planar) {
              for (int k = 0; k < 5; ++k) {
                const double* plane_k = row + transposed[k] * plane;
                const double y = zb[pair[k][1]];
                for (int a = first; a < used; ++a) h[k][a - a0] += plane_k[a] * y;
              }
            } else {
              for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                  const double* plane_ji = row + (j * 3 + i) * plane;
                  for (int a = first; a < used; ++a) h[i][a - a0] += plane_ji[a] * zb[j];
                }
            }
          }
          for (int a = a0; a < used; ++a) {
            double g[3] = {0, 0, 0};  // sum_b K0_c(a, b) z_b
            if (is_planar) {
              for (int k = 0; k < 5; ++k)
                for (int i = 0; i < 3; ++i) g[i] += E[3 * pair[k][0] + i] * h[k][a - a0];
            } else {
              for (int i = 0; i < 3; ++i) g[i] = h[i][a - a0];
            }
            double* fa = f[a - a0];
            for (int i = 0; i < 3; ++i) fa[i] += R[i * 3 + 0] * g[0] + R[i * 3 + 1] * g[1] + R[i * 3 + 2] * g[2];
          }
        }
        for (int a = a0; a < a1; ++a)
          for (int i = 0; i < 3; ++i) forces[(e * W + a) * 3 + i] = f[a - a0][i];
      },
      execution);
}

void enriched_element_clustered_stiffness_reference(const EnrichedElementBatch& batch,
                                                    const EnrichedQuadrature& quadrature,
                                                    const EnrichedRotationClusters& clusters, const double* current,
                                                    double* blocks, double* forces, double* rotations) {
  const int W = batch.width;
  const std::size_t element_blocks = static_cast<std::size_t>(W) * W * 9;
  std::fill(blocks, blocks + batch.count * element_blocks, 0.0);
  if (forces) std::fill(forces, forces + batch.count * W * 3, 0.0);
  std::vector<double> D(2 * static_cast<std::size_t>(W)), K(batch.count * element_blocks), f(batch.count * W * 3);
  for (std::int64_t e = 0; e < batch.count; ++e)
    for (std::int64_t c = clusters.element_start[e]; c < clusters.element_start[e + 1]; ++c) {
      const std::int64_t* points = clusters.points.data() + clusters.point_start[c];
      const std::int64_t count = clusters.point_start[c + 1] - clusters.point_start[c];
      tangent_weights(batch, quadrature, e, points, count, D.data());
      double R[9];
      cluster_rotation(batch, e, D.data(), current, R);
      if (rotations) std::copy(R, R + 9, rotations + 9 * c);
      // The cluster's points alone, on element e, each turned by R.
      std::vector<std::int64_t> start(static_cast<std::size_t>(batch.count) + 1, 0);
      for (std::int64_t x = e + 1; x <= batch.count; ++x) start[x] = count;
      std::vector<double> sub(3 * static_cast<std::size_t>(count)), Rs(9 * static_cast<std::size_t>(count));
      for (std::int64_t k = 0; k < count; ++k) {
        std::copy(quadrature.points + 3 * points[k], quadrature.points + 3 * points[k] + 3, sub.begin() + 3 * k);
        std::copy(R, R + 9, Rs.begin() + 9 * k);
      }
      enriched_element_stiffness_reference(batch, {start.data(), sub.data()}, Rs.data(), K.data(), f.data());
      for (std::size_t i = 0; i < element_blocks; ++i) blocks[e * element_blocks + i] += K[e * element_blocks + i];
      if (forces)
        for (int i = 0; i < 3 * W; ++i) forces[e * W * 3 + i] += f[e * W * 3 + i];
    }
}

}  // namespace dgtex::kernels

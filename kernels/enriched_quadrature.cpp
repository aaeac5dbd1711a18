#include "dgtex/kernels/enriched_quadrature.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "dgtex/kernels/texel_derivative_rows.h"
#include "dgtex/kernels/texel_grid.h"
#include "texel_cell_rules.h"

// The fast form of the rule (the reference twin, enriched_quadrature_reference.cpp, is the
// rule written plainly; both give bitwise the same arrays). Where the time went and what
// replaces it:
//  - texel derivatives of every texel: texel_derivative_rows (reachability bits, no
//    per-neighbour look-ups), in row blocks across threads even for one element;
//  - the merge test re-scanned every texel of a candidate cell for domain and walls at every
//    level: per-row prefix sums of "outside", east and north walls answer that in O(rows)
//    before any texel polynomial is compared (the test is a conjunction: order is free), and
//    the polynomials are then compared row by row in a vectorizable loop;
//  - one element ran on one thread: the quadtree is expanded serially down to a few levels,
//    the cells there become independent subtrees (tasks) and their point lists are spliced
//    back in the serial order.

namespace dgtex::kernels {
namespace {

// Whether texel t's polynomial agrees with the reference polynomial (rule of the header).
inline bool agrees(const TexelDerivatives& ref, const TexelDerivatives& t, double d1, double d2, double size,
                   double tol) {
  const double p = ref.value + ref.g[0] * d1 + ref.g[1] * d2 + 0.5 * (ref.s[0] * d1 * d1 + ref.s[1] * d2 * d2) +
                   ref.s[2] * d1 * d2;
  if (!(std::abs(t.value - p) <= tol)) return false;
  const double g1 = ref.g[0] + ref.s[0] * d1 + ref.s[2] * d2;
  const double g2 = ref.g[1] + ref.s[2] * d1 + ref.s[1] * d2;
  if (!(size * std::max(std::abs(t.g[0] - g1), std::abs(t.g[1] - g2)) <= tol)) return false;
  const double ds = std::max({std::abs(t.s[0] - ref.s[0]), std::abs(t.s[1] - ref.s[1]), std::abs(t.s[2] - ref.s[2])});
  return size * size * ds <= tol;
}

// agrees() for texels i0 .. i0 + length - 1 of one row (d2 = j - rj): the same expressions
// in a branch-free loop that vectorizes, its verdict taken once a chunk of texels (the
// conjunction is the same boolean). Cloned per instruction set; the file is compiled
// without contraction (cmake/areas/enriched_assembly.cmake), so every clone gives the same
// booleans. One pass (instead of the deviations stored, then compared) and the wide clones
// made the quadrature of spiral6's six textures ~15 % faster, the slinky's ~12 %.
constexpr int deviation_chunk = 64;
inline double larger(double a, double b) { return a < b ? b : a; }  // std::max, by value
__attribute__((target_clones("avx512f", "avx2", "default")))
bool row_agrees(const TexelDerivatives& ref, const TexelDerivativePlanes& row, int i0, int length, int ri, double d2,
                double size, double tol) {
  const double rv = ref.value, rg0 = ref.g[0], rg1 = ref.g[1], rs0 = ref.s[0], rs1 = ref.s[1], rs2 = ref.s[2];
  const double *v = row.value, *ga = row.g[0], *gb = row.g[1], *sa = row.s[0], *sb = row.s[1], *sc = row.s[2];
  for (int c0 = i0; c0 < i0 + length; c0 += deviation_chunk) {
    const int end = std::min(c0 + deviation_chunk, i0 + length);
    int deviates = 0;
    for (int i = c0; i < end; ++i) {
      const double d1 = i - ri;
      const double p = rv + rg0 * d1 + rg1 * d2 + 0.5 * (rs0 * d1 * d1 + rs1 * d2 * d2) + rs2 * d1 * d2;
      const double g1 = rg0 + rs0 * d1 + rs2 * d2;
      const double g2 = rg1 + rs2 * d1 + rs1 * d2;
      const double dv = std::abs(v[i] - p);
      const double dg = larger(std::abs(ga[i] - g1), std::abs(gb[i] - g2));
      const double dh = larger(larger(std::abs(sa[i] - rs0), std::abs(sb[i] - rs1)), std::abs(sc[i] - rs2));
      deviates |= !(dv <= tol) | !(size * dg <= tol) | !(size * size * dh <= tol);
    }
    if (deviates) return false;
  }
  return true;
}

constexpr int row_block = 16;  // texel rows per work item of the per-texel set-up
constexpr int task_depth = 3;  // quadtree levels expanded serially before subtrees become tasks

// Everything the merge test reads, per element, built once (in row blocks, each allocated
// and filled by its own work item: no serial zero-filling of megabytes).
struct ElementInputs {
  ElementType type;
  int t = 0;
  const TextureView* textures = nullptr;
  int texture_count = 0;
  // Planar texel derivatives (texel_derivative_rows.h) of texture k in row blocks of
  // row_block rows (texel_derivative_tile.h), which the caller may keep.
  std::vector<std::shared_ptr<TexelDerivativeTile>> field_tiles;
  // Row prefix sums (row j at j * (T + 1), texel i at + i) of texels outside the domain of
  // some texture, east walls and north walls (any texture) among texels (0..i-1, j);
  // interleaved, as the merge test reads all three at the same places.
  struct RowCounts {
    int outside, east, north;
  };
  std::unique_ptr<RowCounts[]> row_prefix;
  // Walls on the line between rows j and j + 1 over columns [i0, i0 + w).
  int north_walls(int j, int i0, int w) const {
    const RowCounts* p = row_prefix.get() + static_cast<std::size_t>(j) * (t + 1);
    return p[i0 + w].north - p[i0].north;
  }
  // Column prefix sums (column i at i * (T + 1)): east walls of texels (i, 0..j-1).
  std::unique_ptr<int[]> east_column_prefix;

  void allocate(bool adaptive) {
    if (!adaptive) return;
    const std::size_t prefix = static_cast<std::size_t>(t) * (t + 1);
    row_prefix.reset(new RowCounts[prefix]);
    east_column_prefix.reset(new int[prefix]);
    for (int k = 0; k < texture_count; ++k) field_tiles.push_back(std::make_shared<TexelDerivativeTile>(t, row_block));
  }
  // The planes of row j of texture k.
  TexelDerivativePlanes field_row(int k, int j) const { return field_tiles[k]->row(j); }

  void build_block(int block) {
    const int row_begin = block * row_block, row_end = std::min(row_begin + row_block, t);
    for (int k = 0; k < texture_count; ++k) {
      std::unique_ptr<double[]>& planes = field_tiles[k]->blocks[block];
      planes.reset(new double[6 * static_cast<std::size_t>(row_block) * t]);  // filled just below
      texel_derivative_rows(type, t, textures[k], row_begin, row_end, field_row(k, row_begin));
    }
    const bool tri = type == ElementType::tri6;
    for (int j = row_begin; j < row_end; ++j) {
      RowCounts* counts = row_prefix.get() + static_cast<std::size_t>(j) * (t + 1);
      counts[0] = {0, 0, 0};
      for (int i = 0; i < t; ++i) {
        std::uint8_t f = 0;
        for (int k = 0; k < texture_count; ++k) f |= textures[k].flags[j * t + i];
        const bool out = (f & inactive) || (tri && i + j > t - 1);
        counts[i + 1] = {counts[i].outside + (out ? 1 : 0), counts[i].east + ((f & stencil_barrier_east) ? 1 : 0),
                         counts[i].north + ((f & stencil_barrier_north) ? 1 : 0)};
      }
    }
  }
  void build_column(int i) {
    int* east = east_column_prefix.get() + static_cast<std::size_t>(i) * (t + 1);
    east[0] = 0;
    for (int j = 0; j < t; ++j) {
      std::uint8_t f = 0;
      for (int k = 0; k < texture_count; ++k) f |= textures[k].flags[j * t + i];
      east[j + 1] = east[j] + ((f & stencil_barrier_east) ? 1 : 0);
    }
  }
  static int count(const std::unique_ptr<int[]>& prefix, int t, int line, int begin, int length) {
    const int* p = prefix.get() + static_cast<std::size_t>(line) * (t + 1);
    return p[begin + length] - p[begin];
  }
};

// A subtree of the quadtree whose points are produced independently (see splice).
struct Task {
  std::int64_t element;
  int i0, j0, w, h;
  std::size_t position;  // where its points go in the element's planned list (doubles)
  std::vector<double> points;
};

struct CellBuilder {
  const ElementInputs& in;
  const EnrichedQuadratureOptions& options;
  std::vector<double>& out;
  // Planning: cells at task_depth become tasks instead of being visited (nullptr: visit all).
  std::vector<Task>* tasks = nullptr;
  std::int64_t element = 0;
  TexelCellRules rules{in.type, in.t};

  // The wall line of the header's split rule (same scan and tie order as the reference).
  bool wall_line(int i0, int j0, int w, int h, bool& horizontal, int& offset) const {
    long best = -1;
    auto dominant = [](int walls, int length) { return 4 * walls >= 3 * length; };
    for (int m = 1; m < h; ++m)
      if (dominant(in.north_walls(j0 + m - 1, i0, w), w)) {
        const long d = static_cast<long>(std::abs(2 * m - h)) * w;
        if (best < 0 || d < best) best = d, horizontal = true, offset = m;
      }
    for (int m = 1; m < w; ++m)
      if (dominant(ElementInputs::count(in.east_column_prefix, in.t, i0 + m - 1, j0, h), h)) {
        const long d = static_cast<long>(std::abs(2 * m - w)) * h;
        if (best < 0 || d < best) best = d, horizontal = false, offset = m;
      }
    return best >= 0;
  }

  // The merge test: no texel outside the domain, no wall between two texels of the cell
  // (both by prefix sums, row by row), then every texel's polynomial against the reference.
  bool uniform(int i0, int j0, int w, int h, bool triangle) const {
    const int t = in.t;
    for (int r = 0; r < h; ++r) {
      const int j = j0 + r, length = triangle ? w - r : w;  // texels i0 .. i0 + length - 1
      const ElementInputs::RowCounts* counts = in.row_prefix.get() + static_cast<std::size_t>(j) * (t + 1);
      const ElementInputs::RowCounts &first = counts[i0], &last = counts[i0 + length];
      if (last.outside != first.outside) return false;
      if (counts[i0 + length - 1].east != first.east) return false;
      // North walls count where the texel above is in the cell too.
      const int north_length = triangle ? length - 1 : (r + 1 < h ? length : 0);
      if (north_length > 0 && counts[i0 + north_length].north != first.north) return false;
    }
    int ri = i0 + w / 2, rj = j0 + h / 2;
    if (triangle) ri = i0 + w / 4, rj = j0 + h / 4;
    const double size = std::max(w, h);
    const double tol = options.merge_tolerance;
    // The polynomials drift apart with the distance from the reference row, so the rows go
    // outermost first (r = 0, h - 1, 1, h - 2, ...), every texture at each: a cell that is
    // split usually fails at its first row instead of after all rows of the earlier textures.
    TexelDerivatives refs[max_enrichments_per_element];
    for (int k = 0; k < in.texture_count; ++k) {
      const TexelDerivativePlanes at_ref = in.field_row(k, rj);
      refs[k].value = at_ref.value[ri];
      for (int c = 0; c < 2; ++c) refs[k].g[c] = at_ref.g[c][ri];
      for (int c = 0; c < 3; ++c) refs[k].s[c] = at_ref.s[c][ri];
    }
    for (int m = 0; m < h; ++m) {
      const int r = m % 2 == 0 ? m / 2 : h - 1 - m / 2;
      const int j = j0 + r, length = triangle ? w - r : w;
      for (int k = 0; k < in.texture_count; ++k)
        if (!row_agrees(refs[k], in.field_row(k, j), i0, length, ri, j - rj, size, tol)) return false;
    }
    return true;
  }

  void visit(int i0, int j0, int w, int h, int depth) {
    const int t = in.t;
    const bool tri = in.type == ElementType::tri6;
    if (tri && i0 + j0 >= t) return;  // outside the triangle
    if (tasks && depth == task_depth) {
      tasks->push_back({element, i0, j0, w, h, out.size(), {}});
      return;
    }
    const bool inside = !tri || i0 + w + j0 + h <= t;
    const bool diagonal = tri && w == h && i0 + j0 + w == t;
    if (inside || diagonal) {
      if (w == 1 && h == 1) {
        if (diagonal) rules.triangle(out, i0, j0, 1);
        else rules.rectangle(out, i0, j0, 1, 1, 2, 2);
        return;
      }
      if (options.adaptive && uniform(i0, j0, w, h, diagonal)) {
        if (diagonal) rules.triangle(out, i0, j0, w);
        else rules.rectangle(out, i0, j0, w, h, w <= 2 ? 2 : 3, h <= 2 ? 2 : 3);
        return;
      }
    }
    int w1 = (w + 1) / 2, h1 = (h + 1) / 2;
    if (options.adaptive && inside) {
      bool horizontal = false;
      int offset = 0;
      if (wall_line(i0, j0, w, h, horizontal, offset)) {
        if (horizontal) {
          visit(i0, j0, w, offset, depth + 1);
          visit(i0, j0 + offset, w, h - offset, depth + 1);
        } else {
          visit(i0, j0, offset, h, depth + 1);
          visit(i0 + offset, j0, w - offset, h, depth + 1);
        }
        return;
      }
      if (w >= 2 * h) h1 = h;
      else if (h >= 2 * w) w1 = w;
    }
    visit(i0, j0, w1, h1, depth + 1);
    if (w > w1) visit(i0 + w1, j0, w - w1, h1, depth + 1);
    if (h > h1) visit(i0, j0 + h1, w1, h - h1, depth + 1);
    if (w > w1 && h > h1) visit(i0 + w1, j0 + h1, w - w1, h - h1, depth + 1);
  }
};

// The element's points above task_depth (the whole list when nothing is left to a task).
void plan_element(const ElementInputs& in, std::int64_t e, const EnrichedQuadratureOptions& options,
                  std::vector<double>& out, std::vector<Task>& tasks) {
  out.clear();
  CellBuilder builder{in, options, out, &tasks, e};
  if (options.adaptive && builder.uniform(0, 0, in.t, in.t, in.type == ElementType::tri6)) {
    // The whole element merged: exactly the standard element rule.
    const QuadratureRule r = element_quadrature(in.type);
    for (int q = 0; q < r.count; ++q) out.insert(out.end(), {r.xi1[q], r.xi2[q], r.weight[q]});
    return;
  }
  builder.visit(0, 0, in.t, in.t, 0);
}

}  // namespace

bool texels_share_one_quadratic(ElementType type, int t, const TextureView* textures, int texture_count,
                                const int* texels, int texel_count, const int reference[2], double size,
                                double tolerance) {
  for (int k = 0; k < texture_count; ++k) {
    TexelDerivatives ref;
    texel_derivatives(type, t, textures[k], reference[0], reference[1], ref);
    for (int n = 0; n < texel_count; ++n) {
      const int i = texels[2 * n], j = texels[2 * n + 1];
      TexelDerivatives d;
      texel_derivatives(type, t, textures[k], i, j, d);
      if (!agrees(ref, d, i - reference[0], j - reference[1], size, tolerance)) return false;
    }
  }
  return true;
}

void enriched_element_quadrature(const EnrichedElementBatch& batch, const EnrichedQuadratureOptions& options,
                                 std::vector<std::int64_t>& start, std::vector<double>& points, Execution execution) {
  enriched_element_quadrature(batch, options, start, points, nullptr, execution);
}

void enriched_element_quadrature(const EnrichedElementBatch& batch, const EnrichedQuadratureOptions& options,
                                 std::vector<std::int64_t>& start, std::vector<double>& points,
                                 std::vector<std::shared_ptr<const TexelDerivativeTile>>* derivatives,
                                 Execution execution) {
  const std::int64_t n = batch.count;
  const int t = batch.resolution;
  // 1. Per-texel inputs of every element, in row blocks (parallel even for one element).
  std::vector<ElementInputs> inputs(static_cast<std::size_t>(n));
  for (std::int64_t e = 0; e < n; ++e) {
    ElementInputs& in = inputs[e];
    const int first = batch.enrichment_start[e];
    in.type = batch.type;
    in.t = t;
    in.textures = batch.textures + first;
    in.texture_count = batch.enrichment_start[e + 1] - first;
    in.allocate(options.adaptive);
  }
  if (options.adaptive) {
    // Row blocks, then columns (of the wall-line prefix sums), in one parallel region. Two
    // loops, each split evenly: as one loop of blocks then columns, static scheduling gave
    // the first thread every (costly) block and the other only columns (chad: 1.9 ms a step
    // of texel derivatives on one thread of two).
    const std::int64_t blocks = (t + row_block - 1) / row_block;
    forall_then(
        n * blocks, [&](std::int64_t m) { inputs[m / blocks].build_block(static_cast<int>(m % blocks)); }, n * t,
        [&](std::int64_t m) { inputs[m / t].build_column(static_cast<int>(m % t)); }, execution);
  }
  // 2. The top levels of every element's quadtree; deeper cells become tasks.
  std::vector<std::vector<double>> planned(static_cast<std::size_t>(n));
  std::vector<std::vector<Task>> element_tasks(static_cast<std::size_t>(n));
  forall(n, [&](std::int64_t e) { plan_element(inputs[e], e, options, planned[e], element_tasks[e]); },
         n > 1 ? execution : Execution::serial);
  std::vector<Task*> tasks;
  for (auto& list : element_tasks)
    for (Task& task : list) tasks.push_back(&task);
  // 3. The subtrees, each into its own list. Neighbouring subtrees are alike in cost, so the
  // loop takes every other one first (static scheduling then hands each thread a mix).
  const std::int64_t task_count = static_cast<std::int64_t>(tasks.size()), half = (task_count + 1) / 2;
  forall(task_count, [&](std::int64_t m) {
    Task& task = *tasks[m < half ? 2 * m : 2 * (m - half) + 1];
    CellBuilder builder{inputs[task.element], options, task.points};
    builder.visit(task.i0, task.j0, task.w, task.h, task_depth);
  }, execution);
  // 4. Splice each element's task lists into its planned list at their positions.
  start.assign(static_cast<std::size_t>(n) + 1, 0);
  for (std::int64_t e = 0; e < n; ++e) {
    std::size_t size = planned[e].size();
    for (const Task& task : element_tasks[e]) size += task.points.size();
    start[e + 1] = start[e] + static_cast<std::int64_t>(size / 3);
  }
  points.resize(static_cast<std::size_t>(start[n]) * 3);
  for (std::int64_t e = 0; e < n; ++e) {  // copies only: not worth a parallel region
    const std::vector<double>& plan = planned[e];
    double* dst = points.data() + start[e] * 3;
    std::size_t from = 0;
    for (const Task& task : element_tasks[e]) {
      dst = std::copy(plan.begin() + from, plan.begin() + task.position, dst);
      dst = std::copy(task.points.begin(), task.points.end(), dst);
      from = task.position;
    }
    std::copy(plan.begin() + from, plan.end(), dst);
  }
  if (derivatives) {
    derivatives->assign(static_cast<std::size_t>(batch.enrichment_start[n] - batch.enrichment_start[0]), nullptr);
    if (options.adaptive)
      for (std::int64_t e = 0; e < n; ++e)
        for (int k = 0; k < inputs[e].texture_count; ++k)
          (*derivatives)[batch.enrichment_start[e] - batch.enrichment_start[0] + k] = std::move(inputs[e].field_tiles[k]);
  }
}

}  // namespace dgtex::kernels

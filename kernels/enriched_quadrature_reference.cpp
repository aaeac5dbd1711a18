// The serial reference twin of enriched_element_quadrature (enriched_quadrature.h): the
// straightforward form of the rule, kept as it was written first (every candidate cell
// tests its texels one by one from cached texel derivatives). The fast form must give
// bitwise the same point arrays (tests/test_enrichment_quadrature_speed.cpp).
#include "dgtex/kernels/enriched_quadrature.h"

#include <algorithm>
#include <cmath>

#include "dgtex/kernels/texel_grid.h"
#include "texel_cell_rules.h"

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

struct CellBuilder {
  ElementType type;
  int t;
  const TextureView* textures;
  int texture_count;
  const EnrichedQuadratureOptions& options;
  std::vector<TexelDerivatives> fields;  // texture_count x T x T (texels in the domain only)
  std::vector<double>& out;
  // Wall counts along texel rows and columns (walls of any texture), as prefix sums:
  // north_prefix[j * (T + 1) + i] = walls north of texels (0..i-1, j); east_prefix[i * (T + 1) + j]
  // = walls east of texels (i, 0..j-1).
  std::vector<int> north_prefix, east_prefix;
  TexelCellRules rules{type, t};

  void count_walls() {
    north_prefix.assign(static_cast<std::size_t>(t) * (t + 1), 0);
    east_prefix.assign(static_cast<std::size_t>(t) * (t + 1), 0);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        std::uint8_t f = 0;
        for (int k = 0; k < texture_count; ++k) f |= textures[k].flags[j * t + i];
        north_prefix[j * (t + 1) + i + 1] = north_prefix[j * (t + 1) + i] + ((f & stencil_barrier_north) ? 1 : 0);
        east_prefix[i * (t + 1) + j + 1] = east_prefix[i * (t + 1) + j] + ((f & stencil_barrier_east) ? 1 : 0);
      }
  }
  // Walls on the line between rows j and j + 1 over columns [i0, i0 + w), and between
  // columns i and i + 1 over rows [j0, j0 + h).
  int walls_north_of_row(int j, int i0, int w) const {
    return north_prefix[j * (t + 1) + i0 + w] - north_prefix[j * (t + 1) + i0];
  }
  int walls_east_of_column(int i, int j0, int h) const {
    return east_prefix[i * (t + 1) + j0 + h] - east_prefix[i * (t + 1) + j0];
  }

  // The interior line of a rectangular cell that carries walls along at least 3/4 of its
  // length and lies closest to the cell's middle (ties: horizontal, then lower). Splitting
  // there leaves a long straight wall on the border of both children instead of inside
  // them. Returns false when no line qualifies (no walls, or only short/staircase walls).
  bool wall_line(int i0, int j0, int w, int h, bool& horizontal, int& offset) const {
    long best = -1;  // distance to the middle, relative to the cell size (cross-multiplied)
    auto dominant = [](int walls, int length) { return 4 * walls >= 3 * length; };
    for (int m = 1; m < h; ++m)
      if (dominant(walls_north_of_row(j0 + m - 1, i0, w), w)) {
        const long d = static_cast<long>(std::abs(2 * m - h)) * w;
        if (best < 0 || d < best) best = d, horizontal = true, offset = m;
      }
    for (int m = 1; m < w; ++m)
      if (dominant(walls_east_of_column(i0 + m - 1, j0, h), h)) {
        const long d = static_cast<long>(std::abs(2 * m - w)) * h;
        if (best < 0 || d < best) best = d, horizontal = false, offset = m;
      }
    return best >= 0;
  }

  const TexelDerivatives& field(int k, int i, int j) const {
    return fields[(static_cast<std::size_t>(k) * t + j) * t + i];
  }

  bool in_cell(int i, int j, int i0, int j0, int w, int h, bool triangle) const {
    if (i < i0 || j < j0 || i >= i0 + w || j >= j0 + h) return false;
    return !triangle || (i - i0) + (j - j0) <= w - 1;
  }

  bool uniform(int i0, int j0, int w, int h, bool triangle) const {
    int ri = i0 + w / 2, rj = j0 + h / 2;
    if (triangle) ri = i0 + w / 4, rj = j0 + h / 4;
    const double size = std::max(w, h);
    for (int j = j0; j < j0 + h; ++j)
      for (int i = i0; i < i0 + w; ++i) {
        if (!in_cell(i, j, i0, j0, w, h, triangle)) continue;
        for (int k = 0; k < texture_count; ++k) {
          const std::uint8_t* flags = textures[k].flags;
          if (!texel_in_domain(type, t, flags, i, j)) return false;
          const std::uint8_t f = flags[j * t + i];
          if ((f & stencil_barrier_east) && in_cell(i + 1, j, i0, j0, w, h, triangle)) return false;
          if ((f & stencil_barrier_north) && in_cell(i, j + 1, i0, j0, w, h, triangle)) return false;
          if (!agrees(field(k, ri, rj), field(k, i, j), i - ri, j - rj, size, options.merge_tolerance)) return false;
        }
      }
    return true;
  }

  void visit(int i0, int j0, int w, int h) {
    const bool tri = type == ElementType::tri6;
    if (tri && i0 + j0 >= t) return;  // outside the triangle
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
        // Sides of at most 2 texels: 2 Gauss points, near the texel centres (3 would put the
        // middle ones on the texel edge between two texel polynomials).
        else rules.rectangle(out, i0, j0, w, h, w <= 2 ? 2 : 3, h <= 2 ? 2 : 3);
        return;
      }
    }
    // Wall-aware splits of rectangular cells (not the tri6 diagonal): at a long straight
    // wall, else in halves of the long side only for an elongated cell.
    int w1 = (w + 1) / 2, h1 = (h + 1) / 2;
    if (options.adaptive && inside) {
      bool horizontal = false;
      int offset = 0;
      if (wall_line(i0, j0, w, h, horizontal, offset)) {
        if (horizontal) {
          visit(i0, j0, w, offset);
          visit(i0, j0 + offset, w, h - offset);
        } else {
          visit(i0, j0, offset, h);
          visit(i0 + offset, j0, w - offset, h);
        }
        return;
      }
      if (w >= 2 * h) h1 = h;
      else if (h >= 2 * w) w1 = w;
    }
    visit(i0, j0, w1, h1);
    if (w > w1) visit(i0 + w1, j0, w - w1, h1);
    if (h > h1) visit(i0, j0 + h1, w1, h - h1);
    if (w > w1 && h > h1) visit(i0 + w1, j0 + h1, w - w1, h - h1);
  }
};

void element_points(const EnrichedElementBatch& b, std::int64_t e, const EnrichedQuadratureOptions& options,
                    std::vector<double>& out) {
  out.clear();
  const int first = b.enrichment_start[e], count = b.enrichment_start[e + 1] - first;
  const int t = b.resolution;
  CellBuilder builder{b.type, t, b.textures + first, count, options, {}, out, {}, {}};
  if (options.adaptive) {
    builder.fields.resize(static_cast<std::size_t>(count) * t * t);
    for (int k = 0; k < count; ++k)
      for (int j = 0; j < t; ++j)
        for (int i = 0; i < t; ++i)
          if (texel_in_domain(b.type, t, b.textures[first + k].flags, i, j))
            texel_derivatives(b.type, t, b.textures[first + k], i, j, builder.fields[(static_cast<std::size_t>(k) * t + j) * t + i]);
    builder.count_walls();
    // The whole element merged: exactly the standard element rule.
    const bool triangle = b.type == ElementType::tri6;
    if (builder.uniform(0, 0, t, t, triangle)) {
      const QuadratureRule r = element_quadrature(b.type);
      for (int q = 0; q < r.count; ++q) out.insert(out.end(), {r.xi1[q], r.xi2[q], r.weight[q]});
      return;
    }
  }
  builder.visit(0, 0, t, t);
}

}  // namespace

void enriched_element_quadrature_reference(const EnrichedElementBatch& batch, const EnrichedQuadratureOptions& options,
                                           std::vector<std::int64_t>& start, std::vector<double>& points) {
  start.assign(static_cast<std::size_t>(batch.count) + 1, 0);
  points.clear();
  std::vector<double> element;
  for (std::int64_t e = 0; e < batch.count; ++e) {
    element_points(batch, e, options, element);
    points.insert(points.end(), element.begin(), element.end());
    start[e + 1] = start[e] + static_cast<std::int64_t>(element.size() / 3);
  }
}

}  // namespace dgtex::kernels

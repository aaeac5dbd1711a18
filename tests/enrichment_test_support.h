#pragma once
// Hand-built enrichment inputs for the enriched-shell tests: a complete straight cut given
// by a level function f (cut where f = 0, H = +1 where f > 0, -1 elsewhere), with walls
// between texels on different sides; rigid motions of one piece in the enriched DOFs; and
// polygon moments of the pieces of a rectangle.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include "dgtex/enrichment_function.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/texel_grid.h"
#include "dgtex/shell_model.h"

namespace dgtex::testing_support {

using LevelFunction = std::function<double(const double* x)>;

// Position on the element's rest mid-surface at xi.
inline void surface_point(const Mesh& mesh, int e, double xi1, double xi2, double x[3]) {
  kernels::ShapeValues s;
  kernels::evaluate_shape(mesh.type, xi1, xi2, s);
  x[0] = x[1] = x[2] = 0;
  for (int a = 0; a < s.count; ++a)
    for (int c = 0; c < 3; ++c) x[c] += s.N[a] * mesh.node(mesh.element_nodes(e)[a])[c];
}

inline double side_of(const LevelFunction& f, const Mesh& mesh, int e, double xi1, double xi2) {
  double x[3];
  surface_point(mesh, e, xi1, xi2, x);
  return f(x) > 0 ? 1.0 : -1.0;
}

// The texture of H on element e: texel sides from the texel centres. With `aligned`, every
// texel must lie wholly on one side (its corners' f never of the opposite sign), i.e. the
// cut runs along texel edges; the test fails otherwise.
inline kernels::TexelTile cut_texture(const Mesh& mesh, int e, int t, const LevelFunction& f, bool aligned = true) {
  kernels::TexelTile tile = kernels::make_element_tile(mesh.type, t);
  const bool tri = mesh.type == ElementType::tri6;
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      if (tri && i + j > t - 1) continue;
      double c[2];
      kernels::texel_centre(mesh.type, t, i, j, c);
      const double side = side_of(f, mesh, e, c[0], c[1]);
      tile.values[tile.index(i, j)] = side;
      if (aligned) {
        const double h = kernels::texel_size(mesh.type, t);
        for (int corner = 0; corner < 4; ++corner) {
          const double xi1 = c[0] + ((corner & 1) ? 0.5 : -0.5) * h, xi2 = c[1] + ((corner & 2) ? 0.5 : -0.5) * h;
          if (tri && corner == 3 && i + j == t - 1) continue;  // outside the triangle
          double x[3];
          surface_point(mesh, e, xi1, xi2, x);
          EXPECT_GE(side * f(x), -1e-12) << "cut not along texel edges: element " << e << " texel " << i << "," << j;
        }
      }
    }
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      if (!kernels::texel_in_domain(mesh.type, t, tile.flags.data(), i, j)) continue;
      const double v = tile.values[tile.index(i, j)];
      if (kernels::texel_in_domain(mesh.type, t, tile.flags.data(), i + 1, j) && tile.values[tile.index(i + 1, j)] != v)
        tile.flags[tile.index(i, j)] |= kernels::wall_east;
      if (kernels::texel_in_domain(mesh.type, t, tile.flags.data(), i, j + 1) && tile.values[tile.index(i, j + 1)] != v)
        tile.flags[tile.index(i, j)] |= kernels::wall_north;
    }
  return tile;
}

// N_i: nodes of the elements with texels on both sides; Omega_i: elements incident to them.
// aligned: require the cut to run along texel edges (see cut_texture).
inline EnrichmentFunction straight_cut_enrichment(const Mesh& mesh, int t, const LevelFunction& f, bool aligned = true) {
  const int npe = mesh.nodes_per_element();
  std::vector<kernels::TexelTile> tiles;
  std::vector<char> enriched(mesh.num_nodes(), 0);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    tiles.push_back(cut_texture(mesh, e, t, f, aligned));
    bool plus = false, minus = false;
    for (int k = 0; k < t * t; ++k)
      if (!(tiles[e].flags[k] & kernels::inactive)) (tiles[e].values[k] > 0 ? plus : minus) = true;
    if (plus && minus)
      for (int a = 0; a < npe; ++a) enriched[mesh.element_nodes(e)[a]] = 1;
  }
  EnrichmentFunction function;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (enriched[n]) function.enriched_nodes.push_back(n);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    bool touches = false;
    for (int a = 0; a < npe; ++a) touches = touches || enriched[mesh.element_nodes(e)[a]];
    if (touches) function.elements.push_back({e, tiles[e]});
  }
  return function;
}

// DOF vector of the field r(x) on the piece `side` (+1: f > 0) and zero on the other piece,
// for a model whose only enrichment is the straight cut of f (function 0): standard DOF
// u^a = r(x^a) on nodes of the piece, enriched DOF q^a = side r(x^a) / 2.
inline std::vector<double> piece_field(const ShellModel& model, const LevelFunction& f, double side,
                                       const std::function<void(const double*, double*)>& r) {
  const Mesh& mesh = model.mesh();
  std::vector<double> u(model.num_dofs(), 0.0);
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    double v[3];
    r(mesh.node(n), v);
    const double node_side = f(mesh.node(n)) > 0 ? 1.0 : -1.0;
    if (node_side == side)
      for (int c = 0; c < 3; ++c) u[3 * n + c] = v[c];
    const int virtual_node = model.virtual_node(0, n);
    if (virtual_node >= 0)
      for (int c = 0; c < 3; ++c) u[3 * virtual_node + c] = side * 0.5 * v[c];
  }
  return u;
}

// Area, first moments (int x, int y) and second moments (int x^2, int y^2) of the part of
// the rectangle [0, a] x [0, b] where f > 0 (f affine in x, y), by the polygon formulas.
struct PolygonMoments {
  double area = 0, mx = 0, my = 0, mxx = 0, myy = 0;
};
inline PolygonMoments half_rectangle_moments(double a, double b, const LevelFunction& f, double side) {
  const std::vector<std::array<double, 2>> box = {{0, 0}, {a, 0}, {a, b}, {0, b}};
  auto g = [&](const std::array<double, 2>& p) {
    const double x[3] = {p[0], p[1], 0};
    return side * f(x);
  };
  std::vector<std::array<double, 2>> poly;  // Sutherland-Hodgman against g >= 0
  for (size_t k = 0; k < box.size(); ++k) {
    const auto& p = box[k];
    const auto& q = box[(k + 1) % box.size()];
    const double gp = g(p), gq = g(q);
    if (gp >= 0) poly.push_back(p);
    if ((gp >= 0) != (gq >= 0)) {
      const double s = gp / (gp - gq);
      poly.push_back({p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])});
    }
  }
  PolygonMoments m;
  for (size_t k = 0; k < poly.size(); ++k) {
    const auto& p = poly[k];
    const auto& q = poly[(k + 1) % poly.size()];
    const double cross = p[0] * q[1] - q[0] * p[1];
    m.area += 0.5 * cross;
    m.mx += (p[0] + q[0]) * cross / 6;
    m.my += (p[1] + q[1]) * cross / 6;
    m.mxx += (p[0] * p[0] + p[0] * q[0] + q[0] * q[0]) * cross / 12;
    m.myy += (p[1] * p[1] + p[1] * q[1] + q[1] * q[1]) * cross / 12;
  }
  return m;
}

// Equal to the last bit (memcmp, so -0.0 differs from 0.0 and a NaN equals itself).
inline bool bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// Two models equal to the last bit in what a simulation reads of them: the block pattern,
// the mass, gravity and area loads, and the unrotated stiffness.
inline void expect_models_equal_bitwise(ShellModel& a, ShellModel& b) {
  ASSERT_EQ(a.num_dofs(), b.num_dofs());
  EXPECT_EQ(a.pattern().column(), b.pattern().column());
  EXPECT_EQ(a.pattern().row_start(), b.pattern().row_start());
  EXPECT_TRUE(bitwise_equal(a.mass_blocks(), b.mass_blocks()));
  const double g[3] = {0.1, -0.2, -9.81}, q[3] = {1, 2, 3};
  std::vector<double> fa(a.num_dofs(), 0.0), fb(b.num_dofs(), 0.0);
  a.add_gravity(g, fa);
  a.add_area_force(q, fa);
  b.add_gravity(g, fb);
  b.add_area_force(q, fb);
  EXPECT_TRUE(bitwise_equal(fa, fb));
  std::vector<double> ka, kb;
  a.assemble_stiffness(nullptr, ka, nullptr);
  b.assemble_stiffness(nullptr, kb, nullptr);
  EXPECT_TRUE(bitwise_equal(ka, kb));
}

}  // namespace dgtex::testing_support

// The enriched basis (H - H(xi^a)) N^a evaluated from enrichment textures: exact for
// quadratic textures, O(h^2) first / O(h) second derivatives for smooth ones, derivatives
// consistent with finite differences of the values, and no difference across a wall.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/texel_grid.h"

using namespace dgtex::kernels;

namespace {

const char* name_of(ElementType t) { return t == ElementType::quad8 ? "quad8" : "tri6"; }

// An analytic field with its derivatives (columns 11, 22, 12).
struct Field {
  std::function<double(double, double)> value;
  std::function<void(double, double, double[2], double[3])> derivatives;
};

Field quadratic_field() {
  return {[](double x, double y) { return x * x - y * y + 0.3 * x * y + 0.2 * x - 0.1; },
          [](double x, double y, double d[2], double d2[3]) {
            d[0] = 2 * x + 0.3 * y + 0.2;
            d[1] = -2 * y + 0.3 * x;
            d2[0] = 2, d2[1] = -2, d2[2] = 0.3;
          }};
}

Field smooth_field() {
  return {[](double x, double y) { return std::sin(2 * x) * std::cos(1.5 * y); },
          [](double x, double y, double d[2], double d2[3]) {
            d[0] = 2 * std::cos(2 * x) * std::cos(1.5 * y);
            d[1] = -1.5 * std::sin(2 * x) * std::sin(1.5 * y);
            d2[0] = -4 * std::sin(2 * x) * std::cos(1.5 * y);
            d2[1] = -2.25 * std::sin(2 * x) * std::cos(1.5 * y);
            d2[2] = -3 * std::cos(2 * x) * std::sin(1.5 * y);
          }};
}

TexelTile sampled(ElementType type, int t, const Field& f) {
  TexelTile tile = make_element_tile(type, t);
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      double c[2];
      texel_centre(type, t, i, j, c);
      tile.values[tile.index(i, j)] = f.value(c[0], c[1]);
    }
  return tile;
}

// Random points of the element (tri6: inside the triangle).
std::vector<std::array<double, 2>> points_in(ElementType type, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::array<double, 2>> p;
  while (static_cast<int>(p.size()) < count) {
    const double a = u(rng), b = u(rng);
    if (type == ElementType::quad8) p.push_back({2 * a - 1, 2 * b - 1});
    else if (a + b <= 1) p.push_back({a, b});
  }
  return p;
}

// A one-element batch with every node enriched by one texture.
struct OneElement {
  std::vector<int> element{0}, connectivity, start{0, 1}, nodes;
  std::vector<double> shifts;
  std::vector<TextureView> textures;
  EnrichedElementBatch batch;
  OneElement(ElementType type, int t, const TexelTile& tile, const std::vector<double>& node_shift) : shifts(node_shift) {
    const int npe = nodes_per_element(type);
    for (int a = 0; a < npe; ++a) connectivity.push_back(a), nodes.push_back(100 + a);
    textures.push_back({tile.values.data(), tile.flags.data()});
    batch = {type, 1, element.data(), connectivity.data(), nullptr, nullptr, t, 2 * npe,
             start.data(), textures.data(), nodes.data(), shifts.data()};
  }
};

TEST(EnrichedBasis, QuadraticTexturesAreReproducedExactly) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const int t = 16;
    const Field f = quadratic_field();
    const TexelTile tile = sampled(type, t, f);
    const int npe = nodes_per_element(type);
    std::vector<double> shift(npe);
    for (int a = 0; a < npe; ++a) {
      double xi[2];
      node_parametric_position(type, a, xi);
      shift[a] = f.value(xi[0], xi[1]);
      // The node shift sampled by the texel rule is exact too (edge/corner texels included),
      // except at the acute tri6 corners (nodes 1, 2): their corner texel has no neighbour
      // along one axis, so H is constant along it there (documented limitation).
      TextureSample s;
      sample_texture(type, t, {tile.values.data(), tile.flags.data()}, xi[0], xi[1], s);
      const bool acute = type == ElementType::tri6 && (a == 1 || a == 2);
      EXPECT_NEAR(s.value, shift[a], acute ? 0.5 * 2.0 / t : 1e-12) << name_of(type) << " node " << a;
    }
    OneElement one(type, t, tile, shift);
    double worst = 0;
    for (const auto& p : points_in(type, 200, 1)) {
      // tri6: within 3 texels of the acute corners the axis stencils are one-sided and
      // first order (or missing): quadratics are not reproduced there.
      if (type == ElementType::tri6 && std::max(p[0], p[1]) > 1 - 3.0 / t) continue;
      ShapeValues s;
      evaluate_shape(type, p[0], p[1], s);
      EnrichedShapeValues es;
      evaluate_enriched_shape(one.batch, 0, p[0], p[1], s, es);
      ASSERT_EQ(es.count, 2 * npe);
      double h = f.value(p[0], p[1]), d[2], d2[3];
      f.derivatives(p[0], p[1], d, d2);
      for (int a = 0; a < npe; ++a) {
        const int k = npe + a;
        const double psi = h - shift[a];
        const double* dN = s.dN[a];
        const double* d2N = s.d2N[a];
        const double expect[6] = {psi * s.N[a],
                                  d[0] * s.N[a] + psi * dN[0],
                                  d[1] * s.N[a] + psi * dN[1],
                                  d2[0] * s.N[a] + 2 * d[0] * dN[0] + psi * d2N[0],
                                  d2[1] * s.N[a] + 2 * d[1] * dN[1] + psi * d2N[1],
                                  d2[2] * s.N[a] + d[0] * dN[1] + d[1] * dN[0] + psi * d2N[2]};
        const double got[6] = {es.N[k], es.dN[k][0], es.dN[k][1], es.d2N[k][0], es.d2N[k][1], es.d2N[k][2]};
        for (int c = 0; c < 6; ++c) worst = std::max(worst, std::abs(got[c] - expect[c]));
      }
    }
    EXPECT_LT(worst, 1e-10) << name_of(type);
  }
}

TEST(EnrichedBasis, SmoothTexturesConvergeAtTheStatedOrders) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Field f = smooth_field();
    const auto points = points_in(type, 400, 2);
    double previous[3] = {0, 0, 0};
    for (int t : {32, 64, 128}) {
      const TexelTile tile = sampled(type, t, f);
      double err[3] = {0, 0, 0};  // value, first, second derivatives
      for (const auto& p : points) {
        TextureSample s;
        sample_texture(type, t, {tile.values.data(), tile.flags.data()}, p[0], p[1], s);
        double d[2], d2[3];
        f.derivatives(p[0], p[1], d, d2);
        err[0] = std::max(err[0], std::abs(s.value - f.value(p[0], p[1])));
        err[1] = std::max({err[1], std::abs(s.d[0] - d[0]), std::abs(s.d[1] - d[1])});
        err[2] = std::max({err[2], std::abs(s.d2[0] - d2[0]), std::abs(s.d2[1] - d2[1]), std::abs(s.d2[2] - d2[2])});
      }
      std::printf("%s T=%d: max error value %.2e, first derivatives %.2e, second derivatives %.2e\n", name_of(type), t,
                  err[0], err[1], err[2]);
      if (previous[0] > 0) {
        EXPECT_GT(previous[0] / err[0], 3.5) << "value O(h^2) (or better)";
        EXPECT_GT(previous[1] / err[1], 3.5) << "first derivatives O(h^2)";
        EXPECT_GT(previous[2] / err[2], 1.8) << "second derivatives O(h)";
      }
      for (int k = 0; k < 3; ++k) previous[k] = err[k];
    }
    EXPECT_LT(previous[1], 1e-3);
    EXPECT_LT(previous[2], 0.1);
  }
}

// Random texel values with two wall lines: the derivatives of every enriched basis
// function match central differences of its values (and of its first derivatives) inside
// texels, so the value, gradient and Hessian of the scheme are one consistent function.
TEST(EnrichedBasis, DerivativesMatchFiniteDifferencesOfTheValues) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const int t = 8;
    TexelTile tile = make_element_tile(type, t);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (double& v : tile.values) v = u(rng);
    for (int j = 0; j < t; ++j) tile.flags[tile.index(2, j)] |= wall_east;
    for (int i = 0; i < t; ++i) tile.flags[tile.index(i, 4)] |= wall_north;
    const int npe = nodes_per_element(type);
    std::vector<double> shift(npe);
    for (double& s : shift) s = u(rng);
    OneElement one(type, t, tile, shift);
    const double h = texel_size(type, t);
    const double step = 1e-6 * h;
    auto eval = [&](double x1, double x2, EnrichedShapeValues& out) {
      ShapeValues s;
      evaluate_shape(type, x1, x2, s);
      evaluate_enriched_shape(one.batch, 0, x1, x2, s, out);
    };
    double worst1 = 0, worst2 = 0, scale1 = 0, scale2 = 0;
    std::uniform_real_distribution<double> inner(0.2, 0.8);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        if (!texel_in_domain(type, t, tile.flags.data(), i, j)) continue;
        double c[2];
        texel_centre(type, t, i, j, c);
        const double r1 = inner(rng), r2 = inner(rng);
        if (type == ElementType::tri6 && i + j == t - 1 && r1 + r2 > 1) continue;
        const double x1 = c[0] + (r1 - 0.5) * h, x2 = c[1] + (r2 - 0.5) * h;
        EnrichedShapeValues at, p1, m1, p2, m2;
        eval(x1, x2, at);
        eval(x1 + step, x2, p1);
        eval(x1 - step, x2, m1);
        eval(x1, x2 + step, p2);
        eval(x1, x2 - step, m2);
        for (int k = npe; k < at.count; ++k) {
          const double fd1[2] = {(p1.N[k] - m1.N[k]) / (2 * step), (p2.N[k] - m2.N[k]) / (2 * step)};
          const double fd2[3] = {(p1.dN[k][0] - m1.dN[k][0]) / (2 * step), (p2.dN[k][1] - m2.dN[k][1]) / (2 * step),
                                 (p2.dN[k][0] - m2.dN[k][0]) / (2 * step)};
          const double fd12 = (p1.dN[k][1] - m1.dN[k][1]) / (2 * step);
          for (int c2 = 0; c2 < 2; ++c2) {
            worst1 = std::max(worst1, std::abs(fd1[c2] - at.dN[k][c2]));
            scale1 = std::max(scale1, std::abs(at.dN[k][c2]));
          }
          for (int c3 = 0; c3 < 3; ++c3) {
            worst2 = std::max(worst2, std::abs(fd2[c3] - at.d2N[k][c3]));
            scale2 = std::max(scale2, std::abs(at.d2N[k][c3]));
          }
          worst2 = std::max(worst2, std::abs(fd12 - at.d2N[k][2]));  // both mixed orders agree
        }
      }
    std::printf("%s: FD consistency, first derivatives %.2e of %.2e, second %.2e of %.2e\n", name_of(type), worst1,
                scale1, worst2, scale2);
    EXPECT_LT(worst1, 1e-6 * scale1) << name_of(type);
    EXPECT_LT(worst2, 1e-6 * scale2) << name_of(type);
  }
}

TEST(EnrichedBasis, DifferencesNeverReachAcrossAWall) {
  // +1 / -1 on either side of a wall: every texel, including those next to the wall, has
  // exactly zero derivatives (a one-sided difference of a constant), and the value is exact.
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const int t = 16;
    TexelTile tile = make_element_tile(type, t);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        tile.values[tile.index(i, j)] = i <= 5 ? -1 : 1;
        if (i == 5) tile.flags[tile.index(i, j)] |= wall_east;
      }
    for (const auto& p : points_in(type, 300, 3)) {
      TextureSample s;
      sample_texture(type, t, {tile.values.data(), tile.flags.data()}, p[0], p[1], s);
      int i = 0, j = 0;
      containing_texel(type, t, p[0], p[1], i, j);
      EXPECT_EQ(s.value, i <= 5 ? -1.0 : 1.0);
      for (double d : s.d) EXPECT_EQ(d, 0.0);
      for (double d : s.d2) EXPECT_EQ(d, 0.0);
    }
  }
}

TEST(EnrichedBasis, ContainingTexelRule) {
  int i = 0, j = 0;
  containing_texel(ElementType::quad8, 8, 1.0, 1.0, i, j);  // corner node: clamped
  EXPECT_EQ(i, 7);
  EXPECT_EQ(j, 7);
  containing_texel(ElementType::quad8, 8, 0.0, -1.0, i, j);  // on a texel edge: larger index
  EXPECT_EQ(i, 4);
  EXPECT_EQ(j, 0);
  containing_texel(ElementType::tri6, 8, 0.5, 0.5, i, j);  // hypotenuse midside node
  EXPECT_EQ(i, 4);
  EXPECT_EQ(j, 3);
  EXPECT_TRUE(is_tri6_texel_active(i, j, 8));
  containing_texel(ElementType::tri6, 8, 0.0, 1.0, i, j);
  EXPECT_EQ(i, 0);
  EXPECT_EQ(j, 7);
}

}  // namespace

// closest_surface_point: exact answers on planes (interior, edges, corners, ties), the
// cylinder distance |r - R| within the mesh's own geometric deviation, first-order
// optimality, and a brute-force oracle on a curved tri6 mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "dgtex/mesh_generators.h"
#include "dgtex/surface_point.h"

using namespace dgtex;

namespace {

void surface_at(const Mesh& mesh, int e, const double xi[2], double x[3], double t1[3], double t2[3]) {
  kernels::ShapeValues s;
  kernels::evaluate_shape(mesh.type, xi[0], xi[1], s);
  for (int d = 0; d < 3; ++d) x[d] = t1[d] = t2[d] = 0;
  for (int a = 0; a < s.count; ++a) {
    const double* p = mesh.node(mesh.element_nodes(e)[a]);
    for (int d = 0; d < 3; ++d) x[d] += s.N[a] * p[d], t1[d] += s.dN[a][0] * p[d], t2[d] += s.dN[a][1] * p[d];
  }
}

bool inside_reference(ElementType type, const double xi[2]) {
  if (type == ElementType::quad8) return std::fabs(xi[0]) <= 1 && std::fabs(xi[1]) <= 1;
  return xi[0] >= 0 && xi[1] >= 0 && xi[0] + xi[1] <= 1 + 1e-15;
}

// The result is self-consistent: xi in the reference element, position = x(xi), distance =
// |position - p|.
void expect_consistent(const Mesh& mesh, const SurfacePoint& sp, const double p[3]) {
  ASSERT_GE(sp.element, 0);
  ASSERT_LT(sp.element, mesh.num_elements());
  EXPECT_TRUE(inside_reference(mesh.type, sp.xi)) << sp.xi[0] << ", " << sp.xi[1];
  double x[3], t1[3], t2[3];
  surface_at(mesh, sp.element, sp.xi, x, t1, t2);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(sp.position[d], x[d], 1e-14);
  EXPECT_NEAR(sp.distance, std::hypot(x[0] - p[0], x[1] - p[1], x[2] - p[2]), 1e-14);
}

// Strictly inside the reference element: on an element edge the surface has a kink and
// only the constrained optimality holds there.
bool strictly_inside(ElementType type, const double xi[2]) {
  return type == ElementType::quad8 ? std::fabs(xi[0]) < 1 && std::fabs(xi[1]) < 1
                                    : xi[0] > 0 && xi[1] > 0 && xi[0] + xi[1] < 1;
}

// x(xi) - p at the answer: its largest component along the surface's unit tangents there
// (0 at a first-order optimum inside an element) and its length.
struct TangentialGap {
  double largest = 0, length = 0;
};
TangentialGap tangential_gap(const Mesh& mesh, const SurfacePoint& sp, const double p[3]) {
  double x[3], t1[3], t2[3];
  surface_at(mesh, sp.element, sp.xi, x, t1, t2);
  const double g[3] = {x[0] - p[0], x[1] - p[1], x[2] - p[2]};
  TangentialGap gap;
  gap.largest = std::max(std::fabs(g[0] * t1[0] + g[1] * t1[1] + g[2] * t1[2]) / std::hypot(t1[0], t1[1], t1[2]),
                         std::fabs(g[0] * t2[0] + g[1] * t2[1] + g[2] * t2[2]) / std::hypot(t2[0], t2[1], t2[2]));
  gap.length = std::hypot(g[0], g[1], g[2]);
  return gap;
}

}  // namespace

class SurfacePointPlane : public ::testing::TestWithParam<ElementType> {};
INSTANTIATE_TEST_SUITE_P(ElementTypes, SurfacePointPlane, ::testing::Values(ElementType::quad8, ElementType::tri6),
                         [](const auto& info) { return info.param == ElementType::quad8 ? "quad8" : "tri6"; });

TEST_P(SurfacePointPlane, OnAndOffThePlane) {
  const Mesh mesh = make_rectangle(2.0, 1.0, 4, 3, GetParam());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(0, 2), uy(0, 1), uz(-2, 2);
  for (int i = 0; i < 50; ++i) {
    const double z = i < 10 ? 0.0 : uz(rng);  // the first ten lie on the plane
    const double p[3] = {ux(rng), uy(rng), z};
    const SurfacePoint sp = closest_surface_point(mesh, p);
    expect_consistent(mesh, sp, p);
    EXPECT_NEAR(sp.position[0], p[0], 1e-14);
    EXPECT_NEAR(sp.position[1], p[1], 1e-14);
    EXPECT_NEAR(sp.position[2], 0.0, 1e-15);
    EXPECT_NEAR(sp.distance, std::fabs(z), 1e-14);
  }
}

TEST_P(SurfacePointPlane, BeyondEdgesAndCorners) {
  const Mesh mesh = make_rectangle(2.0, 1.0, 4, 3, GetParam());
  struct Case {
    double p[3], q[3];
  };
  const Case cases[] = {{{3.0, 0.4, 1.0}, {2.0, 0.4, 0.0}},    // beyond the x = 2 edge
                        {{0.7, -0.5, -0.2}, {0.7, 0.0, 0.0}},  // beyond y = 0
                        {{-1.0, -1.0, -1.0}, {0.0, 0.0, 0.0}},  // beyond the corner (0, 0)
                        {{2.5, 3.0, 0.0}, {2.0, 1.0, 0.0}}};   // beyond the corner (2, 1), in plane
  for (const Case& c : cases) {
    const SurfacePoint sp = closest_surface_point(mesh, c.p);
    expect_consistent(mesh, sp, c.p);
    for (int d = 0; d < 3; ++d) EXPECT_NEAR(sp.position[d], c.q[d], 1e-14) << "query " << c.p[0] << ", " << c.p[1];
    EXPECT_NEAR(sp.distance, std::hypot(c.p[0] - c.q[0], c.p[1] - c.q[1], c.p[2] - c.q[2]), 1e-14);
  }
}

// Small elements (fracture's 1/16-wide tri6 and quad8; a 1 cm cylinder): Newton stops where
// its steps stop shrinking (the gradient is round-off there), and not before: on the plane
// the answer is the query itself to round-off, on the cylinder x - p is normal to the
// surface to round-off of the element's size.
TEST(SurfacePoint, SmallElementsConvergeToRoundOff) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh plate = make_rectangle(1.0, 1.0, 16, 17, type);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1), uz(-0.01, 0.01);
    for (int i = 0; i < 200; ++i) {
      const double p[3] = {u(rng), u(rng), i < 100 ? 0.0 : uz(rng)};
      const SurfacePoint sp = closest_surface_point(plate, p);
      EXPECT_NEAR(sp.position[0], p[0], 4e-16) << "query " << i;
      EXPECT_NEAR(sp.position[1], p[1], 4e-16) << "query " << i;
      EXPECT_EQ(sp.position[2], 0.0);
    }
    const double R = 0.01;
    const Mesh cylinder = make_cylinder(R, 2 * R, 0, 360, 24, 4, type);
    std::uniform_real_distribution<double> angle(0, 2 * M_PI), along(0.05 * R, 1.95 * R), radius(0.5 * R, 1.5 * R);
    int interior_count = 0;
    for (int i = 0; i < 100; ++i) {
      const double t = angle(rng), r = radius(rng);
      const double p[3] = {r * std::sin(t), along(rng), r * std::cos(t)};
      const SurfacePoint sp = closest_surface_point(cylinder, p);
      expect_consistent(cylinder, sp, p);
      if (!strictly_inside(type, sp.xi)) continue;
      ++interior_count;
      EXPECT_LT(tangential_gap(cylinder, sp, p).largest, 1e-16) << "query " << i;
    }
    EXPECT_GT(interior_count, 50);
  }
}

TEST(SurfacePoint, TiesGoToTheLowestElement) {
  // Above the interior node (1, 1) of a 2x2 quad8 grid: all four elements touch it.
  const Mesh mesh = make_rectangle(2.0, 2.0, 2, 2, ElementType::quad8);
  const double node[3] = {1.0, 1.0, 0.5};
  EXPECT_EQ(closest_surface_point(mesh, node).element, 0);
  // Above the edge x = 1 between elements 2 and 3 (top row).
  const double edge[3] = {1.0, 1.5, -0.3};
  const SurfacePoint sp = closest_surface_point(mesh, edge);
  EXPECT_EQ(sp.element, 2);
  EXPECT_NEAR(sp.xi[0], 1.0, 1e-15);
  EXPECT_NEAR(sp.distance, 0.3, 1e-15);
}

TEST(SurfacePoint, CylinderDistanceIsRadialOffset) {
  const double R = 1.0, L = 2.0;
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_cylinder(R, L, 0, 360, 24, 4, type);
    // Geometric deviation of the quadratic surface from the exact cylinder, sampled densely.
    double deviation = 0;
    for (int e = 0; e < mesh.num_elements(); ++e)
      for (int i = 0; i <= 50; ++i)
        for (int j = 0; j <= 50; ++j) {
          double xi[2] = {type == ElementType::quad8 ? -1 + 0.04 * i : 0.02 * i,
                          type == ElementType::quad8 ? -1 + 0.04 * j : 0.02 * j};
          if (!inside_reference(type, xi)) continue;
          double x[3], t1[3], t2[3];
          surface_at(mesh, e, xi, x, t1, t2);
          deviation = std::max(deviation, std::fabs(std::hypot(x[0], x[2]) - R));
        }
    EXPECT_LT(deviation, 2e-5);  // 15 degree quadratic arcs
    EXPECT_GT(deviation, 1e-7);  // ... which are not exact: the bound below is not vacuous
    deviation *= 1.01;  // the sampled maximum may miss the true one slightly
    int interior_count = 0;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> angle(0, 2 * M_PI), along(0.05, L - 0.05);
    for (double r : {0.3, 0.9, 0.99999, 1.0, 1.2, 3.0}) {
      for (int i = 0; i < 8; ++i) {
        const double t = angle(rng), y = along(rng);
        const double p[3] = {r * std::sin(t), y, r * std::cos(t)};
        const SurfacePoint sp = closest_surface_point(mesh, p);
        expect_consistent(mesh, sp, p);
        // The surface lies between radii R - deviation and R + deviation.
        EXPECT_NEAR(sp.distance, std::fabs(r - R), deviation + 1e-14) << "r = " << r << " t = " << t;
        EXPECT_NEAR(sp.position[1], y, 1e-9);
        // First-order optimality where xi is inside the element: (x - p) is normal to the
        // surface up to rounding.
        if (!strictly_inside(type, sp.xi)) continue;
        ++interior_count;
        const TangentialGap gap = tangential_gap(mesh, sp, p);
        EXPECT_LT(gap.largest, 1e-10 * gap.length + 1e-15);
      }
    }
    EXPECT_GT(interior_count, 24);  // the optimality check ran on most of the 48 queries
    // On the axis every direction is (almost) equally near.
    const double axis[3] = {0, 1.0, 0};
    EXPECT_NEAR(closest_surface_point(mesh, axis).distance, R, deviation);
  }
}

// Against a brute-force oracle (dense samples of every element): the returned distance is
// never larger than any sample's, and not smaller than the true minimum (sample minimum
// minus the sampling resolution).
TEST(SurfacePoint, BruteForceOracleOnHemisphere) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_hemisphere(1.0, 30, 3, 6, type);
    const int m = 60;
    std::vector<double> samples;
    for (int e = 0; e < mesh.num_elements(); ++e)
      for (int i = 0; i <= m; ++i)
        for (int j = 0; j <= m; ++j) {
          double xi[2] = {type == ElementType::quad8 ? -1 + 2.0 * i / m : double(i) / m,
                          type == ElementType::quad8 ? -1 + 2.0 * j / m : double(j) / m};
          if (!inside_reference(type, xi)) continue;
          double x[3], t1[3], t2[3];
          surface_at(mesh, e, xi, x, t1, t2);
          samples.insert(samples.end(), x, x + 3);
        }
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.6, 1.6);
    for (int i = 0; i < 40; ++i) {
      const double p[3] = {u(rng), u(rng), u(rng)};
      const SurfacePoint sp = closest_surface_point(mesh, p);
      expect_consistent(mesh, sp, p);
      double brute = 1e300;
      for (size_t s = 0; s < samples.size(); s += 3)
        brute = std::min(brute, std::hypot(samples[s] - p[0], samples[s + 1] - p[1], samples[s + 2] - p[2]));
      EXPECT_LE(sp.distance, brute + 1e-14) << "query " << i;
      EXPECT_GT(sp.distance, brute - 0.02) << "query " << i;  // sample spacing <= ~0.02 here
    }
  }
}

TEST(SurfacePoint, RejectsBadQueries) {
  const Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const double nan_point[3] = {0, NAN, 0};
  EXPECT_THROW(closest_surface_point(mesh, nan_point), MeshError);
  const double p[3] = {0, 0, 0};
  EXPECT_THROW(closest_surface_point(Mesh{}, p), MeshError);
}

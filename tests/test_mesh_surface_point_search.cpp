// SurfacePointSearch (surface_point.h): bitwise the same answers as closest_surface_point,
// the brute-force search it prunes, on curved quad8 and tri6 meshes and on sub-meshes
// (the element lists the cut tracer searches first), including points on the surface,
// far away, on shared edges and nodes (ties), and beyond the mesh's border.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <unordered_map>

#include "dgtex/mesh_generators.h"
#include "dgtex/surface_point.h"

using namespace dgtex;

namespace {

void expect_same(const SurfacePoint& a, const SurfacePoint& b, const double p[3]) {
  const std::string where = "query (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ", " +
                            std::to_string(p[2]) + ")";
  EXPECT_EQ(a.element, b.element) << where;
  EXPECT_EQ(a.xi[0], b.xi[0]) << where;
  EXPECT_EQ(a.xi[1], b.xi[1]) << where;
  for (int d = 0; d < 3; ++d) EXPECT_EQ(a.position[d], b.position[d]) << where;
  EXPECT_EQ(a.distance, b.distance) << where;
}

// The sub-mesh of `elements` (ascending), as the cut tracer built it before.
Mesh sub_mesh(const Mesh& mesh, const std::vector<int>& elements) {
  Mesh sub;
  sub.type = mesh.type;
  std::unordered_map<int, int> local;
  for (int e : elements)
    for (int a = 0; a < mesh.nodes_per_element(); ++a) {
      const int n = mesh.element_nodes(e)[a];
      auto [it, added] = local.emplace(n, sub.num_nodes());
      if (added) sub.positions.insert(sub.positions.end(), mesh.node(n), mesh.node(n) + 3);
      sub.elements.push_back(it->second);
    }
  return sub;
}

std::vector<std::array<double, 3>> queries(const Mesh& mesh, unsigned seed) {
  std::vector<std::array<double, 3>> out;
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) lo[d] = hi[d] = mesh.positions[d];
  for (int n = 0; n < mesh.num_nodes(); ++n)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], mesh.node(n)[d]), hi[d] = std::max(hi[d], mesh.node(n)[d]);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 1.3);
  for (int k = 0; k < 150; ++k) {
    std::array<double, 3> p;
    for (int d = 0; d < 3; ++d) p[d] = lo[d] + u(rng) * (hi[d] - lo[d]);
    out.push_back(p);
  }
  // Every node (shared by several elements: ties) and far points.
  for (int n = 0; n < mesh.num_nodes(); ++n) out.push_back({mesh.node(n)[0], mesh.node(n)[1], mesh.node(n)[2]});
  out.push_back({100, -50, 20});
  out.push_back({0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])});
  return out;
}

}  // namespace

TEST(SurfacePointSearch, MatchesTheFullSearchBitwise) {
  const std::vector<Mesh> meshes = {make_cylinder(0.5, 2.0, 0, 360, 8, 5, ElementType::quad8),
                                    make_cylinder(0.5, 2.0, -60, 150, 6, 4, ElementType::tri6),
                                    make_hemisphere(1.0, 20, 4, 9, ElementType::tri6),
                                    make_rectangle(2.0, 1.0, 6, 3, ElementType::quad8),
                                    // a deep box hierarchy: fracture's mesh
                                    make_rectangle(1.0, 1.0, 16, 17, ElementType::tri6, TriangleSplit::square)};
  unsigned seed = 3;
  for (const Mesh& mesh : meshes) {
    const SurfacePointSearch search(mesh);
    for (const auto& p : queries(mesh, seed++)) expect_same(search.closest(p.data()), closest_surface_point(mesh, p.data()), p.data());
  }
}

TEST(SurfacePointSearch, SubsetMatchesTheSubMeshSearchBitwise) {
  const Mesh mesh = make_hemisphere(1.0, 20, 5, 10, ElementType::tri6);
  const SurfacePointSearch search(mesh);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<int> elements;
    for (int e = 0; e < mesh.num_elements(); ++e)
      if (rng() % 3 == 0) elements.push_back(e);
    ASSERT_FALSE(elements.empty());
    const Mesh sub = sub_mesh(mesh, elements);
    for (const auto& p : queries(sub, 100 + trial)) {
      SurfacePoint expected = closest_surface_point(sub, p.data());
      expected.element = elements[expected.element];
      expect_same(search.closest_among(elements, p.data()), expected, p.data());
    }
  }
}

// Refines every element from its best sample (a one-element search) and takes the nearest,
// ties within 1e-12 x the bounding-box diagonal to the lowest element: what the pruned
// searches must return bit for bit, since their lower bounds only skip elements that
// could not come within the tie tolerance of the answer.
SurfacePoint refine_every_element(const Mesh& mesh, const double p[3]) {
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) lo[d] = hi[d] = mesh.positions[d];
  for (int n = 0; n < mesh.num_nodes(); ++n)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], mesh.node(n)[d]), hi[d] = std::max(hi[d], mesh.node(n)[d]);
  const double tie = 1e-12 * std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  std::vector<SurfacePoint> each;
  double best = 1e300;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    SurfacePoint sp = closest_surface_point(sub_mesh(mesh, {e}), p);
    sp.element = e;
    best = std::min(best, sp.distance);
    each.push_back(sp);
  }
  for (const SurfacePoint& sp : each)
    if (sp.distance <= best + tie) return sp;  // the lowest element within the tie
  return {};
}

TEST(SurfacePointSearch, PruningKeepsTheAnswerOfRefiningEveryElement) {
  // Flat straight-sided elements (no bulge: only elements whose box is near the query are
  // refined), a slightly warped plate and curved cylinders (bulge bounds from the midside
  // offsets).
  // Warped plates: curved elements, and quad8 corners out of plane (a bilinear twist).
  const auto warp = [](Mesh mesh) {
    for (int n = 0; n < mesh.num_nodes(); ++n)
      mesh.positions[3 * n + 2] = 0.08 * std::sin(3 * mesh.node(n)[0]) * std::cos(4 * mesh.node(n)[1]);
    return mesh;
  };
  // A hyperbolic paraboloid z = c x y: quad8 elements with straight edges (midside nodes at
  // the midpoints: no bulge), twisted bilinear patches between their corner facets.
  Mesh hypar = make_rectangle(1.0, 1.0, 2, 2, ElementType::quad8);
  for (int n = 0; n < hypar.num_nodes(); ++n)
    hypar.positions[3 * n + 2] = 6.0 * (hypar.node(n)[0] - 0.5) * (hypar.node(n)[1] - 0.5);
  const std::vector<Mesh> meshes = {hypar, make_rectangle(1.0, 1.0, 5, 4, ElementType::tri6),
                                    make_rectangle(2.0, 1.0, 4, 3, ElementType::quad8),
                                    warp(make_rectangle(1.0, 1.0, 4, 4, ElementType::tri6)),
                                    warp(make_rectangle(1.0, 1.0, 3, 3, ElementType::quad8)),
                                    make_cylinder(0.5, 2.0, -25, 335, 6, 3, ElementType::quad8),
                                    make_cylinder(0.5, 2.0, -65, 150, 5, 3, ElementType::tri6)};
  unsigned seed = 21;
  for (const Mesh& mesh : meshes) {
    const SurfacePointSearch search(mesh);
    std::vector<std::array<double, 3>> points = queries(mesh, seed++);
    // Points on the surface, where the pruning skips the most.
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 400; ++k) {
      const int e = static_cast<int>(rng() % mesh.num_elements());
      double r = u(rng), s = u(rng);
      if (mesh.type == ElementType::tri6 && r + s > 1) r = 1 - r, s = 1 - s;
      if (mesh.type == ElementType::quad8) r = 2 * r - 1, s = 2 * s - 1;
      kernels::ShapeValues shape;
      kernels::evaluate_shape(mesh.type, r, s, shape);
      std::array<double, 3> x = {0, 0, 0};
      for (int a = 0; a < mesh.nodes_per_element(); ++a)
        for (int d = 0; d < 3; ++d) x[d] += shape.N[a] * mesh.node(mesh.element_nodes(e)[a])[d];
      points.push_back(x);
      // and just off it, where a neighbour's nearer sample may seed the search first
      x[2] += 0.05 * (u(rng) - 0.5);
      points.push_back(x);
    }
    // Radial points around the axis (y) at every degree: where an element's extreme in x
    // or z lies between its samples, its surface leaves the box of its samples.
    for (int degree = 0; degree < 360; ++degree) {
      const double t = degree * M_PI / 180;
      points.push_back({0.8 * std::sin(t), 0.37, 0.8 * std::cos(t)});
    }
    for (const auto& p : points) {
      const SurfacePoint expected = refine_every_element(mesh, p.data());
      expect_same(closest_surface_point(mesh, p.data()), expected, p.data());
      expect_same(search.closest(p.data()), expected, p.data());
    }
  }
}

TEST(SurfacePointSearch, Errors) {
  const Mesh mesh = make_rectangle(1.0, 1.0, 2, 2, ElementType::quad8);
  const SurfacePointSearch search(mesh);
  const double nan_point[3] = {0, std::nan(""), 0};
  EXPECT_THROW(search.closest(nan_point), MeshError);
  const double p[3] = {0.2, 0.2, 0};
  EXPECT_THROW(search.closest_among({}, p), MeshError);
  const Mesh no_elements;
  const SurfacePointSearch empty(no_elements);
  EXPECT_THROW(empty.closest(p), MeshError);
}

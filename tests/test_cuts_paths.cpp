// Mesh-level cut paths (cut_path.h): crossings of element edges are one surface point in
// both elements and a lattice point of both tiles, so the rasterised texel paths of
// neighbouring elements meet; paths through nodes; closed cylinders; error messages.
#include <gtest/gtest.h>

#include <cmath>

#include "cut_test_support.h"
#include "dgtex/cut_manager.h"
#include "dgtex/cut_path.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/surface_point.h"
#include "dgtex/topology.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

double distance(const Vec3& a, const Vec3& b) { return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

Vec3 position_of(const Mesh& mesh, int element, std::array<double, 2> xi) {
  Vec3 x, n;
  element_surface_point(mesh, element, xi.data(), x, n);
  return x;
}

// Rest position of a lattice point (x, y) of element e's tile.
Vec3 lattice_position(const Mesh& mesh, int e, int t, int x, int y) {
  const auto xi = kernels::parametric_from_texel_point(mesh.type, t, {double(x), double(y)});
  return position_of(mesh, e, xi);
}

// Every element change of the path happens at one surface point whose parameters are a
// lattice point in both elements; the rasters of consecutive pieces meet there.
void expect_continuous_crossings(const Mesh& mesh, const Cut& cut, int t, int expected_min_crossings) {
  const Topology topology = build_topology(mesh);
  const ElementAdjacency adjacency(mesh, topology);
  const MeshCutPath path = trace_cut_path(mesh, adjacency, cut, t, "cuts[0]");
  int crossings = 0;
  for (std::size_t k = 0; k + 1 < path.vertices.size(); ++k) {
    const CutPathVertex &a = path.vertices[k], &b = path.vertices[k + 1];
    if (a.element == b.element) continue;
    ++crossings;
    EXPECT_EQ(a.arc_length, b.arc_length);
    for (const CutPathVertex* v : {&a, &b}) {
      const auto p = kernels::texel_point_from_parametric(mesh.type, t, v->xi[0], v->xi[1]);
      EXPECT_NEAR(p[0], std::round(p[0]), 1e-9);
      EXPECT_NEAR(p[1], std::round(p[1]), 1e-9);
    }
    EXPECT_LT(distance(position_of(mesh, a.element, a.xi), position_of(mesh, b.element, b.xi)), 1e-12);
  }
  EXPECT_GE(crossings, expected_min_crossings);

  // Rasters: the pieces of the (single) function in consecutive elements share end points.
  EnrichmentOptions options;
  options.texture_resolution = t;
  CutManager manager(mesh, topology, {cut}, options);
  manager.update(0.0);
  ASSERT_EQ(manager.rasters().size(), 1u);
  const auto& pieces = manager.rasters()[0];
  ASSERT_GE(pieces.size(), 2u);
  for (std::size_t k = 0; k + 1 < pieces.size(); ++k) {
    const auto& last = pieces[k].second.edges.back();
    const auto& first = pieces[k + 1].second.edges.front();
    const Vec3 end = lattice_position(mesh, pieces[k].first, t, last.x + last.dx, last.y + last.dy);
    const Vec3 begin = lattice_position(mesh, pieces[k + 1].first, t, first.x, first.y);
    EXPECT_LT(distance(end, begin), 1e-12) << "pieces " << k << " (element " << pieces[k].first << ") and "
                                           << k + 1 << " (element " << pieces[k + 1].first << ")";
  }
}

}  // namespace

TEST(CutPaths, QuadCrossingsMeetOnTheTexelLattice) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  expect_continuous_crossings(mesh, points_cut({{0.2, 0.71, 0}, {1.4, 1.3, 0}, {2.83, 2.27, 0}}), 32, 3);
}

TEST(CutPaths, Tri6CrossingsMeetOnTheTexelLattice) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::tri6);
  expect_continuous_crossings(mesh, points_cut({{0.2, 0.71, 0}, {1.4, 1.3, 0}, {2.83, 2.27, 0}}), 32, 5);
}

// On a flat mesh a chord is its own projection: each crossing's (unsnapped) position lies
// on the line between the cut's points and on a grid line of the mesh (x or y a whole
// number; tri6 also the diagonals x - y whole), found by false position on the distance
// from the shared edge.
TEST(CutPaths, FlatCrossingsLieWhereTheChordMeetsTheEdge) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_rectangle(3, 3, 3, 3, type);
    const Topology topology = build_topology(mesh);
    const ElementAdjacency adjacency(mesh, topology);
    const Vec3 a{0.2, 0.71, 0}, b{2.83, 2.27, 0};
    const MeshCutPath path = trace_cut_path(mesh, adjacency, points_cut({a, b}), 32, "cuts[0]");
    int crossings = 0;
    for (std::size_t k = 0; k + 1 < path.vertices.size(); ++k) {
      if (path.vertices[k].element == path.vertices[k + 1].element) continue;
      ++crossings;
      const Vec3& x = path.vertices[k].position;
      const double off_line = std::abs((b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0])) /
                              std::hypot(b[0] - a[0], b[1] - a[1]);
      EXPECT_LT(off_line, 1e-12) << "crossing " << crossings;
      double off_grid = std::min(std::abs(x[0] - std::round(x[0])), std::abs(x[1] - std::round(x[1])));
      if (type == ElementType::tri6) off_grid = std::min(off_grid, std::abs(x[0] - x[1] - std::round(x[0] - x[1])));
      EXPECT_LT(off_grid, 1e-12) << "crossing " << crossings << " at " << x[0] << ", " << x[1];
      EXPECT_EQ(x[2], 0.0);
    }
    EXPECT_GE(crossings, type == ElementType::quad8 ? 3 : 5);
  }
}

TEST(CutPaths, CurvedCylinderCrossingsMeet) {
  const Mesh mesh = make_cylinder(1.0, 2.0, 0, 360, 6, 2, ElementType::quad8);
  std::vector<Vec3> ring;
  for (int k = 0; k <= 24; ++k) {
    const double a = 2 * M_PI * k / 24;
    ring.push_back({std::sin(a), 0.7 + 0.5 * k / 24, std::cos(a)});
  }
  expect_continuous_crossings(mesh, points_cut(ring), 32, 6);
}

TEST(CutPaths, DiagonalThroughNodesVisitsOnlyDiagonalElements) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  const Topology topology = build_topology(mesh);
  const ElementAdjacency adjacency(mesh, topology);
  const MeshCutPath path = trace_cut_path(mesh, adjacency, points_cut({{0, 0, 0}, {3, 3, 0}}), 16, "cuts[0]");
  // Rounding of the chord may graze an element touching the diagonal at a node: only in
  // a zero-length piece at that node.
  for (const CutPathVertex& v : path.vertices)
    if (!(v.element == 0 || v.element == 4 || v.element == 8)) {
      EXPECT_EQ(std::abs(v.xi[0]), 1.0) << v.element;
      EXPECT_EQ(std::abs(v.xi[1]), 1.0) << v.element;
    }
  EXPECT_NEAR(path.length(), 3 * std::sqrt(2.0), 1e-11);
}

TEST(CutPaths, ArcLengthIsRestLength) {
  const Mesh mesh = make_cylinder(1.0, 2.0, 0, 360, 8, 2, ElementType::quad8);
  const Topology topology = build_topology(mesh);
  const ElementAdjacency adjacency(mesh, topology);
  std::vector<Vec3> ring;
  for (int k = 0; k <= 64; ++k) ring.push_back({std::sin(2 * M_PI * k / 64), 1.0, std::cos(2 * M_PI * k / 64)});
  const MeshCutPath path = trace_cut_path(mesh, adjacency, points_cut(ring), 64, "cuts[0]");
  // The surface is the quadratic interpolation of the circle (8 elements of 45 degrees:
  // its circumference is about 5e-4 short of 2 pi).
  EXPECT_NEAR(path.length(), 2 * M_PI, 5e-3);
}

namespace {
std::string error_of(const Mesh& mesh, const Cut& cut) {
  const Topology topology = build_topology(mesh);
  const ElementAdjacency adjacency(mesh, topology);
  try {
    trace_cut_path(mesh, adjacency, cut, 16, "cuts[2]");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST(CutPaths, ErrorsNameThePointTheValueAndWhatIsValid) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  std::string m = error_of(mesh, points_cut({{0.5, 0.5, 0}, {1, 1, 0.6}}));
  EXPECT_NE(m.find("cuts[2].points[1]"), std::string::npos) << m;
  EXPECT_NE(m.find("off the surface"), std::string::npos) << m;
  EXPECT_NE(m.find("[1, 1, 0.6]"), std::string::npos) << m;
  EXPECT_NE(m.find("within 0.25"), std::string::npos) << m;

  m = error_of(mesh, points_cut({{0.5, 0.5, 0}, {0.5, 0.5, 0.1}}));  // both project to one point
  EXPECT_NE(m.find("cuts[2].points: zero-length cut"), std::string::npos) << m;

  Cut s;
  s.kind = Cut::Kind::surface_points;
  s.surface_points = {{0, {0, 0}}, {9, {0, 0}}};
  m = error_of(mesh, s);
  EXPECT_NE(m.find("cuts[2].surface_points[1].element: no such element, got 9; the mesh has elements 0..8"),
            std::string::npos)
      << m;
  s.surface_points = {{0, {0, 0}}, {1, {0.5, 1.5}}};
  m = error_of(mesh, s);
  EXPECT_NE(m.find("cuts[2].surface_points[1].xi: outside the reference element, got [0.5, 1.5]; quad8 needs"),
            std::string::npos)
      << m;
  const Mesh tri = make_rectangle(3, 3, 3, 3, ElementType::tri6);
  s.surface_points = {{0, {0.2, 0.2}}, {1, {0.7, 0.7}}};
  m = error_of(tri, s);
  EXPECT_NE(m.find("tri6 needs xi1, xi2 >= 0 and xi1 + xi2 <= 1"), std::string::npos) << m;
  s.surface_points = {{4, {0.3, 0.3}}, {4, {0.3, 0.3}}};
  m = error_of(mesh, s);
  EXPECT_NE(m.find("zero-length cut"), std::string::npos) << m;
  s.surface_points = {{4, {0.3, 0.3}}};
  m = error_of(mesh, s);
  EXPECT_NE(m.find("at least 2 points"), std::string::npos) << m;
}

TEST(CutPaths, SurfacePointsInOneElementAreStraightInParameters) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  const Topology topology = build_topology(mesh);
  const ElementAdjacency adjacency(mesh, topology);
  Cut s;
  s.kind = Cut::Kind::surface_points;
  s.surface_points = {{4, {-0.5, -0.5}}, {4, {0.5, 0.25}}, {5, {0.0, 0.0}}};
  const MeshCutPath path = trace_cut_path(mesh, adjacency, s, 16, "cuts[0]");
  ASSERT_GE(path.vertices.size(), 4u);
  EXPECT_EQ(path.vertices[1].element, 4);
  EXPECT_EQ(path.vertices[1].xi[0], 0.5);
  EXPECT_EQ(path.vertices.back().element, 5);
  EXPECT_NEAR(path.vertices[1].arc_length, std::hypot(0.5, 0.375), 1e-12);
}

#include "dgtex/scene_io.h"
#include "dgtex/scene_mesh_checks.h"
#include "dgtex/scene_model.h"

TEST(CutPaths, SceneCheckRejectsPointsOffTheSurface) {
  const std::string text = R"({
    "mesh": {"generator": "rectangle", "size": [3, 3], "divisions": [3, 3], "element": "quad8"},
    "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01},
    "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
    "cuts": [{"points": [[0.5, 0.5, 0], [1.5, 0.5, 0]]}, {"points": [[0.5, 0.5, 0], [1.5, 0.5, 2.0]]}]
  })";
  const Scene scene = parse_scene(text, "scene.json");
  const Mesh mesh = build_scene_mesh(scene);
  try {
    check_scene_against_mesh(scene, mesh);
    FAIL() << "expected a SceneError";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("scene.json: cuts[1].points[1]: off the surface, got [1.5, 0.5, 2]"), std::string::npos) << m;
    EXPECT_NE(m.find("within 0.25 of the surface"), std::string::npos) << m;
  }
}

TEST(CutPaths, LargeMeshUsesTheSamePathAsTheWholeMeshSearch) {
  // 144 elements: chord samples are projected on a local patch first. The crossings must
  // still meet, and the path length is the straight distance on the plane.
  const Mesh mesh = make_rectangle(6, 6, 12, 12, ElementType::tri6);
  const Cut cut = points_cut({{0.05, 0.3, 0}, {5.93, 5.1, 0}});
  expect_continuous_crossings(mesh, cut, 16, 20);
  const Topology topology = build_topology(mesh);
  const MeshCutPath path = trace_cut_path(mesh, ElementAdjacency(mesh, topology), cut, 16, "cuts[0]");
  EXPECT_NEAR(path.length(), std::hypot(5.88, 4.8), 1e-9);
  for (const CutPathVertex& v : path.vertices) {
    const Vec3 x = position_of(mesh, v.element, v.xi);
    // every vertex (crossings unsnapped in `position`) lies on the chord
    EXPECT_NEAR((v.position[0] - 0.05) * 4.8 - (v.position[1] - 0.3) * 5.88, 0.0, 1e-9);
    EXPECT_LT(distance(x, v.position), 6.0 / 12 / 16);  // snapped within a texel
  }
}

TEST(CutPaths, OneSearchForManyCutsGivesEachCutsOwnPath) {
  // CutManager traces its cuts concurrently with one SurfacePointSearch: each path is
  // bitwise the one traced with a search of its own, whatever the order of the cuts.
  const Mesh mesh = make_cylinder(1.0, 2.0, 0, 180, 12, 4, ElementType::tri6);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  const std::vector<Cut> cuts = {points_cut({{0.0, 0.2, 1.0}, {1.0, 1.8, 0.0}}),
                                 points_cut({{0.43589, 0.5, -0.9}, {0.6, 0.9, 0.8}, {0.31225, 1.5, 0.95}})};
  const SurfacePointSearch search(mesh);
  for (int c : {1, 0, 1}) {
    const MeshCutPath own = trace_cut_path(mesh, adjacency, cuts[c], 32, "cuts[0]");
    const MeshCutPath shared = trace_cut_path(mesh, search, adjacency, cuts[c], 32, "cuts[0]");
    ASSERT_EQ(own.vertices.size(), shared.vertices.size());
    ASSERT_GT(own.vertices.size(), 10u);
    for (std::size_t k = 0; k < own.vertices.size(); ++k) {
      EXPECT_EQ(own.vertices[k].element, shared.vertices[k].element);
      EXPECT_EQ(own.vertices[k].xi, shared.vertices[k].xi);
      EXPECT_EQ(own.vertices[k].arc_length, shared.vertices[k].arc_length);
      EXPECT_EQ(own.vertices[k].position, shared.vertices[k].position);
    }
  }
}

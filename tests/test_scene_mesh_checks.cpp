// Scene checks that need the mesh: empty selections, surface points, rigid motions left
// free in static runs.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "dgtex/mesh_generators.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_mesh_checks.h"

namespace {

using namespace dgtex;

BoundaryCondition on_plane(Vec3 normal, double offset, std::array<bool, 3> fixed, bool clamp) {
  BoundaryCondition bc;
  bc.select.kind = BoundarySelect::Kind::plane;
  bc.select.normal = normal;
  bc.select.offset = offset;
  bc.fixed = fixed;
  bc.clamp = clamp;
  return bc;
}

Scene static_scene() {
  Scene s;
  s.source_name = "checks.json";
  return s;
}

std::string error_of(const Scene& scene, const Mesh& mesh) {
  try {
    check_scene_against_mesh(scene, mesh);
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    return e.what();
  }
  return "";
}

constexpr std::array<bool, 3> kAll{true, true, true};

TEST(SceneMeshChecks, SelectionThatSelectsNothing) {
  const Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::quad8);
  Scene s = static_scene();
  s.boundary.push_back(on_plane({1, 0, 0}, 0, kAll, true));
  s.boundary.push_back(on_plane({1, 0, 0}, 1.5, kAll, false));  // beyond x = 1
  const std::string message = error_of(s, mesh);
  EXPECT_EQ(message.rfind("checks.json: boundary[1].select: selects no mesh node, got {\"plane\": {\"normal\": [1, 0, 0], "
                          "\"offset\": 1.5}",
                          0),
            0u)
      << message;
  EXPECT_NE(message.find("span [0, 0, 0] to [1, 1, 0]"), std::string::npos) << message;
}

TEST(SceneMeshChecks, CantileverNeedsTheClamp) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_rectangle(2, 1, 4, 2, type);
    Scene s = static_scene();
    s.boundary.push_back(on_plane({1, 0, 0}, 0, kAll, false));
    // Nodes on one straight line leave the rotation about that line free.
    const std::string message = error_of(s, mesh);
    EXPECT_EQ(message.rfind("checks.json: boundary: the model is statically unconstrained", 0), 0u) << message;
    EXPECT_NE(message.find("rotation about [0, 1, 0]"), std::string::npos) << message;
    s.boundary[0].clamp = true;
    EXPECT_EQ(error_of(s, mesh), "");
    // A dynamic run has mass, so it needs no support.
    Scene free_flying = static_scene();
    free_flying.analysis.type = Analysis::Type::dynamic;
    EXPECT_EQ(error_of(free_flying, mesh), "");
  }
}

TEST(SceneMeshChecks, SimplySupportedPlateIsHeld) {
  const Mesh mesh = make_rectangle(2, 1, 4, 2, ElementType::quad8);
  Scene s = static_scene();
  s.boundary.push_back(on_plane({1, 0, 0}, 0, kAll, false));
  s.boundary.push_back(on_plane({1, 0, 0}, 2, {false, false, true}, false));
  EXPECT_EQ(error_of(s, mesh), "");
}

// One node far from the supports (the centre of a plate held on its four sides lifted to
// z = 1e5) sized the part by its bounding box, and the held nodes' rotation rows fell below
// the rank test's tolerance: "unconstrained". The held nodes' spread sizes it now.
TEST(SceneMeshChecks, AFarNodeDoesNotHideTheSupports) {
  Mesh mesh = make_rectangle(1, 1, 4, 4, ElementType::quad8);
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (mesh.node(n)[0] == 0.5 && mesh.node(n)[1] == 0.5) mesh.positions[3 * n + 2] = 1e5;
  Scene s = static_scene();
  s.boundary.push_back(on_plane({1, 0, 0}, 0, kAll, false));
  s.boundary.push_back(on_plane({1, 0, 0}, 1, kAll, false));
  s.boundary.push_back(on_plane({0, 1, 0}, 0, kAll, false));
  s.boundary.push_back(on_plane({0, 1, 0}, 1, kAll, false));
  EXPECT_EQ(error_of(s, mesh), "");
  s.boundary.resize(1);  // one side, no clamp: the rotation about it is free
  EXPECT_NE(error_of(s, mesh).find("rotation about [0, 1, 0]"), std::string::npos) << error_of(s, mesh);
}

TEST(SceneMeshChecks, InPlaneMotionsLeftFree) {
  const Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::quad8);
  Scene s = static_scene();
  s.boundary.push_back(on_plane({0, 0, 1}, 0, {false, false, true}, false));  // every node, z only
  const std::string message = error_of(s, mesh);
  EXPECT_NE(message.find("statically unconstrained"), std::string::npos) << message;
  // No boundary condition at all.
  EXPECT_NE(error_of(static_scene(), mesh).find("statically unconstrained"), std::string::npos);
}

TEST(SceneMeshChecks, EveryDisconnectedPartNeedsSupport) {
  Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const Mesh other = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const int offset = mesh.num_nodes();
  for (int n = 0; n < other.num_nodes(); ++n) {
    mesh.positions.push_back(other.node(n)[0] + 3);  // a second square at x in [3, 4]
    mesh.positions.push_back(other.node(n)[1]);
    mesh.positions.push_back(other.node(n)[2]);
  }
  for (int node : other.elements) mesh.elements.push_back(node + offset);
  Scene s = static_scene();
  s.boundary.push_back(on_plane({1, 0, 0}, 0, kAll, true));
  const std::string message = error_of(s, mesh);
  EXPECT_NE(message.find("statically unconstrained (the part containing node " + std::to_string(offset)), std::string::npos)
      << message;
  s.boundary.push_back(on_plane({1, 0, 0}, 4, kAll, true));
  EXPECT_EQ(error_of(s, mesh), "");
}

// Appends b to a, sharing the nodes of b that lie exactly on nodes of a.
Mesh joined_where_nodes_meet(Mesh a, const Mesh& b) {
  std::vector<int> index(b.num_nodes());
  for (int n = 0; n < b.num_nodes(); ++n) {
    index[n] = -1;
    for (int m = 0; m < a.num_nodes() && index[n] < 0; ++m)
      if (a.node(m)[0] == b.node(n)[0] && a.node(m)[1] == b.node(n)[1] && a.node(m)[2] == b.node(n)[2]) index[n] = m;
    if (index[n] >= 0) continue;
    index[n] = a.num_nodes();
    a.positions.insert(a.positions.end(), b.node(n), b.node(n) + 3);
  }
  for (int node : b.elements) a.elements.push_back(index[node]);
  return a;
}

Mesh moved(Mesh mesh, const std::function<Vec3(const double*)>& map) {
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const Vec3 x = map(mesh.node(n));
    for (int c = 0; c < 3; ++c) mesh.positions[3 * n + c] = x[c];
  }
  return mesh;
}

BoundaryCondition at_point(Vec3 p, std::array<bool, 3> fixed) {
  BoundaryCondition bc;
  bc.select.kind = BoundarySelect::Kind::box;
  bc.select.min = bc.select.max = p;
  bc.fixed = fixed;
  return bc;
}

// Two squares that meet at one corner: a shared node ties their translations there but
// not their rotations, so clamping one leaves the other free to turn about the corner.
// It used to pass this check and fail in the factorisation as "penalty too low?".
TEST(SceneMeshChecks, PartsMeetingAtANodeTurnAboutIt) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh square = make_rectangle(1, 1, 1, 1, type);
    const Mesh bowtie =
        joined_where_nodes_meet(square, moved(square, [](const double* x) { return Vec3{x[0] + 1, x[1] + 1, x[2]}; }));
    ASSERT_EQ(bowtie.num_nodes(), 2 * square.num_nodes() - 1);
    Scene s = static_scene();
    s.boundary.push_back(on_plane({1, 0, 0}, 0, kAll, true));
    const std::string message = error_of(s, bowtie);
    EXPECT_NE(message.find("statically unconstrained (the part containing node " + std::to_string(square.num_nodes())),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("it meets the rest of the mesh only at single nodes (node "), std::string::npos) << message;
    s.boundary.push_back(on_plane({1, 0, 0}, 2, kAll, true));  // the second square clamped too
    EXPECT_EQ(error_of(s, bowtie), "");
  }
}

// Parts that each keep one free rotation can hold each other through the node they share:
// a square in the xy-plane pinned at two corners (free: the rotation about x = 0, which
// lifts the shared corner along z) and one in the xz-plane pinned at two corners (free:
// the rotation about its far edge, which moves the shared corner along y). Tested one part
// at a time, each would read as unconstrained; together they are held.
TEST(SceneMeshChecks, PartsMeetingAtANodeCanHoldEachOther) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh square = make_rectangle(1, 1, 1, 1, type);
    const Mesh upright = moved(square, [](const double* x) { return Vec3{1 + x[0], 1, x[1]}; });
    const Mesh corner = joined_where_nodes_meet(square, upright);
    ASSERT_EQ(corner.num_nodes(), 2 * square.num_nodes() - 1);
    Scene s = static_scene();
    for (Vec3 p : {Vec3{0, 0, 0}, Vec3{0, 1, 0}, Vec3{2, 1, 0}, Vec3{2, 1, 1}}) s.boundary.push_back(at_point(p, kAll));
    EXPECT_EQ(error_of(s, corner), "");
    s.boundary.pop_back();  // the upright square now also turns about its pinned corner
    EXPECT_NE(error_of(s, corner).find("statically unconstrained"), std::string::npos);
  }
}

TEST(SceneMeshChecks, ClampedCylinderEdgeIsHeld) {
  // An open quarter cylinder clamped along its straight edge at t = 0 (the top line z = R).
  const Mesh mesh = make_cylinder(1, 2, 0, 90, 4, 3, ElementType::quad8);
  Scene s = static_scene();
  s.boundary.push_back(on_plane({0, 0, 1}, 1, kAll, false));
  EXPECT_NE(error_of(s, mesh).find("statically unconstrained"), std::string::npos);
  s.boundary[0].clamp = true;
  EXPECT_EQ(error_of(s, mesh), "");
}

// The parser bounds surface-point element indices by divisions[0] * divisions[1] (times 2
// for tri6) before any mesh exists; the generators must agree.
TEST(SceneMeshChecks, GeneratorElementCountsMatchTheParserRule) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const int per_cell = type == ElementType::tri6 ? 2 : 1;
    EXPECT_EQ(make_rectangle(1, 2, 3, 5, type).num_elements(), 15 * per_cell);
    EXPECT_EQ(make_cylinder(1, 2, 0, 360, 6, 2, type).num_elements(), 12 * per_cell);
    EXPECT_EQ(make_cylinder(1, 2, 0, 90, 3, 2, type).num_elements(), 6 * per_cell);
    EXPECT_EQ(make_hemisphere(1, 20, 3, 8, type).num_elements(), 24 * per_cell);
  }
}

TEST(SceneMeshChecks, SurfacePoints) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);  // elements 0 at x<1, 1 at x>1
  Scene s = static_scene();
  s.analysis.type = Analysis::Type::dynamic;
  Cut cut;
  cut.kind = Cut::Kind::surface_points;
  cut.surface_points = {{0, {-1, 0}}, {1, {1, 0}}};
  s.cuts.push_back(cut);
  EXPECT_EQ(error_of(s, mesh), "");
  // Right edge of element 0 and left edge of element 1 are the same physical line.
  s.cuts[0].surface_points = {{0, {1, 0.5}}, {1, {-1, 0.5}}};
  EXPECT_EQ(error_of(s, mesh).rfind("checks.json: cuts[0].surface_points: zero-length cut on the surface", 0), 0u)
      << error_of(s, mesh);
  s.cuts[0].surface_points = {{0, {1, 0.5}}, {2, {-1, 0.5}}};
  EXPECT_EQ(error_of(s, mesh).rfind("checks.json: cuts[0].surface_points[1].element: no such element, got 2", 0), 0u)
      << error_of(s, mesh);
  const Mesh triangles = make_rectangle(2, 1, 2, 1, ElementType::tri6);
  s.cuts[0].surface_points = {{0, {0.1, 0.1}}, {1, {0.7, 0.7}}};
  EXPECT_EQ(error_of(s, triangles).rfind("checks.json: cuts[0].surface_points[1].xi: outside the reference element, got "
                                         "[0.7, 0.7]",
                                         0),
            0u)
      << error_of(s, triangles);
}

}  // namespace

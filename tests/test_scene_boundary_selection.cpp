// select_nodes on a small hand-built mesh: planes (any orientation), boxes, tolerances;
// the caution for tolerances of the mesh's size (dgtex/selection_caution.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "dgtex/boundary_selection.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/selection_caution.h"
#include "example_scene_files_support.h"

namespace {

using namespace dgtex;

// Two quad8 elements on [0,2] x [0,1] (z = 0) plus one orphan node that no element uses.
//   5 -10- 4 -9- 3        corners 0..5, midsides 6..12
//   11    12     8
//   0 -6-  1 -7- 2        orphan: node 13 at (0, 0, 0)
Mesh two_quads() {
  Mesh mesh;
  mesh.type = ElementType::quad8;
  mesh.positions = {0, 0, 0,   1, 0, 0,   2, 0, 0,   2, 1, 0,   1, 1, 0,   0, 1, 0,    // corners
                    0.5, 0, 0, 1.5, 0, 0, 2, 0.5, 0, 1.5, 1, 0, 0.5, 1, 0, 0, 0.5, 0,  // 6..11
                    1, 0.5, 0,                                                      // 12
                    0, 0, 0};                                                       // orphan 13
  mesh.elements = {0, 1, 4, 5, 6, 12, 10, 11,  //
                   1, 2, 3, 4, 7, 8, 9, 12};
  return mesh;
}

BoundarySelect plane(Vec3 normal, double offset, double tolerance) {
  BoundarySelect s;
  s.kind = BoundarySelect::Kind::plane;
  s.normal = normal;
  s.offset = offset;
  s.tolerance = tolerance;
  return s;
}

BoundarySelect box(Vec3 min, Vec3 max, double tolerance) {
  BoundarySelect s;
  s.kind = BoundarySelect::Kind::box;
  s.min = min;
  s.max = max;
  s.tolerance = tolerance;
  return s;
}

TEST(BoundarySelection, AxisPlanes) {
  const Mesh mesh = two_quads();
  EXPECT_EQ(select_nodes(mesh, plane({1, 0, 0}, 0, 1e-9)), (std::vector<int>{0, 5, 11}));  // not the orphan
  EXPECT_EQ(select_nodes(mesh, plane({1, 0, 0}, 2, 1e-9)), (std::vector<int>{2, 3, 8}));
  EXPECT_EQ(select_nodes(mesh, plane({0, -1, 0}, -1, 1e-9)), (std::vector<int>{3, 4, 5, 9, 10}));  // y = 1
  EXPECT_EQ(select_nodes(mesh, plane({0, 0, 1}, 0, 0)).size(), 13u);
  EXPECT_TRUE(select_nodes(mesh, plane({1, 0, 0}, 3, 1e-9)).empty());
}

TEST(BoundarySelection, TiltedPlane) {
  const Mesh mesh = two_quads();
  const double s = 1 / std::sqrt(2.0);
  // x + y = 1 passes through nodes 1 (1,0) and 5 (0,1) only (the cell centre is no quad8 node).
  EXPECT_EQ(select_nodes(mesh, plane({s, s, 0}, s, 1e-12)), (std::vector<int>{1, 5}));
  // x + y = 1.5: nodes 7 (1.5, 0), 10 (0.5, 1) and 12 (1, 0.5).
  EXPECT_EQ(select_nodes(mesh, plane({s, s, 0}, 1.5 * s, 1e-12)), (std::vector<int>{7, 10, 12}));
}

TEST(BoundarySelection, PlaneToleranceIsADistance) {
  Mesh mesh = two_quads();
  mesh.positions[3 * 8 + 0] = 2 + 5e-7;  // node 8 slightly off the plane x = 2
  EXPECT_EQ(select_nodes(mesh, plane({1, 0, 0}, 2, 1e-6)), (std::vector<int>{2, 3, 8}));
  EXPECT_EQ(select_nodes(mesh, plane({1, 0, 0}, 2, 1e-7)), (std::vector<int>{2, 3}));
  // Exactly at the tolerance counts as selected (representable values: 0.5 off, tolerance 0.5).
  EXPECT_EQ(select_nodes(mesh, plane({1, 0, 0}, 0.5, 0.5)), (std::vector<int>{0, 1, 4, 5, 6, 10, 11, 12}));
}

TEST(BoundarySelection, Boxes) {
  const Mesh mesh = two_quads();
  EXPECT_EQ(select_nodes(mesh, box({0.9, -1, -1}, {1.1, 2, 1}, 0)), (std::vector<int>{1, 4, 12}));
  // A degenerate box is a point; tolerance 0 picks exactly the node there.
  EXPECT_EQ(select_nodes(mesh, box({2, 1, 0}, {2, 1, 0}, 0)), (std::vector<int>{3}));
  // Bounds are inclusive and widened by the tolerance on every side.
  EXPECT_EQ(select_nodes(mesh, box({1.5, 0.5, 0}, {2, 1, 0}, 0)), (std::vector<int>{3, 8, 9}));
  EXPECT_EQ(select_nodes(mesh, box({1.75, 0.75, 0}, {1.75, 0.75, 0}, 0.25)), (std::vector<int>{3, 8, 9}));
  EXPECT_EQ(select_nodes(mesh, box({1.75, 0.75, 0}, {1.75, 0.75, 0}, 0.125)), (std::vector<int>{}));
  // The whole mesh, orphan excluded.
  EXPECT_EQ(select_nodes(mesh, box({-1, -1, -1}, {3, 3, 3}, 0)).size(), 13u);
  // The orphan sits at node 0's position, so a box around it still picks node 0 only.
  EXPECT_EQ(select_nodes(mesh, box({0, 0, 0}, {0, 0, 0}, 1e-9)), (std::vector<int>{0}));
}

TEST(BoundarySelection, ParsedPlaneNormalIsNormalised) {
  // normal [0, 3, 0] with offset 1 means y = 1 (offset is a distance along the unit normal).
  const Scene s = parse_scene(R"({"mesh": {"generator": "rectangle", "size": [2, 1], "divisions": [2, 1]},
    "material": {"youngs_modulus": 1, "poisson_ratio": 0.3, "thickness": 0.1},
    "boundary": [{"select": {"plane": {"normal": [0, 3, 0], "offset": 1}}, "fix": ["z"]}]})",
                              "plane.json");
  ASSERT_EQ(s.boundary.size(), 1u);
  EXPECT_EQ(s.boundary[0].select.normal, (Vec3{0, 1, 0}));
  EXPECT_EQ(select_nodes(two_quads(), s.boundary[0].select), (std::vector<int>{3, 4, 5, 9, 10}));
}

// A selection set in code (the C++ API) may give any non-zero normal, as a scene file may:
// the offset is still a distance along the unit normal.
TEST(BoundarySelection, PlaneNormalSetInCodeNeedNotBeAUnitVector) {
  const Mesh mesh = two_quads();
  EXPECT_EQ(select_nodes(mesh, plane({0, 3, 0}, 1, 1e-12)), (std::vector<int>{3, 4, 5, 9, 10}));
  const double s = 1 / std::sqrt(2.0);
  EXPECT_EQ(select_nodes(mesh, plane({2, 2, 0}, 1.5 * s, 1e-12)), (std::vector<int>{7, 10, 12}));
}

TEST(BoundarySelection, PointRuleMatchesNodeRule) {
  const BoundarySelect s = box({0, 0, 0}, {1, 1, 1}, 0.25);
  const double inside[3] = {1.25, -0.25, 0.5};
  const double outside[3] = {1.2500001, 0.5, 0.5};
  EXPECT_TRUE(point_is_selected(s, inside));
  EXPECT_FALSE(point_is_selected(s, outside));
}

// A tolerance is a length in the mesh's units: the default 1e-6 is 45 % of the two quads
// measured in micrometres, and cautioned; in metres, or below 1 % of the mesh, it is not.
TEST(SelectionCaution, AToleranceOfAPercentOfTheMeshOrMoreIsCautioned) {
  Scene scene;
  BoundaryCondition held;
  held.select = plane({1, 0, 0}, 0, 1e-6);
  held.fixed = {true, true, true};
  scene.boundary = {held, held};
  const Mesh metres = two_quads();
  EXPECT_EQ(selection_tolerance_caution(scene, metres), "");
  Mesh micrometres = metres;
  for (double& x : micrometres.positions) x *= 1e-6;
  const std::string caution = selection_tolerance_caution(scene, micrometres);
  for (const char* part : {"boundary[0].select.tolerance 1e-06 is 45 % of the mesh's size", "2.23607e-06",
                           "selects 8 of its 14 nodes", "a length in the mesh's units (default 1e-6)"})
    EXPECT_NE(caution.find(part), std::string::npos) << part << " not in: " << caution;
  // The line: 1 % of the diagonal, for the first selection that reaches it.
  const double diagonal = std::sqrt(5.0);
  scene.boundary[0].select.tolerance = 0.0099 * diagonal;
  scene.boundary[1].select.tolerance = 0.01 * diagonal;
  EXPECT_NE(selection_tolerance_caution(scene, metres).find("boundary[1].select.tolerance"), std::string::npos);
  scene.boundary[1].select.tolerance = 0.0099 * diagonal;
  EXPECT_EQ(selection_tolerance_caution(scene, metres), "");
}

TEST(SelectionCaution, NoExampleSceneIsCautioned) {
  const std::vector<std::string> files = test::example_scene_files();
  for (const std::string& file : files) {
    const Scene scene = load_scene(file);
    EXPECT_EQ(selection_tolerance_caution(scene, build_scene_mesh(scene)), "") << file;
  }
  EXPECT_GE(files.size(), 10u);
}

}  // namespace

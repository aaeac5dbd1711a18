// validate_mesh: each rejected defect gives a MeshError naming the element or node;
// element_area / element_perimeter against closed forms.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "dgtex/mesh_generators.h"
#include "dgtex/mesh_validation.h"

using namespace dgtex;

namespace {

std::string validation_message(const Mesh& mesh) {
  try {
    validate_mesh(mesh);
  } catch (const MeshError& error) {
    return error.what();
  }
  return "";
}

#define EXPECT_MESSAGE_CONTAINS(message, text) \
  EXPECT_NE((message).find(text), std::string::npos) << "message: '" << (message) << "'"

}  // namespace

TEST(Validation, GeneratedMeshesPass) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    EXPECT_NO_THROW(validate_mesh(make_rectangle(1, 2, 3, 4, type)));
    EXPECT_NO_THROW(validate_mesh(make_cylinder(1, 2, 0, 360, 3, 1, type)));  // smallest closed ring
    EXPECT_NO_THROW(validate_mesh(make_hemisphere(1, 5, 2, 3, type)));
  }
}

TEST(Validation, ZeroAreaElement) {
  // Collapse element 2 of a 2x2 quad8 rectangle onto a line: move its top corners (and top
  // midside) onto its bottom edge.
  Mesh mesh = make_rectangle(2, 2, 2, 2, ElementType::quad8);
  const int* n = mesh.element_nodes(2);
  for (int a : {2, 3, 6, 5, 7}) mesh.positions[3 * n[a] + 1] = mesh.node(n[0])[1];
  const std::string message = validation_message(mesh);
  EXPECT_MESSAGE_CONTAINS(message, "element 2 is degenerate");
}

TEST(Validation, NearZeroAreaTriangleNamesTheElement) {
  // A tri6 sliver whose apex is 1e-12 off its base line (relative to size 1).
  Mesh mesh;
  mesh.type = ElementType::tri6;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0.5, 1e-12, 0, 0.5, 0, 0, 0.75, 0.5e-12, 0, 0.25, 0.5e-12, 0};
  mesh.elements = {0, 1, 2, 3, 4, 5};
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "element 0 is degenerate");
  mesh.positions[7] = 1e-3;  // a thin but valid triangle
  mesh.positions[13] = mesh.positions[16] = 0.5e-3;
  EXPECT_EQ(validation_message(mesh), "");
}

// Slivers pass the Jacobian test while their stiffness is already round-off (a row of them
// across a clamped plate: 0.46 of its deflection at diameter^2 / area 1e5, OBJ fuzzing,
// session 68): refused above kMaxElementAspect.
TEST(Validation, SliversAboveTheAspectLimitAreRefused) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    // 1 x 5e-5: diameter^2 / area 2e4 (quad8), 4e4 (each tri6 half).
    EXPECT_MESSAGE_CONTAINS(validation_message(make_rectangle(1, 5e-5, 1, 1, type)), "element 0 is a sliver");
    EXPECT_MESSAGE_CONTAINS(validation_message(make_rectangle(1, 5e-5, 1, 1, type)), "is above 10000");
    EXPECT_EQ(validation_message(make_rectangle(1, 1e-3, 1, 1, type)), "");  // 1e3 (2e3): thin but sound
  }
}

// A reflex corner, or two corners at one point, kept every quadrature point's Jacobian
// positive (the factorisation then failed as "penalty too low?"): checked at the corners.
TEST(Validation, ReflexAndCollapsedCornersAreRefused) {
  Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::quad8);
  auto move_corner = [&](Mesh& m, int element, int corner, double x, double y) {
    const int* n = m.element_nodes(element);
    m.positions[3 * n[corner]] = x, m.positions[3 * n[corner] + 1] = y;
    // the midside nodes next to it stay at the middle of their edges
    const int before = (corner + 3) % 4, after = (corner + 1) % 4;
    for (const auto& [mid, other] : {std::pair{4 + before, before}, std::pair{4 + corner, after}})
      for (int d = 0; d < 2; ++d) m.positions[3 * n[mid] + d] = 0.5 * (m.positions[3 * n[corner] + d] + m.positions[3 * n[other] + d]);
  };
  EXPECT_EQ(validation_message(mesh), "");
  Mesh reflex = mesh;  // element 0's corner at the plate's centre pulled back past its diagonal
  move_corner(reflex, 0, 2, 0.1, 0.1);
  EXPECT_MESSAGE_CONTAINS(validation_message(reflex), "element 0 is degenerate at its corner 2");
  Mesh collapsed = mesh;  // element 0's corner 1 onto its corner 0: a zero-length edge
  move_corner(collapsed, 0, 1, 0, 0);
  EXPECT_MESSAGE_CONTAINS(validation_message(collapsed), "is degenerate");
}

// Triangle A (0,0,0), (1,0,0), (0.5,1,0) and triangle B across their edge 0-1, apex given.
Mesh two_triangles(const std::array<double, 3>& apex) {
  Mesh mesh;
  mesh.type = ElementType::tri6;
  const std::array<std::array<double, 3>, 4> corners = {{{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, apex}};
  for (const auto& c : corners) mesh.positions.insert(mesh.positions.end(), c.begin(), c.end());
  auto midside = [&](int a, int b) {
    for (int d = 0; d < 3; ++d) mesh.positions.push_back(0.5 * (corners[a][d] + corners[b][d]));
    return mesh.num_nodes() - 1;
  };
  const int m01 = midside(0, 1), m12 = midside(1, 2), m20 = midside(2, 0), m03 = midside(0, 3), m31 = midside(3, 1);
  mesh.elements = {0, 1, 2, m01, m12, m20, 1, 0, 3, m01, m03, m31};
  return mesh;
}

// B's apex beside A's: manifold and consistently oriented, but folded back 180 degrees (the
// corotated step read it as "penalty too low?"). A 90-degree fold is a crease and passes.
TEST(Validation, NeighboursFoldedBackOntoEachOtherAreRefused) {
  EXPECT_EQ(validation_message(two_triangles({0.5, -1, 0})), "");  // flat
  EXPECT_EQ(validation_message(two_triangles({0.5, 0, -1})), "");  // creased 90 degrees
  EXPECT_EQ(validation_message(two_triangles({0.5, 0.9, -0.2})), "");  // 167 degrees: below the 172
  const std::string folded = validation_message(two_triangles({0.5, 0.9, 0}));
  EXPECT_MESSAGE_CONTAINS(folded, "elements 0 and 1 fold back onto each other along their shared edge (nodes 0-1)");
  EXPECT_MESSAGE_CONTAINS(folded, "180 degrees apart");
}

TEST(Validation, RepeatedAndOutOfRangeNodes) {
  Mesh mesh = make_rectangle(1, 1, 2, 1, ElementType::quad8);
  mesh.elements[8 + 2] = mesh.elements[8 + 0];
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "element 1 repeats node");
  mesh = make_rectangle(1, 1, 2, 1, ElementType::quad8);
  mesh.elements[8 + 5] = mesh.num_nodes();
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "element 1 local node 5 refers to node");
  mesh.elements[8 + 5] = -1;
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "element 1 local node 5 refers to node -1");
}

TEST(Validation, NonFiniteAndUnusedNodesAndShapes) {
  Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::tri6);
  mesh.positions[3 * 4 + 2] = NAN;
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "node 4 has a non-finite coordinate");
  mesh = make_rectangle(1, 1, 1, 1, ElementType::tri6);
  mesh.positions.insert(mesh.positions.end(), {5, 5, 5});
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "node 9 is used by no element");
  mesh = make_rectangle(1, 1, 1, 1, ElementType::tri6);
  mesh.elements.pop_back();
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "6 node indices per element");
  mesh.elements.clear();
  mesh.positions.clear();
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "no elements");
}

TEST(Validation, FlippedElementIsCaughtThroughTopology) {
  Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::tri6);
  int* n = mesh.elements.data() + 6 * 3;
  std::swap(n[1], n[2]);
  std::swap(n[3], n[5]);
  EXPECT_MESSAGE_CONTAINS(validation_message(mesh), "inconsistent orientation");
}

TEST(Validation, AreaAndPerimeterOfCurvedElements) {
  // One quad8 spanning a quarter of a cylinder is the extrusion of the quadratic curve c(t)
  // through the arc's end and mid points (quad8 reproduces it exactly). Reference: its
  // length by composite Simpson with 20000 intervals; area = L x length, perimeter =
  // 2 L + 2 length. The element's rules (3x3 / 5-point Gauss on a non-polynomial
  // integrand) must agree to 5e-4 (measured 2.3e-4) / 1e-6; the exact arc R pi / 2
  // differs by 0.56%.
  const double R = 2, L = 3;
  const Mesh mesh = make_cylinder(R, L, 0, 90, 1, 1, ElementType::quad8);
  const double s45 = std::sqrt(0.5);
  auto speed = [&](double t) {  // |c'(t)| for c through (0,R), (R s45, R s45), (R,0) at t = -1, 0, 1
    const double dx = R * (t + 0.5) - 2 * t * R * s45, dz = R * (t - 0.5) - 2 * t * R * s45;
    return std::hypot(dx, dz);
  };
  const int intervals = 20000;
  double length = 0;
  for (int i = 0; i < intervals; ++i) {
    const double a = -1 + 2.0 * i / intervals, b = a + 2.0 / intervals;
    length += (b - a) / 6 * (speed(a) + 4 * speed(0.5 * (a + b)) + speed(b));
  }
  EXPECT_NEAR(length, R * M_PI / 2, 0.01 * R * M_PI / 2);
  EXPECT_NEAR(element_area(mesh, 0), L * length, 5e-4 * L * length);
  EXPECT_NEAR(element_perimeter(mesh, 0), 2 * L + 2 * length, 1e-6 * (2 * L + 2 * length));
  // Straight-sided elements are exact: unit right tri6 has area 1/2, perimeter 2 + sqrt(2).
  Mesh tri;
  tri.type = ElementType::tri6;
  tri.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, 0, 0, 0.5, 0.5, 0, 0, 0.5, 0};
  tri.elements = {0, 1, 2, 3, 4, 5};
  EXPECT_NEAR(element_area(tri, 0), 0.5, 1e-15);
  EXPECT_NEAR(element_perimeter(tri, 0), 2 + std::sqrt(2.0), 1e-14);
  // A parabolic edge: midside 3 moved to (0.5, -0.25): edge y = -(1 - (2x-1)^2)/4... length of
  // y = x^2 - x on [0,1] is (sqrt(2) + asinh(1))/2; area grows by 2/3 * 1 * 0.25.
  tri.positions[3 * 3 + 1] = -0.25;
  EXPECT_NEAR(element_area(tri, 0), 0.5 + 1.0 / 6, 1e-14);
  const double parabola = 0.5 * (std::sqrt(2.0) + std::asinh(1.0));
  EXPECT_NEAR(element_perimeter(tri, 0), 1 + std::sqrt(2.0) + parabola, 2e-4);
  EXPECT_THROW(element_area(tri, 1), MeshError);
}

// Two unit squares side by side whose shared side repeats its nodes instead of sharing
// them (an OBJ seam written twice): valid, separate pieces, so only a caution.
TEST(Validation, UnweldedSeamsAreCautioned) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh left = make_rectangle(1, 1, 1, 1, type);
    Mesh both = left;
    for (int n = 0; n < left.num_nodes(); ++n)
      both.positions.insert(both.positions.end(), {left.node(n)[0] + 1, left.node(n)[1], left.node(n)[2]});
    for (int index : left.elements) both.elements.push_back(index + left.num_nodes());
    EXPECT_EQ(validation_message(both), "");  // valid
    const std::string caution = unwelded_seam_caution(both);
    EXPECT_MESSAGE_CONTAINS(caution, "3 boundary nodes lie on other boundary nodes without being joined to them");
    EXPECT_EQ(unwelded_seam_caution(make_rectangle(2, 1, 2, 1, type)), "");  // the same squares, welded
  }
}

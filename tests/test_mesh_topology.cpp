// Edge topology: counts against Euler's formula, the plus/minus conventions, and the
// errors for flipped elements, non-manifold edges and disagreeing midside nodes.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <utility>

#include "dgtex/mesh_generators.h"
#include "dgtex/topology.h"

using namespace dgtex;

namespace {

int corner_node_count(const Mesh& mesh) {
  std::set<int> corners;
  const int c = kernels::corners_per_element(mesh.type);
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < c; ++k) corners.insert(mesh.element_nodes(e)[k]);
  return static_cast<int>(corners.size());
}

int euler_characteristic(const Mesh& mesh, const Topology& t) {
  return corner_node_count(mesh) - static_cast<int>(t.interior_edges.size() + t.boundary_edges.size()) +
         mesh.num_elements();
}

// Reverses element e's orientation: corners 0, 3, 2, 1 (quad8) / 0, 2, 1 (tri6) with the
// matching midside nodes.
void flip_element(Mesh& mesh, int e) {
  int* n = mesh.elements.data() + static_cast<size_t>(e) * mesh.nodes_per_element();
  if (mesh.type == ElementType::quad8) {
    const int f[8] = {n[0], n[3], n[2], n[1], n[7], n[6], n[5], n[4]};
    std::copy(f, f + 8, n);
  } else {
    const int f[6] = {n[0], n[2], n[1], n[5], n[4], n[3]};
    std::copy(f, f + 6, n);
  }
}

std::string message_of(const Mesh& mesh, std::vector<int>* elements = nullptr) {
  try {
    build_topology(mesh);
  } catch (const MeshError& error) {
    if (elements) *elements = error.elements();
    return error.what();
  }
  return "";
}

}  // namespace

class TopologyTest : public ::testing::TestWithParam<ElementType> {};
INSTANTIATE_TEST_SUITE_P(ElementTypes, TopologyTest, ::testing::Values(ElementType::quad8, ElementType::tri6),
                         [](const auto& info) { return info.param == ElementType::quad8 ? "quad8" : "tri6"; });

TEST_P(TopologyTest, RectangleGridCounts) {
  const ElementType type = GetParam();
  const int nx = 4, ny = 3;
  const Mesh mesh = make_rectangle(1.0, 1.0, nx, ny, type);
  const Topology t = build_topology(mesh);
  const int grid_interior = nx * (ny - 1) + ny * (nx - 1);
  const int diagonals = type == ElementType::tri6 ? nx * ny : 0;
  EXPECT_EQ(static_cast<int>(t.interior_edges.size()), grid_interior + diagonals);
  EXPECT_EQ(static_cast<int>(t.boundary_edges.size()), 2 * (nx + ny));
  EXPECT_EQ(euler_characteristic(mesh, t), 1);  // a disk
}

TEST_P(TopologyTest, ClosedSurfacesAreAnnuli) {
  const ElementType type = GetParam();
  const Mesh cylinder = make_cylinder(1.0, 2.0, 0, 360, 5, 2, type);
  const Mesh hemisphere = make_hemisphere(1.0, 10, 3, 7, type);
  const Topology tc = build_topology(cylinder), th = build_topology(hemisphere);
  EXPECT_EQ(euler_characteristic(cylinder, tc), 0);
  EXPECT_EQ(euler_characteristic(hemisphere, th), 0);
  EXPECT_EQ(static_cast<int>(tc.boundary_edges.size()), 2 * 5);
  EXPECT_EQ(static_cast<int>(th.boundary_edges.size()), 2 * 7);
  // Every local edge of every element appears exactly once (as plus or minus side).
  const int corners = kernels::corners_per_element(type);
  EXPECT_EQ(2 * tc.interior_edges.size() + tc.boundary_edges.size(),
            static_cast<size_t>(cylinder.num_elements() * corners));
}

TEST_P(TopologyTest, PlusMinusConventions) {
  const ElementType type = GetParam();
  const Mesh mesh = make_cylinder(1.0, 1.0, 0, 360, 4, 3, type);
  const Topology t = build_topology(mesh);
  std::set<std::pair<int, int>> seen;
  auto check_side = [&](int element, int local_edge, const int nodes[3], bool reversed) {
    int local[3];
    kernels::local_edge_nodes(type, local_edge, local);
    const int* en = mesh.element_nodes(element);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(en[local[i]], nodes[reversed ? 2 - i : i]);
    EXPECT_TRUE(seen.insert({element, local_edge}).second) << "element " << element << " edge " << local_edge;
  };
  for (const MeshEdge& e : t.interior_edges) {
    check_side(e.plus_element, e.plus_local_edge, e.nodes, false);
    check_side(e.minus_element, e.minus_local_edge, e.nodes, true);
    EXPECT_LT(e.plus_element, e.minus_element);
  }
  for (const MeshEdge& e : t.boundary_edges) {
    check_side(e.plus_element, e.plus_local_edge, e.nodes, false);
    EXPECT_EQ(e.minus_element, -1);
    EXPECT_EQ(e.minus_local_edge, -1);
  }
  EXPECT_EQ(seen.size(), static_cast<size_t>(mesh.num_elements() * kernels::corners_per_element(type)));
  // Ordered by (plus element, plus local edge).
  for (size_t i = 1; i < t.interior_edges.size(); ++i)
    EXPECT_LT(std::make_pair(t.interior_edges[i - 1].plus_element, t.interior_edges[i - 1].plus_local_edge),
              std::make_pair(t.interior_edges[i].plus_element, t.interior_edges[i].plus_local_edge));
}

// On a flat mesh with normal +z the plus element lies left of (start -> end).
TEST_P(TopologyTest, PlusElementLiesOnTheLeft) {
  const ElementType type = GetParam();
  const Mesh mesh = make_rectangle(2.0, 1.0, 3, 2, type);
  const Topology t = build_topology(mesh);
  auto centroid = [&](int e, double c[2]) {
    c[0] = c[1] = 0;
    for (int a = 0; a < mesh.nodes_per_element(); ++a)
      c[0] += mesh.node(mesh.element_nodes(e)[a])[0] / mesh.nodes_per_element(),
          c[1] += mesh.node(mesh.element_nodes(e)[a])[1] / mesh.nodes_per_element();
  };
  auto side = [&](const MeshEdge& edge, int e) {
    const double* a = mesh.node(edge.nodes[0]);
    const double* b = mesh.node(edge.nodes[2]);
    double c[2];
    centroid(e, c);
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);  // > 0: left
  };
  for (const MeshEdge& edge : t.interior_edges) {
    EXPECT_GT(side(edge, edge.plus_element), 0);
    EXPECT_LT(side(edge, edge.minus_element), 0);
  }
  for (const MeshEdge& edge : t.boundary_edges) EXPECT_GT(side(edge, edge.plus_element), 0);
}

TEST_P(TopologyTest, FlippedElementIsReported) {
  const ElementType type = GetParam();
  Mesh mesh = make_rectangle(1.0, 1.0, 3, 3, type);
  const int flipped = type == ElementType::quad8 ? 4 : 9;  // an element with interior edges
  flip_element(mesh, flipped);
  std::vector<int> involved;
  const std::string message = message_of(mesh, &involved);
  EXPECT_NE(message.find("inconsistent orientation"), std::string::npos) << message;
  EXPECT_NE(message.find("element " + std::to_string(flipped)), std::string::npos) << message;
  EXPECT_NE(std::find(involved.begin(), involved.end(), flipped), involved.end());
}

TEST(TopologyErrors, NonManifoldEdge) {
  // Three tri6 fins around the edge between nodes 0 and 1.
  Mesh mesh;
  mesh.type = ElementType::tri6;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0.5, 0.0, 0.0,  // corners 0, 1 and their midside node 2
                    0.5, 1, 0, 0.5, -1, 0, 0.5, 0, 1};
  auto mid = [&](int a, int b) {
    for (int d = 0; d < 3; ++d) mesh.positions.push_back(0.5 * (mesh.positions[3 * a + d] + mesh.positions[3 * b + d]));
    return mesh.num_nodes() - 1;
  };
  const int apex[3] = {3, 4, 5};
  for (int f = 0; f < 3; ++f) {
    const int m1 = mid(1, apex[f]), m2 = mid(apex[f], 0);
    if (f == 1)
      mesh.elements.insert(mesh.elements.end(), {1, 0, apex[f], 2, m2, m1});
    else
      mesh.elements.insert(mesh.elements.end(), {0, 1, apex[f], 2, m1, m2});
  }
  std::vector<int> involved;
  const std::string message = message_of(mesh, &involved);
  EXPECT_NE(message.find("non-manifold"), std::string::npos) << message;
  EXPECT_NE(message.find("nodes 0 and 1"), std::string::npos) << message;
  EXPECT_EQ(involved, (std::vector<int>{0, 1, 2}));
}

TEST(TopologyErrors, MidsideNodesDisagree) {
  Mesh mesh = make_rectangle(2.0, 1.0, 2, 1, ElementType::quad8);
  // Give element 1's left edge (local edge 3) its own midside node.
  const int old_mid = mesh.element_nodes(1)[7];
  mesh.positions.insert(mesh.positions.end(), mesh.node(old_mid), mesh.node(old_mid) + 3);
  mesh.elements[8 + 7] = mesh.num_nodes() - 1;
  std::vector<int> involved;
  const std::string message = message_of(mesh, &involved);
  EXPECT_NE(message.find("midside nodes disagree"), std::string::npos) << message;
  EXPECT_EQ(involved, (std::vector<int>{0, 1}));
}

TEST(TopologyErrors, DegenerateEdge) {
  Mesh mesh = make_rectangle(1.0, 1.0, 1, 1, ElementType::tri6);
  mesh.elements[1] = mesh.elements[0];
  const std::string message = message_of(mesh);
  EXPECT_NE(message.find("degenerate edge"), std::string::npos) << message;
}

// Mesh generators: node/element counts, closed seams, areas against the analytic surface
// areas (with their convergence rate under refinement) and the documented normal directions.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>

#include "dgtex/cut_path.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/mesh_validation.h"
#include "dgtex/topology.h"

using namespace dgtex;

namespace {

double total_area(const Mesh& mesh) {
  double area = 0;
  for (int e = 0; e < mesh.num_elements(); ++e) area += element_area(mesh, e);
  return area;
}

// Position and normal dx/dxi1 x dx/dxi2 of element e at (r, s).
void point_and_normal(const Mesh& mesh, int e, double r, double s, double x[3], double n[3]) {
  kernels::ShapeValues sv;
  kernels::evaluate_shape(mesh.type, r, s, sv);
  double t1[3] = {0, 0, 0}, t2[3] = {0, 0, 0};
  for (int d = 0; d < 3; ++d) x[d] = 0;
  for (int a = 0; a < sv.count; ++a) {
    const double* p = mesh.node(mesh.element_nodes(e)[a]);
    for (int d = 0; d < 3; ++d) x[d] += sv.N[a] * p[d], t1[d] += sv.dN[a][0] * p[d], t2[d] += sv.dN[a][1] * p[d];
  }
  n[0] = t1[1] * t2[2] - t1[2] * t2[1];
  n[1] = t1[2] * t2[0] - t1[0] * t2[2];
  n[2] = t1[0] * t2[1] - t1[1] * t2[0];
}

// Every element's normal at every quadrature point makes an angle below 30 degrees with the
// expected direction expected(x) (unit), i.e. points the documented way.
void expect_normals(const Mesh& mesh, const std::function<void(const double*, double*)>& expected) {
  const kernels::QuadratureRule rule = kernels::element_quadrature(mesh.type);
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int q = 0; q < rule.count; ++q) {
      double x[3], n[3], m[3];
      point_and_normal(mesh, e, rule.xi1[q], rule.xi2[q], x, n);
      expected(x, m);
      const double cosine = (n[0] * m[0] + n[1] * m[1] + n[2] * m[2]) / std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      ASSERT_GT(cosine, std::cos(M_PI / 6)) << "element " << e << " quadrature point " << q;
    }
}

// All nodes (midsides included) lie on the exact surface: |distance(x)| < 1e-14 * scale.
void expect_nodes_on_surface(const Mesh& mesh, const std::function<double(const double*)>& distance, double scale) {
  for (int n = 0; n < mesh.num_nodes(); ++n) ASSERT_NEAR(distance(mesh.node(n)), 0.0, 1e-14 * scale) << "node " << n;
}

}  // namespace

class Generators : public ::testing::TestWithParam<ElementType> {};
INSTANTIATE_TEST_SUITE_P(ElementTypes, Generators, ::testing::Values(ElementType::quad8, ElementType::tri6),
                         [](const auto& info) { return info.param == ElementType::quad8 ? "quad8" : "tri6"; });

TEST_P(Generators, RectangleCountsAreaAndNormals) {
  const ElementType type = GetParam();
  const int nx = 5, ny = 3;
  const Mesh mesh = make_rectangle(2.0, 1.5, nx, ny, type);
  EXPECT_EQ(mesh.type, type);
  if (type == ElementType::quad8) {
    EXPECT_EQ(mesh.num_elements(), nx * ny);
    EXPECT_EQ(mesh.num_nodes(), (2 * nx + 1) * (2 * ny + 1) - nx * ny);
  } else {
    EXPECT_EQ(mesh.num_elements(), 2 * nx * ny);
    EXPECT_EQ(mesh.num_nodes(), (2 * nx + 1) * (2 * ny + 1));
  }
  validate_mesh(mesh);
  EXPECT_NEAR(total_area(mesh), 3.0, 1e-13);  // flat affine elements: quadrature is exact
  for (int e = 0; e < mesh.num_elements(); ++e)
    EXPECT_NEAR(element_area(mesh, e), 3.0 / mesh.num_elements(), 1e-14);
  // Perimeter of one quad8 cell (0.4 x 0.5) / of one tri6 (legs 0.4, 0.5 and the diagonal).
  const double expected_perimeter = type == ElementType::quad8 ? 1.8 : 0.9 + std::hypot(0.4, 0.5);
  EXPECT_NEAR(element_perimeter(mesh, 0), expected_perimeter, 1e-14);
  double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
  for (int n = 0; n < mesh.num_nodes(); ++n)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], mesh.node(n)[d]), hi[d] = std::max(hi[d], mesh.node(n)[d]);
  EXPECT_EQ(lo[0], 0.0);
  EXPECT_EQ(hi[0], 2.0);
  EXPECT_EQ(lo[1], 0.0);
  EXPECT_EQ(hi[1], 1.5);
  EXPECT_EQ(lo[2], 0.0);
  EXPECT_EQ(hi[2], 0.0);
  expect_normals(mesh, [](const double*, double* m) { m[0] = 0, m[1] = 0, m[2] = 1; });
}

// The square split: the same nodes and cells as the sheared one, each triangle's first vertex
// at a right angle of the cell with its legs along the cell sides (so its texels are square on
// a square cell), the diagonal the hypotenuse (local edge 1) of both, normals +z. On a closed
// cylinder and the hemisphere too, every mesh stays valid with outward normals.
TEST(Generators, SquareSplitTrianglesStartAtACellCorner) {
  const int nx = 3, ny = 2;
  const Mesh sheared = make_rectangle(1.5, 1.0, nx, ny, ElementType::tri6);
  const Mesh square = make_rectangle(1.5, 1.0, nx, ny, ElementType::tri6, TriangleSplit::square);
  validate_mesh(square);
  EXPECT_EQ(square.positions, sheared.positions);
  ASSERT_EQ(square.num_elements(), sheared.num_elements());
  for (int e = 0; e < square.num_elements(); ++e) {
    const int* a = square.element_nodes(e);
    const int* b = sheared.element_nodes(e);
    EXPECT_EQ(std::multiset<int>(a, a + 6), std::multiset<int>(b, b + 6)) << "element " << e;
    const double *p0 = square.node(a[0]), *p1 = square.node(a[1]), *p2 = square.node(a[2]);
    const double u[2] = {p1[0] - p0[0], p1[1] - p0[1]}, v[2] = {p2[0] - p0[0], p2[1] - p0[1]};
    EXPECT_EQ(u[0] * v[0] + u[1] * v[1], 0.0) << "element " << e << ": a right angle at vertex 0";
    EXPECT_TRUE((u[0] == 0) != (u[1] == 0)) << "element " << e << ": legs along the cell sides";
  }
  const Topology topology = build_topology(square);
  const ElementAdjacency adjacency(square, topology);
  for (int e = 0; e < square.num_elements(); e += 2)
    EXPECT_EQ(adjacency.neighbour(e, 1), (std::array<int, 2>{e + 1, 1})) << "the diagonal: both hypotenuses";
  expect_normals(square, [](const double*, double* m) { m[0] = 0, m[1] = 0, m[2] = 1; });
  const Mesh ring = make_cylinder(1.0, 2.0, 0, 360, 6, 2, ElementType::tri6, TriangleSplit::square);
  validate_mesh(ring);
  expect_normals(ring, [](const double* x, double* m) {
    const double r = std::hypot(x[0], x[2]);
    m[0] = x[0] / r, m[1] = 0, m[2] = x[2] / r;
  });
  const Mesh cap = make_hemisphere(1.0, 10, 4, 8, ElementType::tri6, TriangleSplit::square);
  validate_mesh(cap);
  expect_normals(cap, [](const double* x, double* m) {
    const double r = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int d = 0; d < 3; ++d) m[d] = x[d] / r;
  });
}

TEST_P(Generators, CylinderOpenAndClosed) {
  const ElementType type = GetParam();
  const double R = 0.7, L = 2.0;
  const int na = 6, nl = 3;
  const Mesh open = make_cylinder(R, L, -45, 90, na, nl, type);
  const Mesh closed = make_cylinder(R, L, 0, 360, na, nl, type);
  validate_mesh(open);
  validate_mesh(closed);
  const int grid = type == ElementType::quad8 ? (2 * na + 1) * (2 * nl + 1) - na * nl : (2 * na + 1) * (2 * nl + 1);
  const int per_cell = type == ElementType::quad8 ? 1 : 2;
  EXPECT_EQ(open.num_nodes(), grid);
  EXPECT_EQ(open.num_elements(), per_cell * na * nl);
  // Closing the seam shares one column of 2nl+1 nodes.
  EXPECT_EQ(closed.num_nodes(), grid - (2 * nl + 1));
  EXPECT_EQ(closed.num_elements(), per_cell * na * nl);
  // The seam is interior: only the two end circles (2 na edges) remain on the boundary.
  EXPECT_EQ(static_cast<int>(build_topology(closed).boundary_edges.size()), 2 * na);
  EXPECT_EQ(static_cast<int>(build_topology(open).boundary_edges.size()), 2 * na + 2 * nl);

  for (const Mesh* m : {&open, &closed}) {
    expect_nodes_on_surface(*m, [&](const double* x) { return std::hypot(x[0], x[2]) - R; }, R);
    expect_normals(*m, [](const double* x, double* n) {
      const double r = std::hypot(x[0], x[2]);
      n[0] = x[0] / r, n[1] = 0, n[2] = x[2] / r;
    });
  }
  // Angle convention: t = 0 is the top (z = R), t = 90 is +x; y runs over [0, L].
  bool top = false, plus_x = false;
  for (int n = 0; n < open.num_nodes(); ++n) {
    const double* x = open.node(n);
    top |= x[0] == 0.0 && x[2] == R;
    plus_x |= x[0] == R && x[2] == 0.0;
    EXPECT_GE(x[1], 0.0);
    EXPECT_LE(x[1], L);
    EXPECT_LE(x[0], R);
    EXPECT_GE(x[0], R * std::sin(-M_PI / 4) - 1e-15);
  }
  EXPECT_TRUE(top);
  EXPECT_TRUE(plus_x);
}

TEST_P(Generators, HemisphereClosesInAzimuth) {
  const ElementType type = GetParam();
  const double R = 1.3, hole = 20;
  const int np = 4, nz = 8;
  const Mesh mesh = make_hemisphere(R, hole, np, nz, type);
  validate_mesh(mesh);
  const int per_cell = type == ElementType::quad8 ? 1 : 2;
  const int rows = 2 * nz;  // half-step rows in azimuth (periodic)
  const int expected_nodes = type == ElementType::quad8 ? (2 * np + 1) * rows - np * nz : (2 * np + 1) * rows;
  EXPECT_EQ(mesh.num_nodes(), expected_nodes);
  EXPECT_EQ(mesh.num_elements(), per_cell * np * nz);
  // Boundary: hole rim and equator, nz edges each; no seam.
  const Topology topology = build_topology(mesh);
  EXPECT_EQ(static_cast<int>(topology.boundary_edges.size()), 2 * nz);
  double zmin = 1e9, zmax = -1e9;
  for (int n = 0; n < mesh.num_nodes(); ++n) zmin = std::min(zmin, mesh.node(n)[2]), zmax = std::max(zmax, mesh.node(n)[2]);
  EXPECT_EQ(zmin, 0.0);  // the equator lies exactly on z = 0
  EXPECT_NEAR(zmax, R * std::cos(hole * M_PI / 180), 1e-15);
  expect_nodes_on_surface(mesh, [&](const double* x) { return std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - R; }, R);
  expect_normals(mesh, [](const double* x, double* n) {
    const double r = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int d = 0; d < 3; ++d) n[d] = x[d] / r;
  });
}

// Relative area error e(n) of a curved generator at n and 2n divisions: it must fall below a
// stated bound and converge at least at rate 3.5 (quadratic elements with nodes on the
// surface: measured rate ~4).
TEST_P(Generators, CylinderAreaConverges) {
  const ElementType type = GetParam();
  const double R = 0.8, L = 1.7, span = 150;
  const double exact = R * L * span * M_PI / 180;  // 2 pi R L * (150 / 360)
  double previous = 0;
  for (int n : {4, 8, 16}) {
    const double error = std::fabs(total_area(make_cylinder(R, L, -30, 120, n, 2, type)) - exact) / exact;
    EXPECT_LT(error, 4e-4 * std::pow(4.0 / n, 4)) << "n = " << n;
    if (previous > 0) {
      EXPECT_GT(std::log2(previous / error), 3.5) << "n = " << n;
    }
    std::printf("n = %d: relative area error %.3e\n", n, error);
    previous = error;
  }
  const double full = 2 * M_PI * R * L;
  EXPECT_NEAR(total_area(make_cylinder(R, L, 0, 360, 32, 2, type)), full, 1e-5 * full);
}

TEST_P(Generators, HemisphereAreaConverges) {
  const ElementType type = GetParam();
  const double R = 1.1, hole = 15;
  const double exact = 2 * M_PI * R * R * std::cos(hole * M_PI / 180);
  double previous = 0;
  for (int n : {4, 8, 16}) {
    const double error = std::fabs(total_area(make_hemisphere(R, hole, n, 2 * n, type)) - exact) / exact;
    EXPECT_LT(error, 2.5e-3 * std::pow(4.0 / n, 4)) << "n = " << n;
    if (previous > 0) {
      EXPECT_GT(std::log2(previous / error), 3.5) << "n = " << n;
    }
    std::printf("n = %d: relative area error %.3e\n", n, error);
    previous = error;
  }
}

TEST(GeneratorErrors, RejectInvalidArguments) {
  EXPECT_THROW(make_rectangle(0, 1, 2, 2, ElementType::quad8), MeshError);
  EXPECT_THROW(make_rectangle(1, 1, 0, 2, ElementType::quad8), MeshError);
  EXPECT_THROW(make_rectangle(1, NAN, 2, 2, ElementType::tri6), MeshError);
  EXPECT_THROW(make_cylinder(1, 1, 0, 400, 8, 2, ElementType::quad8), MeshError);
  EXPECT_THROW(make_cylinder(1, 1, 30, 30, 8, 2, ElementType::quad8), MeshError);
  EXPECT_THROW(make_cylinder(1, 1, 0, 360, 2, 2, ElementType::quad8), MeshError);
  EXPECT_THROW(make_hemisphere(1, 10, 2, 2, ElementType::tri6), MeshError);
  EXPECT_NO_THROW(make_cylinder(1, 1, 0, 180, 1, 1, ElementType::quad8));  // open: one element is fine
  EXPECT_THROW(make_hemisphere(1, 0, 4, 8, ElementType::quad8), MeshError);
  EXPECT_THROW(make_hemisphere(1, 90, 4, 8, ElementType::quad8), MeshError);
  EXPECT_THROW(make_hemisphere(-1, 10, 4, 8, ElementType::quad8), MeshError);
  try {
    make_hemisphere(1, 95, 4, 8, ElementType::tri6);
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("hole_deg"), std::string::npos) << e.what();
  }
  // Divisions whose indices would not fit an int overflowed (undefined behaviour) before the
  // generator could fail on memory (helper audit, session 71).
  for (auto generate : {+[] { make_rectangle(1, 1, 2147483647, 1, ElementType::quad8); },
                        +[] { make_cylinder(1, 1, 0, 360, 1 << 30, 1, ElementType::quad8); },
                        +[] { make_hemisphere(1, 10, 1, 2147483647, ElementType::tri6); },
                        +[] { make_rectangle(1, 1, 20000, 20000, ElementType::tri6); }}) {
    try {
      generate();
      ADD_FAILURE() << "generated";
    } catch (const MeshError& e) {
      EXPECT_NE(std::string(e.what()).find("divisions give more nodes or element indices than an int counts"),
                std::string::npos)
          << e.what();
    }
  }
}

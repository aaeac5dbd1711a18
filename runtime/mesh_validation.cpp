#include "dgtex/mesh_validation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "dgtex/topology.h"

namespace dgtex {
namespace {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

double norm(const Vec3& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// Tangents dx/dxi1, dx/dxi2 of element e at (xi1, xi2).
void tangents(const Mesh& mesh, int e, double xi1, double xi2, Vec3& t1, Vec3& t2) {
  kernels::ShapeValues s;
  kernels::evaluate_shape(mesh.type, xi1, xi2, s);
  const int* en = mesh.element_nodes(e);
  t1 = t2 = Vec3{};
  for (int a = 0; a < s.count; ++a) {
    const double* p = mesh.node(en[a]);
    t1.x += s.dN[a][0] * p[0], t1.y += s.dN[a][0] * p[1], t1.z += s.dN[a][0] * p[2];
    t2.x += s.dN[a][1] * p[0], t2.y += s.dN[a][1] * p[1], t2.z += s.dN[a][1] * p[2];
  }
}

double area_jacobian(const Mesh& mesh, int e, double xi1, double xi2) {
  Vec3 t1, t2;
  tangents(mesh, e, xi1, xi2, t1, t2);
  return norm(cross(t1, t2));
}

constexpr double kDegreesPerRadian = 180 / 3.14159265358979323846;

// Unit normal of element e at the midpoint of its local edge k.
Vec3 edge_midpoint_normal(const Mesh& mesh, int e, int k) {
  double xi[2], dxi[2];
  kernels::local_edge_point(mesh.type, k, 0.0, xi, dxi);
  Vec3 t1, t2;
  tangents(mesh, e, xi[0], xi[1], t1, t2);
  const Vec3 n = cross(t1, t2);
  const double length = norm(n);
  return {n.x / length, n.y / length, n.z / length};
}

double element_diameter(const Mesh& mesh, int e) {
  const int* en = mesh.element_nodes(e);
  const int n = mesh.nodes_per_element();
  double d2 = 0;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      const double* p = mesh.node(en[a]);
      const double* q = mesh.node(en[b]);
      const double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
      d2 = std::max(d2, dx * dx + dy * dy + dz * dz);
    }
  return std::sqrt(d2);
}

void check_element_index(const Mesh& mesh, int e, const char* function) {
  if (e < 0 || e >= mesh.num_elements())
    throw MeshError(std::string(function) + ": element index " + std::to_string(e) + " out of range [0, " +
                    std::to_string(mesh.num_elements()) + ")");
}

}  // namespace

void validate_mesh(const Mesh& mesh) {
  if (mesh.type != ElementType::quad8 && mesh.type != ElementType::tri6)
    throw MeshError("mesh element type must be quad8 or tri6, got " + std::to_string(static_cast<int>(mesh.type)));
  if (mesh.positions.size() % 3 != 0)
    throw MeshError("mesh positions must hold 3 coordinates per node, got " + std::to_string(mesh.positions.size()) +
                    " values");
  const int npe = mesh.nodes_per_element();
  if (mesh.elements.size() % npe != 0)
    throw MeshError("mesh elements must hold " + std::to_string(npe) + " node indices per element, got " +
                    std::to_string(mesh.elements.size()) + " values");
  if (mesh.num_elements() == 0) throw MeshError("mesh has no elements");

  const int nodes = mesh.num_nodes();
  for (int n = 0; n < nodes; ++n) {
    const double* p = mesh.node(n);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw MeshError("node " + std::to_string(n) + " has a non-finite coordinate (" + mesh_number(p[0]) + ", " +
                      mesh_number(p[1]) + ", " + mesh_number(p[2]) + ")");
  }

  std::vector<char> used(nodes, 0);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const int* en = mesh.element_nodes(e);
    for (int a = 0; a < npe; ++a) {
      if (en[a] < 0 || en[a] >= nodes)
        throw MeshError("element " + std::to_string(e) + " local node " + std::to_string(a) + " refers to node " +
                            std::to_string(en[a]) + ", outside [0, " + std::to_string(nodes) + ")",
                        {e});
      for (int b = 0; b < a; ++b)
        if (en[a] == en[b])
          throw MeshError("element " + std::to_string(e) + " repeats node " + std::to_string(en[a]) +
                              " (local nodes " + std::to_string(b) + " and " + std::to_string(a) + ")",
                          {e});
      used[en[a]] = 1;
    }
  }
  for (int n = 0; n < nodes; ++n)
    if (!used[n])
      throw MeshError("node " + std::to_string(n) +
                      " is used by no element; its displacement would be undetermined (remove it)");

  const kernels::QuadratureRule rule = kernels::element_quadrature(mesh.type);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const double h = element_diameter(mesh, e);
    const double threshold = 1e-10 * h * h;
    double area = 0;
    for (int q = 0; q < rule.count; ++q) {
      const double j = area_jacobian(mesh, e, rule.xi1[q], rule.xi2[q]);
      if (!(j > threshold))
        throw MeshError("element " + std::to_string(e) + " is degenerate: area Jacobian " + mesh_number(j) +
                            " at quadrature point " + std::to_string(q) + " (xi = " + mesh_number(rule.xi1[q]) +
                            ", " + mesh_number(rule.xi2[q]) + ") is below 1e-10 x diameter^2 = " +
                            mesh_number(threshold) + " (zero area, collapsed or collinear nodes)",
                        {e});
      area += rule.weight[q] * j;
    }
    // The corners too, signed against the normal at the centre: a reflex (concave) corner
    // or two corners at one point (a zero-length edge) kept every quadrature point's
    // Jacobian positive, and the factorisation failed as "penalty too low?".
    const double centre = mesh.type == ElementType::quad8 ? 0.0 : 1.0 / 3;  // both coordinates
    Vec3 t1, t2;
    tangents(mesh, e, centre, centre, t1, t2);
    const Vec3 normal = cross(t1, t2);
    const double normal_length = norm(normal);
    for (int a = 0; a < kernels::corners_per_element(mesh.type); ++a) {
      double xi[2];
      kernels::node_parametric_position(mesh.type, a, xi);
      tangents(mesh, e, xi[0], xi[1], t1, t2);
      const Vec3 n = cross(t1, t2);
      const double j = (n.x * normal.x + n.y * normal.y + n.z * normal.z) / normal_length;
      if (!(j > threshold))
        throw MeshError("element " + std::to_string(e) + " is degenerate at its corner " + std::to_string(a) + " (node " +
                            std::to_string(mesh.element_nodes(e)[a]) + "): signed area Jacobian " + mesh_number(j) +
                            " is below 1e-10 x diameter^2 = " + mesh_number(threshold) +
                            " (a reflex corner, or two corners at one point)",
                        {e});
    }
    // Slivers pass the Jacobian test long before their results are sound: a row of quad8
    // (tri6) slivers across a clamped plate gave 0.93 (0.88) of its deflection without the
    // row at diameter^2 / area 1e3-1e4, 0.95 (0.86) at 3e4, and 0.46 (4.7) at 1e5, where
    // the stiffness is round-off (session 68; beyond ~3e5 it is not positive definite).
    if (h * h > kMaxElementAspect * area)
      throw MeshError("element " + std::to_string(e) + " is a sliver: diameter^2 / area = " + mesh_number(h * h / area) +
                          " is above " + mesh_number(kMaxElementAspect) +
                          ", where its stiffness is lost in round-off (remesh it; a square has 2, a right triangle 4)",
                      {e});
  }

  // A face turned back onto its neighbour (a 180-degree fold, a face and its reverse
  // copy) is manifold and consistently oriented, but the DG edge terms then tie opposite
  // normals: the corotated step matrix lost definiteness ("penalty too low?") and static
  // runs gave results without meaning (OBJ fuzzing, session 68).
  const Topology topology = build_topology(mesh);
  for (const MeshEdge& edge : topology.interior_edges) {
    const Vec3 plus = edge_midpoint_normal(mesh, edge.plus_element, edge.plus_local_edge);
    const Vec3 minus = edge_midpoint_normal(mesh, edge.minus_element, edge.minus_local_edge);
    const double cosine = plus.x * minus.x + plus.y * minus.y + plus.z * minus.z;
    if (cosine < kMinNeighbourNormalCosine)
      throw MeshError("elements " + std::to_string(edge.plus_element) + " and " + std::to_string(edge.minus_element) +
                          " fold back onto each other along their shared edge (nodes " + std::to_string(edge.nodes[0]) +
                          "-" + std::to_string(edge.nodes[2]) + "): their normals there are " +
                          std::to_string(std::lround(std::acos(std::max(-1.0, cosine)) * kDegreesPerRadian)) +
                          " degrees apart, more than a shell can turn between neighbours (at most " +
                          std::to_string(std::lround(std::acos(kMinNeighbourNormalCosine) * kDegreesPerRadian)) + ")",
                      {edge.plus_element, edge.minus_element});
  }
}

std::string unwelded_seam_caution(const Mesh& mesh) {
  const Topology topology = build_topology(mesh);
  std::vector<int> boundary;
  for (const MeshEdge& edge : topology.boundary_edges) boundary.insert(boundary.end(), edge.nodes, edge.nodes + 3);
  std::sort(boundary.begin(), boundary.end());
  boundary.erase(std::unique(boundary.begin(), boundary.end()), boundary.end());
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double* p = mesh.node(n);
    lo = {std::min(lo.x, p[0]), std::min(lo.y, p[1]), std::min(lo.z, p[2])};
    hi = {std::max(hi.x, p[0]), std::max(hi.y, p[1]), std::max(hi.z, p[2])};
  }
  const double tolerance = 1e-9 * std::max(norm(Vec3{hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}), 1e-300);
  // Repeated vertices carry the same coordinates: the same cell of a grid at the tolerance.
  std::map<std::array<long long, 3>, int> first_at;
  int coincident = 0, example = -1, example_other = -1;
  for (int n : boundary) {
    const double* p = mesh.node(n);
    const std::array<long long, 3> cell = {std::llround((p[0] - lo.x) / tolerance), std::llround((p[1] - lo.y) / tolerance),
                                           std::llround((p[2] - lo.z) / tolerance)};  // at most 1e9 each
    const auto [it, inserted] = first_at.emplace(cell, n);
    if (inserted) continue;
    ++coincident;
    if (example < 0) example = it->second, example_other = n;
  }
  if (coincident == 0) return "";
  const double* p = mesh.node(example);
  return std::to_string(coincident) + " boundary node" + (coincident == 1 ? "" : "s") +
         " lie on other boundary nodes without being joined to them (node " + std::to_string(example) + " and node " +
         std::to_string(example_other) + " at [" + mesh_number(p[0]) + ", " + mesh_number(p[1]) + ", " +
         mesh_number(p[2]) + "]): the pieces run apart, as if cut there; if they are one sheet, give their faces "
         "shared vertices (an OBJ seam that repeats its vertices)";
}

double element_area(const Mesh& mesh, int e) {
  check_element_index(mesh, e, "element_area");
  const kernels::QuadratureRule rule = kernels::element_quadrature(mesh.type);
  double area = 0;
  for (int q = 0; q < rule.count; ++q) area += rule.weight[q] * area_jacobian(mesh, e, rule.xi1[q], rule.xi2[q]);
  return area;
}

double element_perimeter(const Mesh& mesh, int e) {
  check_element_index(mesh, e, "element_perimeter");
  const kernels::LineRule line = kernels::gauss_legendre(5);
  double length = 0;
  for (int k = 0; k < kernels::corners_per_element(mesh.type); ++k)
    for (int q = 0; q < line.count; ++q) {
      double xi[2], dxi[2];
      kernels::local_edge_point(mesh.type, k, line.t[q], xi, dxi);
      Vec3 t1, t2;
      tangents(mesh, e, xi[0], xi[1], t1, t2);
      const Vec3 dx{t1.x * dxi[0] + t2.x * dxi[1], t1.y * dxi[0] + t2.y * dxi[1], t1.z * dxi[0] + t2.z * dxi[1]};
      length += line.weight[q] * norm(dx);
    }
  return length;
}

}  // namespace dgtex

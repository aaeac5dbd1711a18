// Mesh-dependent scene validation: empty selections, surface points, rigid motions.
#include "dgtex/scene_mesh_checks.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "dgtex/boundary_selection.h"
#include "dgtex/cut_path.h"
#include "dgtex/kernels/flood_fill.h"
#include "dgtex/surface_point.h"
#include "dgtex/scene_io.h"

namespace dgtex {
namespace {

std::string fmt(double x) {
  std::ostringstream out;
  out.precision(6);
  out << x;
  return out.str();
}
std::string fmt(const Vec3& v) { return "[" + fmt(v[0]) + ", " + fmt(v[1]) + ", " + fmt(v[2]) + "]"; }
std::string fmt(const Eigen::Vector3d& v) { return fmt(Vec3{v[0], v[1], v[2]}); }
// A unit direction with round-off (and negative zeros) cleaned away, for messages.
std::string direction_text(const Eigen::Vector3d& v) {
  Eigen::Vector3d d = v.normalized();
  for (int i = 0; i < 3; ++i)
    if (std::abs(d[i]) < 1e-9) d[i] = 0;
  return fmt(d);
}

std::string describe(const BoundarySelect& s) {
  if (s.kind == BoundarySelect::Kind::plane)
    return "{\"plane\": {\"normal\": " + fmt(s.normal) + ", \"offset\": " + fmt(s.offset) + "}, \"tolerance\": " +
           fmt(s.tolerance) + "}";
  return "{\"box\": {\"min\": " + fmt(s.min) + ", \"max\": " + fmt(s.max) + "}, \"tolerance\": " + fmt(s.tolerance) + "}";
}

Eigen::Vector3d node_position(const Mesh& mesh, int n) { return Eigen::Vector3d(mesh.node(n)); }

// Position and (unnormalised) normal of element e at parametric point xi.
void surface_point(const Mesh& mesh, int e, const double xi[2], Eigen::Vector3d& x, Eigen::Vector3d& normal) {
  kernels::ShapeValues shape;
  kernels::evaluate_shape(mesh.type, xi[0], xi[1], shape);
  Eigen::Vector3d a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
  x.setZero();
  const int* nodes = mesh.element_nodes(e);
  for (int a = 0; a < shape.count; ++a) {
    const Eigen::Vector3d p = node_position(mesh, nodes[a]);
    x += shape.N[a] * p;
    a1 += shape.dN[a][0] * p;
    a2 += shape.dN[a][1] * p;
  }
  normal = a1.cross(a2);
}

void check_selections(const Scene& scene, const Mesh& mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY);
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    lo = lo.cwiseMin(node_position(mesh, n));
    hi = hi.cwiseMax(node_position(mesh, n));
  }
  for (size_t i = 0; i < scene.boundary.size(); ++i) {
    const BoundarySelect& s = scene.boundary[i].select;
    if (!select_nodes(mesh, s).empty()) continue;
    throw SceneError(scene.source_name, "boundary[" + std::to_string(i) + "].select", "selects no mesh node", describe(s),
                     "the mesh's nodes span " + fmt(lo) + " to " + fmt(hi) + "; move the plane/box or raise tolerance");
  }
}

void check_surface_points(const Scene& scene, const Mesh& mesh) {
  for (size_t c = 0; c < scene.cuts.size(); ++c) {
    const Cut& cut = scene.cuts[c];
    if (cut.kind != Cut::Kind::surface_points) continue;
    const std::string path = "cuts[" + std::to_string(c) + "].surface_points";
    double total = 0;
    Eigen::Vector3d previous = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < cut.surface_points.size(); ++k) {
      const CutSurfacePoint& sp = cut.surface_points[k];
      const std::string p = path + "[" + std::to_string(k) + "]";
      if (sp.element >= mesh.num_elements())
        throw SceneError(scene.source_name, p + ".element", "no such element", std::to_string(sp.element),
                         "the mesh has elements 0.." + std::to_string(mesh.num_elements() - 1));
      const double a = sp.xi[0], b = sp.xi[1];
      if (!kernels::inside_reference_element(mesh.type, a, b))
        throw SceneError(scene.source_name, p + ".xi", "outside the reference element", "[" + fmt(a) + ", " + fmt(b) + "]",
                         kernels::reference_element_rule(mesh.type));
      Eigen::Vector3d x, normal;
      surface_point(mesh, sp.element, sp.xi.data(), x, normal);
      if (k > 0) total += (x - previous).norm();
      previous = x;
    }
    if (!(total > 0))
      throw SceneError(scene.source_name, path, "zero-length cut on the surface", "all points at " + fmt(previous),
                       "expected points that span a positive length");
  }
}

// Connected parts: nodes linked through shared elements (union-find over element nodes).
std::vector<int> part_of_node(const Mesh& mesh) {
  std::vector<int> parent(mesh.num_nodes());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int n) { return kernels::find_root_halving(parent, n); };
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const int* nodes = mesh.element_nodes(e);
    for (int a = 1; a < mesh.nodes_per_element(); ++a) parent[root(nodes[a])] = root(nodes[0]);
  }
  for (int n = 0; n < mesh.num_nodes(); ++n) parent[n] = root(n);
  return parent;
}

// Static runs need every connected part held against all six rigid motions
// u(x) = t + w x (x - c). Each constraint is a linear condition on (t, w); the part is
// held when those conditions have rank 6. Rotations are scaled by the spread of the part's
// held nodes so the rank test depends neither on the length unit nor on nodes far from the
// supports (the part's bounding box took one node lifted to z = 1e5 on a unit plate as its
// size, and the held nodes' rotation rows fell below the test's tolerance).
void check_rigid_motions(const Scene& scene, const Mesh& mesh) {
  if (scene.analysis.is_dynamic() || mesh.num_elements() == 0) return;
  const std::vector<int> part = part_of_node(mesh);
  std::vector<char> used(mesh.num_nodes(), 0);
  for (int n : mesh.elements) used[n] = 1;
  std::vector<std::vector<int>> selections;
  for (const BoundaryCondition& bc : scene.boundary) selections.push_back(select_nodes(mesh, bc.select));

  // Per part: centroid and RMS radius of its held nodes, and the accumulated normal matrix
  // A^T A of the constraints.
  std::map<int, Eigen::Vector3d> held_sum;
  std::map<int, double> held_count, held_squares;
  for (const std::vector<int>& selected : selections)
    for (int n : selected) {  // zero first: a default Eigen vector is left unset
      held_sum.try_emplace(part[n], Eigen::Vector3d::Zero()).first->second += node_position(mesh, n);
      held_count[part[n]] += 1;
    }
  auto centre = [&](int p) { return Eigen::Vector3d(held_sum[p] / held_count[p]); };
  for (const std::vector<int>& selected : selections)
    for (int n : selected) held_squares[part[n]] += (node_position(mesh, n) - centre(part[n])).squaredNorm();
  std::map<int, Eigen::Matrix<double, 6, 6>> normal_matrix;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (used[n]) normal_matrix[part[n]].setZero();
  auto add_row = [&](int p, const Eigen::Matrix<double, 6, 1>& row) { normal_matrix[p] += row * row.transpose(); };
  // A single held point has no spread: its rotation rows are 0 whatever the scale.
  auto scale = [&](int p) { return std::max(std::sqrt(held_squares[p] / held_count[p]), 1e-300); };

  // Boundary edges (used by one element) keyed by their sorted corner pair.
  std::map<std::pair<int, int>, std::pair<int, int>> edge_owner;  // -> (element, local edge)
  std::map<std::pair<int, int>, int> edge_count;
  const int corners = kernels::corners_per_element(mesh.type);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    for (int k = 0; k < corners; ++k) {
      int local[3];
      kernels::local_edge_nodes(mesh.type, k, local);
      const int* nodes = mesh.element_nodes(e);
      const std::pair<int, int> key = std::minmax(nodes[local[0]], nodes[local[2]]);
      ++edge_count[key];
      edge_owner[key] = {e, k};
    }
  }

  for (size_t b = 0; b < scene.boundary.size(); ++b) {
    const BoundaryCondition& bc = scene.boundary[b];
    const std::vector<int>& selected = selections[b];
    std::vector<char> is_selected(mesh.num_nodes(), 0);
    for (int n : selected) {
      is_selected[n] = 1;
      const int p = part[n];
      const Eigen::Vector3d r = (node_position(mesh, n) - centre(p)) / scale(p);
      for (int c = 0; c < 3; ++c) {
        if (!bc.fixed[c]) continue;
        const Eigen::Vector3d axis = Eigen::Vector3d::Unit(c);
        Eigen::Matrix<double, 6, 1> row;
        row << axis, r.cross(axis);
        add_row(p, row);
      }
    }
    if (!bc.clamp) continue;
    // A held normal n forbids rotations w with w x n != 0: rows (0, n x e_c).
    for (const auto& entry : edge_count) {
      if (entry.second != 1) continue;
      const auto [e, k] = edge_owner[entry.first];
      int local[3];
      kernels::local_edge_nodes(mesh.type, k, local);
      const int* nodes = mesh.element_nodes(e);
      if (!(is_selected[nodes[local[0]]] && is_selected[nodes[local[1]]] && is_selected[nodes[local[2]]])) continue;
      double xi[2], dxi[2];
      kernels::local_edge_point(mesh.type, k, 0.0, xi, dxi);
      Eigen::Vector3d x, normal;
      surface_point(mesh, e, xi, x, normal);
      if (!(normal.norm() > 0)) continue;
      normal.normalize();
      for (int c = 0; c < 3; ++c) {
        Eigen::Matrix<double, 6, 1> row;
        row << Eigen::Vector3d::Zero(), normal.cross(Eigen::Vector3d::Unit(c));
        add_row(part[nodes[local[1]]], row);
      }
    }
  }

  for (const auto& entry : normal_matrix) {
    const int p = entry.first;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> solver(entry.second);
    const Eigen::Matrix<double, 6, 1> eigenvalues = solver.eigenvalues();  // ascending
    const double largest = std::max(eigenvalues[5], 0.0);
    if (eigenvalues[0] > 1e-10 * largest && largest > 0) continue;
    Eigen::Matrix<double, 6, 1> mode = solver.eigenvectors().col(0);
    Eigen::Index largest_entry = 0;
    mode.cwiseAbs().maxCoeff(&largest_entry);
    if (mode[largest_entry] < 0) mode = -mode;  // eigenvector sign is arbitrary; print a stable one
    const Eigen::Vector3d t = mode.head<3>(), w = mode.tail<3>();
    const std::string motion = t.norm() >= w.norm() ? "translation along " + direction_text(t)
                                                    : "rotation about " + direction_text(w);
    int example_node = 0;
    while (part[example_node] != p || !used[example_node]) ++example_node;
    throw SceneError(scene.source_name, "boundary", "the model is statically unconstrained (the part containing node " +
                         std::to_string(example_node) + " at " + fmt(node_position(mesh, example_node)) +
                         " can still move rigidly, e.g. " + motion + ")",
                     std::to_string(scene.boundary.size()) + " boundary condition(s)",
                     "hold every part against all rigid motions (e.g. fix x, y, z on a line of nodes and clamp it) or "
                     "use a dynamic analysis");
  }
}

}  // namespace

// cuts[i].points: each within cut_point_tolerance of the surface (they are projected
// onto it), and a positive length once projected.
void check_cut_points(const Scene& scene, const Mesh& mesh) {
  if (mesh.num_elements() == 0) return;
  const double tolerance = cut_point_tolerance(mesh);
  const SurfacePointSearch search(mesh);  // closest_surface_point, pruned per query
  for (size_t c = 0; c < scene.cuts.size(); ++c) {
    const Cut& cut = scene.cuts[c];
    if (cut.kind != Cut::Kind::points) continue;
    const std::string path = "cuts[" + std::to_string(c) + "].points";
    double total = 0;
    Eigen::Vector3d previous = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < cut.points.size(); ++k) {
      const SurfacePoint sp = search.closest(cut.points[k].data());
      const Eigen::Vector3d x(sp.position[0], sp.position[1], sp.position[2]);
      if (sp.distance > tolerance)
        throw SceneError(scene.source_name, path + "[" + std::to_string(k) + "]", "off the surface",
                         fmt(Eigen::Vector3d(cut.points[k][0], cut.points[k][1], cut.points[k][2])),
                         "cut points must lie within " + fmt(tolerance) +
                             " of the surface (a quarter of the mean element edge); the nearest surface point is " +
                             fmt(x) + " at distance " + fmt(sp.distance));
      if (k > 0) total += (x - previous).norm();
      previous = x;
    }
    if (!(total > 0))
      throw SceneError(scene.source_name, path, "zero-length cut on the surface", "all points project to " + fmt(previous),
                       "expected points that span a positive length on the surface");
  }
}

void check_scene_against_mesh(const Scene& scene, const Mesh& mesh) {
  check_selections(scene, mesh);
  check_surface_points(scene, mesh);
  check_cut_points(scene, mesh);
  check_rigid_motions(scene, mesh);
}

}  // namespace dgtex

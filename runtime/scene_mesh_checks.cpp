// Mesh-dependent scene validation: empty selections, surface points, rigid motions.
#include "dgtex/scene_mesh_checks.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "dgtex/boundary_selection.h"
#include "dgtex/cut_path.h"
#include "dgtex/kernels/flood_fill.h"
#include "dgtex/scene_io.h"
#include "dgtex/surface_point.h"
#include "dgtex/topology.h"

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
      Vec3 position, normal;
      element_surface_point(mesh, sp.element, sp.xi.data(), position, normal);
      const Eigen::Vector3d x(position.data());
      if (k > 0) total += (x - previous).norm();
      previous = x;
    }
    if (!(total > 0))
      throw SceneError(scene.source_name, path, "zero-length cut on the surface", "all points at " + fmt(previous),
                       "expected points that span a positive length");
  }
}

// Rigid bodies of a static check: elements joined across shared edges move as one (the DG
// edge terms tie their rotations); bodies that meet only at nodes share those nodes'
// translations and can turn about them (two squares meeting at a corner: the solver's
// factorisation failed and read as "penalty too low?"). A piece of the mesh (nodes linked
// through elements) with more than kMaxJointedBodies bodies is tested as one rigid body,
// as if its node joints were stiff: its dense 6B x 6B test would grow as B^3.
constexpr int kMaxJointedBodies = 32;

struct RigidBodies {
  std::vector<int> of_element;              // body of each element
  std::vector<std::vector<int>> of_node;    // distinct bodies using each node, ascending
  std::vector<int> piece, index_in_piece;   // per body: its piece and its place there
  std::vector<int> piece_size;              // bodies per piece
  int count() const { return static_cast<int>(piece.size()); }
};

RigidBodies rigid_bodies(const Mesh& mesh, const Topology& topology) {
  std::vector<int> edge_joined(mesh.num_elements()), node_joined(mesh.num_nodes());
  std::iota(edge_joined.begin(), edge_joined.end(), 0);
  std::iota(node_joined.begin(), node_joined.end(), 0);
  for (const MeshEdge& edge : topology.interior_edges)
    kernels::unite_smaller_root(edge_joined, edge.plus_element, edge.minus_element);
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 1; a < mesh.nodes_per_element(); ++a)
      kernels::unite_smaller_root(node_joined, mesh.element_nodes(e)[0], mesh.element_nodes(e)[a]);
  auto piece_of = [&](int e) { return kernels::find_root_halving(node_joined, mesh.element_nodes(e)[0]); };
  std::map<int, std::set<int>> edge_parts_of_piece;
  for (int e = 0; e < mesh.num_elements(); ++e)
    edge_parts_of_piece[piece_of(e)].insert(kernels::find_root_halving(edge_joined, e));

  RigidBodies bodies;
  bodies.of_element.resize(mesh.num_elements());
  std::map<int, int> body_of_root, piece_index;  // roots of edge parts (or of big pieces)
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const int piece = piece_of(e);
    const bool jointed = static_cast<int>(edge_parts_of_piece[piece].size()) <= kMaxJointedBodies;
    const int root = jointed ? kernels::find_root_halving(edge_joined, e) : -1 - piece;
    const auto [it, inserted] = body_of_root.emplace(root, bodies.count());
    if (inserted) {
      const auto [p, new_piece] = piece_index.emplace(piece, static_cast<int>(bodies.piece_size.size()));
      if (new_piece) bodies.piece_size.push_back(0);
      bodies.piece.push_back(p->second);
      bodies.index_in_piece.push_back(bodies.piece_size[p->second]++);
    }
    bodies.of_element[e] = it->second;
  }
  bodies.of_node.resize(mesh.num_nodes());
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < mesh.nodes_per_element(); ++a) bodies.of_node[mesh.element_nodes(e)[a]].push_back(bodies.of_element[e]);
  for (std::vector<int>& list : bodies.of_node) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return bodies;
}

// Static runs need every body held against all six rigid motions u(x) = t + w x (x - c),
// jointly: each constraint is a linear condition on the (t, w) of one body, each node
// shared by two bodies three conditions on both, and a piece is held when its conditions
// have full rank 6B. Rotations are scaled by the spread of each body's held and shared
// nodes so the rank test depends neither on the length unit nor on nodes far from the
// supports (a plate's bounding box took one node lifted to z = 1e5 on a unit plate as its
// size, and the held nodes' rotation rows fell below the test's tolerance).
void check_rigid_motions(const Scene& scene, const Mesh& mesh) {
  if (scene.analysis.is_dynamic() || mesh.num_elements() == 0) return;
  const Topology topology = build_topology(mesh);
  const RigidBodies bodies = rigid_bodies(mesh, topology);
  std::vector<std::vector<int>> selections;
  for (const BoundaryCondition& bc : scene.boundary) selections.push_back(select_nodes(mesh, bc.select));

  // Per body: centroid and RMS radius of the nodes that hold it (selected or shared).
  std::vector<Eigen::Vector3d> centre(bodies.count(), Eigen::Vector3d::Zero());
  std::vector<double> count(bodies.count(), 0), squares(bodies.count(), 0);
  auto for_each_holding_node = [&](auto&& visit) {
    for (const std::vector<int>& selected : selections)
      for (int n : selected)
        for (int b : bodies.of_node[n]) visit(b, n);
    for (int n = 0; n < mesh.num_nodes(); ++n)
      if (bodies.of_node[n].size() > 1)
        for (int b : bodies.of_node[n]) visit(b, n);
  };
  for_each_holding_node([&](int b, int n) { centre[b] += node_position(mesh, n), count[b] += 1; });
  for (int b = 0; b < bodies.count(); ++b)
    if (count[b] > 0) centre[b] /= count[b];
  for_each_holding_node([&](int b, int n) { squares[b] += (node_position(mesh, n) - centre[b]).squaredNorm(); });
  // A single holding point has no spread: its rotation rows are 0 whatever the scale.
  auto offset = [&](int b, int n) {
    const double scale = count[b] > 0 ? std::sqrt(squares[b] / count[b]) : 0;
    return Eigen::Vector3d((node_position(mesh, n) - centre[b]) / std::max(scale, 1e-300));
  };

  // Normal matrices A^T A per piece, block (i, j) for the bodies at places i and j in it.
  std::vector<Eigen::MatrixXd> normal_matrix;
  for (int size : bodies.piece_size) normal_matrix.push_back(Eigen::MatrixXd::Zero(6 * size, 6 * size));
  using Row = Eigen::Matrix<double, 6, 1>;
  auto block = [&](int b, int c) {
    return normal_matrix[bodies.piece[b]].block<6, 6>(6 * bodies.index_in_piece[b], 6 * bodies.index_in_piece[c]);
  };
  auto add_row = [&](int b, const Row& row) { block(b, b) += row * row.transpose(); };
  auto translation_row = [&](int b, int n, int c) {  // component c of body b's motion at node n
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(c);
    Row row;
    row << axis, offset(b, n).cross(axis);
    return row;
  };

  for (size_t k = 0; k < scene.boundary.size(); ++k) {
    const BoundaryCondition& bc = scene.boundary[k];
    std::vector<char> is_selected(mesh.num_nodes(), 0);
    for (int n : selections[k]) {
      is_selected[n] = 1;
      for (int b : bodies.of_node[n])
        for (int c = 0; c < 3; ++c)
          if (bc.fixed[c]) add_row(b, translation_row(b, n, c));
    }
    if (!bc.clamp) continue;
    // A held normal n forbids rotations w with w x n != 0: rows (0, n x e_c).
    for (const MeshEdge& edge : topology.boundary_edges) {
      if (!(is_selected[edge.nodes[0]] && is_selected[edge.nodes[1]] && is_selected[edge.nodes[2]])) continue;
      double xi[2], dxi[2];
      kernels::local_edge_point(mesh.type, edge.plus_local_edge, 0.0, xi, dxi);
      Vec3 position, unit_normal;
      element_surface_point(mesh, edge.plus_element, xi, position, unit_normal);
      const Eigen::Vector3d normal(unit_normal.data());
      if (!(normal.norm() > 0)) continue;
      for (int c = 0; c < 3; ++c) {
        Row row;
        row << Eigen::Vector3d::Zero(), normal.cross(Eigen::Vector3d::Unit(c));
        add_row(bodies.of_element[edge.plus_element], row);
      }
    }
  }
  // A node shared by bodies a < b: their motions agree there, rows (a's) - (b's).
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const std::vector<int>& shared = bodies.of_node[n];
    for (size_t i = 1; i < shared.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        const int a = shared[0], b = shared[i];
        const Row row_a = translation_row(a, n, c), row_b = translation_row(b, n, c);
        block(a, a) += row_a * row_a.transpose();
        block(b, b) += row_b * row_b.transpose();
        block(a, b) -= row_a * row_b.transpose();
        block(b, a) -= row_b * row_a.transpose();
      }
  }

  std::vector<std::vector<int>> body_at(bodies.piece_size.size());
  for (int b = 0; b < bodies.count(); ++b) body_at[bodies.piece[b]].push_back(b);
  for (size_t p = 0; p < normal_matrix.size(); ++p) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(normal_matrix[p]);
    const Eigen::VectorXd& eigenvalues = solver.eigenvalues();  // ascending
    const double largest = std::max(eigenvalues[eigenvalues.size() - 1], 0.0);
    if (eigenvalues[0] > 1e-10 * largest && largest > 0) continue;
    // The free motion: shown for the body that moves most in it.
    const Eigen::VectorXd mode_of_piece = solver.eigenvectors().col(0);
    int place = 0;
    for (int i = 1; i < bodies.piece_size[p]; ++i)
      if (mode_of_piece.segment<6>(6 * i).norm() > mode_of_piece.segment<6>(6 * place).norm() + 1e-9) place = i;
    Row mode = mode_of_piece.segment<6>(6 * place);
    Eigen::Index largest_entry = 0;
    mode.cwiseAbs().maxCoeff(&largest_entry);
    if (mode[largest_entry] < 0) mode = -mode;  // eigenvector sign is arbitrary; print a stable one
    const Eigen::Vector3d t = mode.head<3>(), w = mode.tail<3>();
    const std::string motion = t.norm() >= w.norm() ? "translation along " + direction_text(t)
                                                    : "rotation about " + direction_text(w);
    const int body = body_at[p][place];
    int example_node = -1, joint = -1;  // a node of the body alone (else any), and a shared one
    for (int n = 0; n < mesh.num_nodes(); ++n) {
      const std::vector<int>& of = bodies.of_node[n];
      if (std::find(of.begin(), of.end(), body) == of.end()) continue;
      if (of.size() > 1 && joint < 0) joint = n;
      if (of.size() == 1 && example_node < 0) example_node = n;
    }
    if (example_node < 0) example_node = joint;
    const std::string joint_text = joint < 0 ? "" : "; it meets the rest of the mesh only at single nodes (node " +
                                                        std::to_string(joint) +
                                                        "), not along an edge, and can turn about them";
    throw SceneError(scene.source_name, "boundary", "the model is statically unconstrained (the part containing node " +
                         std::to_string(example_node) + " at " + fmt(node_position(mesh, example_node)) +
                         " can still move rigidly, e.g. " + motion + joint_text + ")",
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

#pragma once
// A scene cut traced across the mesh (thesis §5.6: "discontinuities were prescribed as
// polylines and then rasterized to texel edges"). The polyline's points are projected
// onto the rest surface (or given as surface points), and between consecutive points the
// path follows the surface projection of the straight 3D chord, densified to a fraction
// of an element so curved elements are followed. Wherever the path passes from element A
// to element B across their shared edge, the crossing is computed ONCE on that edge,
// snapped to a lattice point of the edge's texel lattice (T texels per edge, lattice
// coordinate u in 0..T from the edge's start corner) and written in both elements'
// parameters (u in A is T - u in B, which runs the edge backwards), so the texel-edge
// paths rasterised in A and B meet at the same lattice point and a complete cut separates
// the texels on both sides of the edge. A path that passes from A to an element touching
// it only at a corner goes through that node.
//
// Arc length and turning angles are measured on the rest surface with the unsnapped
// crossing points, so they do not depend on the texture resolution.
// Value types and pure functions (thread-safe): a MeshCutPath owns its vertices.
// Lengths and arc lengths in the mesh's unit (SI: m); xi are element parameters.
#include <array>
#include <string>
#include <vector>

#include "dgtex/mesh.h"
#include "dgtex/scene.h"
#include "dgtex/topology.h"

namespace dgtex {

class SurfacePointSearch;  // surface_point.h

// Neighbour across each local edge: neighbour(e, k) = {element, its local edge} or
// {-1, -1} on the mesh boundary. Built from a Topology.
class ElementAdjacency {
 public:
  ElementAdjacency() = default;
  ElementAdjacency(const Mesh& mesh, const Topology& topology);
  std::array<int, 2> neighbour(int element, int local_edge) const {
    return {across_[4 * element + local_edge], across_edge_[4 * element + local_edge]};
  }
  int edges_per_element() const { return edges_; }

 private:
  int edges_ = 4;
  std::vector<int> across_, across_edge_;  // 4 slots per element (tri6 uses 3)
};

struct CutPathVertex {
  int element = -1;
  std::array<double, 2> xi{};  // parameters in `element` (edge crossings: a lattice point)
  double arc_length = 0;       // rest arc length from the start of the path
  Vec3 position{};             // rest position (unsnapped)
  Vec3 normal{};               // unit surface normal there (for turning angles)
};

// Consecutive vertices in the same element are joined by a straight segment in that
// element's parameter space. A change of element happens between two vertices with the
// same arc length and position: one surface point written in both elements.
struct MeshCutPath {
  std::vector<CutPathVertex> vertices;
  double length() const { return vertices.empty() ? 0.0 : vertices.back().arc_length; }
};

// Largest distance a cut's `points` may lie from the surface: a quarter of the mean
// element corner-to-corner edge length.
double cut_point_tolerance(const Mesh& mesh);

// Traces scene cut `cut` (name: its JSON path for messages, e.g. "cuts[2]").
// resolution: texels per element side (crossing points snap to that lattice).
// Throws std::invalid_argument, naming the point (e.g. "cuts[2].points[1]"), the value and
// what is valid, for: a point farther than cut_point_tolerance from the surface, an element
// index out of range, xi outside the reference element, fewer than 2 points, a path of
// zero length on the surface, and a chord that leaves the surface (two consecutive points
// on parts of the mesh that do not touch).
MeshCutPath trace_cut_path(const Mesh& mesh, const ElementAdjacency& adjacency, const Cut& cut, int resolution,
                           const std::string& name);
// The same with a SurfacePointSearch of `mesh` built once for many cuts: its queries are
// const, so cuts may be traced concurrently with one search (and its per-element samples,
// ~0.6 KB an element, exist once instead of per cut).
MeshCutPath trace_cut_path(const Mesh& mesh, const SurfacePointSearch& search, const ElementAdjacency& adjacency,
                           const Cut& cut, int resolution, const std::string& name);

// Rest position and unit normal at xi of an element.
void element_surface_point(const Mesh& mesh, int element, const double xi[2], Vec3& position, Vec3& normal);

// The part of `path` between arc lengths a <= b (closed: the ends are interpolated inside
// their element, vertices at exactly a or b are kept).
std::vector<CutPathVertex> sub_path(const MeshCutPath& path, double a, double b);

// The elements holding a piece of positive length of the path (consecutive vertices in the
// element at different xi), sorted; an element the path only touches at a point is not one.
std::vector<int> elements_passed_through(const std::vector<CutPathVertex>& vertices);

// Inserts a vertex at arc length s on the path's segment inside `element` (no change if a
// vertex of that element is already there, within 1e-12 of the length). Returns false if
// the path has no segment in `element` at s.
bool insert_path_vertex(MeshCutPath& path, double s, int element);

}  // namespace dgtex

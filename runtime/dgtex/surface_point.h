#pragma once
// Closest point on the curved (quadratic) mesh surface: probes and cut paths given as
// rest-configuration points are projected with this.
// A pure function (thread-safe). Positions and distances in the mesh's length unit (SI: m).
#include <memory>
#include <vector>

#include "dgtex/mesh.h"
#include "dgtex/mesh_error.h"

namespace dgtex {

struct SurfacePoint {
  int element = -1;
  double xi[2] = {0, 0};           // parametric coordinates in that element's reference domain
  double position[3] = {0, 0, 0};  // x(xi) on the rest surface
  double distance = 0;             // |position - query| (unsigned)
};

// Nearest point to p on the surface x(xi) of the mesh's quadratic elements (not on their
// facets). Each element is seeded from the best of a fixed set of samples (quad8 5x5,
// tri6 15), elements are refined in order of their sampled distance and skipped once a
// lower bound of their distance exceeds the best refined distance (the sampled distance
// less half the element's diameter, or the distance to the box of its samples less how far
// its midside nodes let it bulge beyond its corners' box, or the distance to its corner
// facets less that bulge (and a quad8's twist), whichever is largest: for flat
// straight-sided elements the last is the exact distance, so a query on a flat mesh
// refines little more than the element that holds it);
// refinement is Newton (Gauss-Newton where the Hessian is indefinite) on |x(xi) - p|^2
// with an active set on the reference element's bounds and a projected backtracking line
// search, so points on edges and corners come out exactly. Ties (distances within
// 1e-12 x the mesh's bounding-box diagonal) go to the lowest element index.
// Throws MeshError for an empty mesh or a non-finite p. Assumes a validated mesh.
SurfacePoint closest_surface_point(const Mesh& mesh, const double p[3]);

// The same search for many queries on one mesh, bitwise equal to closest_surface_point:
// the seed samples, margins and a box around each element's samples are computed once;
// a query computes the exact seed distance only for elements whose box could hold the
// nearest seed or whose margin could let them be refined (a lower bound, so the refined
// candidates, their order and the answer are those of the full search). A cut path of
// the 544-element bunny projects ~6x faster. The whole-mesh search (closest) finds those
// elements in a hierarchy of their sample boxes instead of measuring every box (fracture's
// 213 cut points, one whole-mesh search each: its cut tracing 4.2-4.6 -> 3.2-3.6 ms on one
// thread, with the sample points built once and the tracer's patches sorted, not set).
// Keeps a reference to the mesh (which must outlive it and not change). Thread-safe
// queries (const).
namespace detail {
class BoxHierarchy;
}

class SurfacePointSearch {
 public:
  explicit SurfacePointSearch(const Mesh& mesh);
  // The mesh is kept by reference: a temporary one would dangle, a const one too.
  explicit SurfacePointSearch(Mesh&&) = delete;
  explicit SurfacePointSearch(const Mesh&&) = delete;
  // == closest_surface_point(mesh, p).
  SurfacePoint closest(const double p[3]) const;
  // == closest_surface_point of the sub-mesh made of these elements (distinct, ascending),
  // with the element given as a mesh element index. Throws MeshError for an empty list and
  // std::invalid_argument for an index out of range or a list not strictly ascending.
  SurfacePoint closest_among(const std::vector<int>& elements, const double p[3]) const;

 private:
  // whole: elements is all_ (then the box hierarchy finds the candidates).
  SurfacePoint search(const int* elements, int count, const double p[3], double tie_tolerance, bool whole) const;
  double tie_tolerance_of(const std::vector<int>& elements) const;
  static void check_query(const double p[3]);
  const Mesh& mesh_;
  int samples_ = 0;
  std::vector<double> sample_positions_;  // per element and sample: x, y, z
  std::vector<double> margins_;           // per element: half its diameter over node pairs
  std::vector<double> bulges_;            // per element: how far it can leave its corners' box
  std::vector<double> facet_slacks_;      // per element: how far it can lie from its corner facets
  std::vector<double> sample_boxes_;      // per element: lo[3], hi[3] of its samples
  std::vector<double> node_boxes_;        // per element: lo[3], hi[3] of its nodes
  std::vector<int> all_;                  // 0..elements-1
  // The whole mesh: its sample boxes' hierarchy, the largest min(margin, bulge) of its
  // elements, and closest_among's tie tolerance over all of them.
  std::shared_ptr<const detail::BoxHierarchy> sample_box_tree_;
  double largest_slack_ = 0;
  double whole_tie_tolerance_ = 0;
};

}  // namespace dgtex

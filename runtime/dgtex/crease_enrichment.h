#pragma once
// Creases (thesis §5.6, Fig. 5.21): the shell stays C0 across a crease line but its slope
// may jump there (a hinge). Each scene crease becomes one EnrichmentFunction WITHOUT walls
// whose texture H has a kink along the crease, so that the enriched basis
// (H - H(xi^a)) N^a (enrichment_function.h) represents displacement fields whose first
// derivatives jump across it. On the elements the crease passes through, H is the ridge
// sum_b |d_b| N^b - |d| of the distance d from the crease line (divided by the mesh's mean
// element edge length, so H = O(1)): zero at the nodes and on the element edges the crease
// does not cross. The other elements of Omega_i get H = 0, so no element carries a ramp its
// basis cannot follow. The crease's texel edges carry kink bits (texel_grid.h): the texel
// rule's differences stay on one side, so the kink is not a curvature spike.
//
// What is built, per crease:
//   - the crease is traced across the mesh like a cut (trace_cut_path, same point forms and
//     validation, messages name creases[i]);
//   - N_i: the nodes of every element the crease passes through (a segment of positive
//     length inside it); Omega_i: every element incident to one of those nodes (one ring);
//   - per element the crease passes through, a fast-marching distance
//     (kernels/fast_marching.h) in the element's own parameter space scaled by its metric
//     at the element centre (texel steps |dx/dxi1| dxi and |dx/dxi2| dxi: an affine,
//     orthogonal approximation). Seeds, with the exact 3D distance to the crease polyline
//     (the traced path's rest points): the texels within 1.5 texels of the crease, and
//     every texel on the tile's border, so neighbouring elements agree along their shared
//     edge (H is C0 across elements up to the half-texel offset of the texel centres from
//     the edge); then the ridge of it, with the nodes' exact distances, and the kink bits
//     on the texel edges the crease's path rasterises to (as a cut's walls would be).
// Limits: on a flat mesh the result is the exact Euclidean (= geodesic) distance up to the
// first-order fast-marching error O(texel) away from the seeds. On a curved mesh the seeds
// use the chordal 3D distance, which underestimates the geodesic one by O(kappa^2 d^3), and
// the metric is taken constant per element. Crease textures carry no cut walls: a cut
// crossing a creased element does not split the crease's enrichment. Creases are static
// (no start_time/speed). A crease tip inside an element gives distance-to-endpoint (a cone),
// so the slope jump fades out around the tip as the kink does.
// Pure functions: return their results by value (keep nothing; thread-safe).
// H is dimensionless (distance / mean edge length); lengths in the mesh's unit (SI: m).
#include <vector>

#include "dgtex/enrichment_function.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/mesh.h"
#include "dgtex/scene.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"

namespace dgtex {

// A scene crease traced across the mesh: what build_crease_functions needs from the trace.
// Kept between the texel memory check and the build, so each crease is traced once.
struct TracedCrease {
  int resolution = 0;           // T, texels per element side, the kinks were rasterised at
  std::vector<Vec3> line;       // the traced path's rest points
  std::vector<int> nodes;       // N_i (sorted)
  std::vector<int> elements;    // Omega_i (sorted)
  std::vector<int> crossed;     // the elements the crease folds inside (sorted)
  // Per crossed element (kink_edges[k] for crossed[k]): the texel edges its path
  // rasterises to inside the element, as a cut's walls would be.
  std::vector<std::vector<kernels::CutLatticeEdge>> kink_edges;
};

// One trace per crease, in order. resolution: texels per element side (T, as for cuts).
// Throws std::invalid_argument naming creases[i] for a crease the mesh cannot take (see
// trace_cut_path), one that passes through no element with positive length, or one that
// runs along element edges only (it could not fold there; the message gives the remedy).
std::vector<TracedCrease> trace_creases(const Mesh& mesh, const Topology& topology, const std::vector<Cut>& creases,
                                        int resolution);

// One function per traced crease, in order.
std::vector<EnrichmentFunction> build_crease_functions(const Mesh& mesh, const std::vector<TracedCrease>& creases);

// trace_creases, then build_crease_functions; throws as trace_creases does.
std::vector<EnrichmentFunction> build_crease_functions(const Mesh& mesh, const Topology& topology,
                                                       const std::vector<Cut>& creases, int resolution);

// The fields build_crease_functions makes from the traced creases (one per crease, a tile on
// each element of its Omega_i; texel_memory_estimate.h).
TexelFootprint crease_footprint(const std::vector<TracedCrease>& creases);

}  // namespace dgtex

#pragma once
// Closest point on the curved (quadratic) mesh surface: probes and cut paths given as
// rest-configuration points are projected with this.
// A pure function (thread-safe). Positions and distances in the mesh's length unit (SI: m).
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
// tri6 15), elements are refined in order of their sampled distance and skipped once their
// sampled distance minus half the element's diameter exceeds the best refined distance;
// refinement is Newton (Gauss-Newton where the Hessian is indefinite) on |x(xi) - p|^2
// with an active set on the reference element's bounds and a projected backtracking line
// search, so points on edges and corners come out exactly. Ties (distances within
// 1e-12 x the mesh's bounding-box diagonal) go to the lowest element index.
// Throws MeshError for an empty mesh or a non-finite p. Assumes a validated mesh.
SurfacePoint closest_surface_point(const Mesh& mesh, const double p[3]);

}  // namespace dgtex

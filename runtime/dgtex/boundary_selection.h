#pragma once
// Which mesh nodes a boundary condition's "select" picks (scene file, boundary[].select).
// Pure functions of the mesh and the selection (thread-safe); lengths in the mesh's unit (SI: m).
#include <vector>

#include "dgtex/mesh.h"
#include "dgtex/scene.h"

namespace dgtex {

// Indices (ascending) of the nodes of mesh that the selection picks:
//   plane: |n . x - offset| <= tolerance, with n the selection's normal made a unit vector;
//   box:   min[i] - tolerance <= x[i] <= max[i] + tolerance for i = 0, 1, 2.
// Nodes not referenced by any element are never selected. An empty result is not an
// error here; the caller reports it with the selection's JSON path.
std::vector<int> select_nodes(const Mesh& mesh, const BoundarySelect& select);

// Whether one point satisfies the selection (same rule as select_nodes).
bool point_is_selected(const BoundarySelect& select, const double x[3]);

}  // namespace dgtex

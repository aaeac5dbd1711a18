#pragma once
// Edge connectivity of a shell mesh: which elements meet across each edge, for the DG
// interface terms (interior edges) and the clamped/free boundary terms (boundary edges).
// A value type that owns its edge arrays (no reference to the mesh); const use is thread-safe.
#include <vector>

#include "dgtex/mesh.h"
#include "dgtex/mesh_error.h"

namespace dgtex {

// One mesh edge. The plus element traverses it in its own local direction
// nodes[0] -> nodes[1] -> nodes[2], so it lies on the LEFT of the edge seen from its normal
// side; the minus element (if any) traverses it backwards (nodes[2] -> nodes[0]) and lies
// on the right. Local edges follow dgtex/kernels/shape_functions.h (local_edge_nodes).
struct MeshEdge {
  int plus_element = -1, plus_local_edge = -1;
  int minus_element = -1, minus_local_edge = -1;  // -1, -1 on boundary edges
  int nodes[3] = {-1, -1, -1};                    // start corner, midside, end corner (plus direction)
};

// interior_edges: shared by exactly two elements; the plus element is the one with the lower
// index. boundary_edges: used by one element (the plus element). Both lists are ordered by
// (plus_element, plus_local_edge), so the result does not depend on anything but the mesh.
struct Topology {
  std::vector<MeshEdge> interior_edges;
  std::vector<MeshEdge> boundary_edges;
};

// Throws MeshError (naming the elements, local edges and node indices; elements() lists the
// elements involved) for: an edge whose two corners coincide, an edge used by three or more
// elements (non-manifold), two elements traversing a shared edge in the same direction
// (inconsistent orientation: one is flipped), and a shared edge whose midside nodes differ.
// Node indices are assumed in range (validate_mesh checks that first).
Topology build_topology(const Mesh& mesh);

}  // namespace dgtex

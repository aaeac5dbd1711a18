#pragma once
// Internal (CutManager's growth rounds): whether the two sides of a cut segment meet in the
// mesh's texel graph. A segment whose every side component also holds texels of the other
// side closes no region: its step function is a step only on part of the mesh (the sides
// meet beyond a free tip, perhaps one of a later segment of the same cut), and growing its
// region cannot make a step of it.
#include <map>
#include <utility>
#include <vector>

#include "dgtex/kernels/texel_grid.h"
#include "dgtex/mesh_texel_laplace.h"

namespace dgtex::detail {

// A segment's side texels: element -> (texel index, value), values +1 or -1 (0: neither side).
using SideTexels = std::map<int, std::vector<std::pair<int, double>>>;

// Whether every component of the mesh's texel graph that holds a texel of one side also
// holds one of the other. The graph couples the texels as the harmonic problem does
// (mesh_texel_laplace.h): lattice neighbours that no wall or inactive texel separates, and
// partner texels across mesh edges that no cut along the edge blocks. `walls`: the cut walls
// per element (elements without an entry: `blank`, the element type's tile without walls).
// A breadth-first search from every side texel at once, layer by layer; it stops when the
// sides have met in every component found, or when a component with one side only is
// complete (a closed region): its cost is that of the smallest such region, not the mesh's.
bool every_side_meets_the_other(const SideTexels& sides, const std::map<int, kernels::TexelTile>& walls,
                                const kernels::TexelTile& blank, ElementType type, const ElementAdjacency& adjacency,
                                const MeshEdgeWalls& edge_walls);

}  // namespace dgtex::detail

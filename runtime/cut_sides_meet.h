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

// A segment's side texels: element -> (texel index, value), +1 left, -1 right (other
// values, where passes disagree: neither side).
using SideTexels = std::map<int, std::vector<std::pair<int, double>>>;

// Whether every component of the mesh's texel graph that holds a texel of one side of
// segments[segment] also holds one of the other. The graph couples the texels as the
// harmonic problem does (mesh_texel_laplace.h): lattice neighbours that no wall or inactive
// texel separates, and partner texels across mesh edges that no cut along the edge blocks.
// `walls`: the cut walls per element (elements without an entry: `blank`, the element
// type's tile without walls).
// A breadth-first search from every side texel at once, layer by layer; it stops when the
// sides have met in every component found, or when a component with one side only is
// complete (a closed region): it floods as many layers as the sides need to meet or the
// smallest such region needs to fill, not the whole mesh.
// The other segments' side texels seed it too, without a side: they change no component,
// but the search runs along every cut from the start, and the sides of a segment that a
// long segment continues meet beyond that one's free tip in a few layers (fracture's
// T-junction segment: 3 layers over 7,200 texels instead of 199 over 84,000).
bool every_side_meets_the_other(const std::vector<SideTexels>& segments, std::size_t segment,
                                const std::map<int, kernels::TexelTile>& walls, const kernels::TexelTile& blank,
                                ElementType type, const ElementAdjacency& adjacency, const MeshEdgeWalls& edge_walls);

}  // namespace dgtex::detail

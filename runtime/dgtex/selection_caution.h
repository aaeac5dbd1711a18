#pragma once
// Is a boundary selection's tolerance a large part of the mesh? The tolerance is a length in
// the mesh's units (default 1e-6), so a mesh measured in micrometres takes every node within
// the default of a plane: a cantilever 1e-6 long, clamped on the plane x = 0, was held at
// every node and ended its run with zero displacement, exit 0. A deliberate whole-mesh
// selection (every node of a flat plate on its plane) needs no tolerance of that size, so
// `dgtex run` cautions instead of refusing. Pure function.
#include <string>

#include "dgtex/mesh.h"
#include "dgtex/scene.h"

namespace dgtex {

// A tolerance of this part of the mesh's bounding-box diagonal or more is cautioned.
inline constexpr double kSelectionToleranceCautionAbove = 0.01;

// One sentence for `dgtex run` to print before the steps for the first selection of
// `scene.boundary` whose tolerance reaches the line, naming it, the mesh's size, how many of
// the mesh's nodes it holds and the remedy; else "".
std::string selection_tolerance_caution(const Scene& scene, const Mesh& mesh);

}  // namespace dgtex

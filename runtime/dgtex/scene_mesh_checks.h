#pragma once
// Scene checks that need the mesh, run once the mesh has been generated or loaded. They
// throw SceneError (one line, with the JSON path) like the parser, so `dgtex run` reports
// them the same way (exit code 2).
// Pure functions (thread-safe).
#include "dgtex/mesh.h"
#include "dgtex/scene.h"

namespace dgtex {

// Throws SceneError when
//  - boundary[i].select picks no mesh node (the message gives the mesh's bounding box);
//  - cuts[i].surface_points name an element the mesh lacks, lie outside the reference
//    element of the mesh's type, or span zero length on the surface;
//  - the analysis is static and some connected part of the mesh can still move rigidly
//    under the boundary conditions (fixed components on selected nodes, clamped normals on
//    boundary edges whose three nodes are all selected). Parts are elements joined across
//    shared edges; parts that meet only at nodes share those nodes' translations, not
//    their rotations.
void check_scene_against_mesh(const Scene& scene, const Mesh& mesh);

}  // namespace dgtex

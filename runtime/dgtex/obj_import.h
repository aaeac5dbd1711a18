#pragma once
// Wavefront OBJ import of a shell surface.
// Functions that read a file and return a Mesh by value (thread-safe). Positions in the
// OBJ's length unit (the scene's, SI: m).
#include <string>

#include "dgtex/mesh.h"
#include "dgtex/mesh_error.h"

namespace dgtex {

// Reads 'v x y z' and 'f ...' lines (face corners as v, v/vt, v//vn or v/vt/vn; negative
// indices count back from the last vertex read so far); all other lines (vt, vn, o, g, s,
// usemtl, mtllib, l, comments) are ignored. Faces must be all triangles (-> tri6) or all
// quads (-> quad8), their corners counter-clockwise seen from the side the normal should
// point to (the OBJ convention). A midside node is added at the midpoint of every edge,
// shared by the faces on both sides. Node numbering: the referenced OBJ vertices in file
// order (vertices no face uses are dropped), then the midside nodes in order of first use.
// Element e is the e-th face of the file.
// The result passes validate_mesh; any problem throws MeshError naming path:line (for
// faces found invalid by validate_mesh / build_topology, the lines of the faces involved).
Mesh load_obj(const std::string& path);

}  // namespace dgtex

#pragma once
// Wavefront OBJ import of a shell surface.
// Functions that read a file and return a Mesh by value (thread-safe). Positions in the
// OBJ's length unit (the scene's, SI: m).
#include <cstdint>
#include <string>

#include "dgtex/mesh.h"
#include "dgtex/mesh_error.h"

namespace dgtex {

// Reads 'v x y z' and 'f ...' lines (face corners as v, v/vt, v//vn or v/vt/vn; negative
// indices count back from the last vertex read so far); vt, vn, vp, l, p, g, o, s, usemtl
// and mtllib lines and comments (from '#' on) are skipped, any other statement is refused
// naming its line (an 'F' dropped a face silently). Lines end in LF, CR LF or CR; a UTF-8
// byte order mark is skipped. Faces must be all triangles (-> tri6) or all
// quads (-> quad8), their corners counter-clockwise seen from the side the normal should
// point to (the OBJ convention). A midside node is added at the midpoint of every edge,
// shared by the faces on both sides. Node numbering: the referenced OBJ vertices in file
// order (vertices no face uses are dropped), then the midside nodes in order of first use.
// Element e is the e-th face of the file.
// The result passes validate_mesh; any problem throws MeshError naming path:line (for
// faces found invalid by validate_mesh / build_topology, the lines of the faces involved).
Mesh load_obj(const std::string& path);

// The faces of an OBJ file and the corners of its first one (3 or 4; 0 without faces),
// counted from its 'f' lines without reading them: what load_obj's mesh will hold, for a
// memory check before the file is parsed (a 3000 x 3000 grid took 35 s and 5.4 GB to be
// read before its model was refused). MeshError when the file cannot be opened.
struct ObjFaceCount {
  std::int64_t faces = 0;
  int first_face_corners = 0;
};
ObjFaceCount count_obj_faces(const std::string& path);

}  // namespace dgtex

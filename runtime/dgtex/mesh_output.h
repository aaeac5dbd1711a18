#pragma once
// Mesh files for viewing results: VTK XML (ParaView) and OBJ (any viewer).
// Functions that write files and keep nothing; safe from several threads for distinct files.
// Positions and displacements in the mesh's length unit (SI: m).
#include <string>
#include <utility>
#include <vector>

#include "dgtex/mesh.h"
#include "dgtex/mesh_error.h"

namespace dgtex {

// ASCII VTK XML UnstructuredGrid (.vtu) with quadratic cells: VTK_QUADRATIC_QUAD (23) for
// quad8, VTK_QUADRATIC_TRIANGLE (22) for tri6 (VTK's node order equals ours: corners, then
// the midsides of edges 01, 12, 23/20, ...). Points are rest positions + displacement;
// displacement is #nodes x 3 row-major, or nullptr for none (the "displacement" vector
// array is then zero). point_scalars: extra named per-node arrays, each #nodes long.
// Values are written with 17 significant digits (round-trip exact).
// Array names are written as XML text (escaped). Throws MeshError naming the path on I/O
// failure, for a wrong scalar array length or a non-finite value (naming the array and
// node), and for a mesh the writers cannot read: an unknown element type, arrays that are
// not whole nodes and elements, no element, or a node index out of range (naming it).
void write_vtu(const std::string& path, const Mesh& mesh, const double* displacement,
               const std::vector<std::pair<std::string, std::vector<double>>>& point_scalars = {});

// Wavefront OBJ of the deformed surface as linear triangles through the midside nodes:
// vertices 1..#nodes are the mesh nodes (rest + displacement, displacement may be nullptr);
// tri6 -> 4 triangles (3 corner triangles + the midside triangle); quad8 -> 8 triangles
// (4 corner triangles + 4 around an extra vertex at the element centre x(0, 0), evaluated
// with the shape functions; the centre vertices follow the nodes, one per element in
// element order). All triangles keep the element's orientation (counter-clockwise seen
// from the normal side). Throws MeshError naming the path on I/O failure, and for a mesh
// the writers cannot read (as write_vtu).
void write_obj(const std::string& path, const Mesh& mesh, const double* displacement);

}  // namespace dgtex

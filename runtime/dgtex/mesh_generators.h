#pragma once
// Structured shell meshes of the scene file's generators (README.md, "Scene file reference", `mesh`).
// Divisions count elements along each parameter. Every node, midside nodes included, is
// placed ON the exact surface at its parameter value (not on chords), so curved meshes are
// as exact as quadratic elements allow. Corner order follows the parameters, so each
// element's normal (dx/dxi1 x dx/dxi2) points the documented way.
// tri6: every grid cell (u0..u1) x (v0..v1) is split along its diagonal (u0,v0)-(u1,v1)
// into two tri6; the diagonal's midside node is the cell-centre node. Which corner each
// triangle starts at (its local vertex 0, where its texel axes meet) is the TriangleSplit.
// Node numbering: row by row in the second parameter, first parameter fastest, on the
// half-step grid (quad8 skips the cell centres). Invalid arguments throw MeshError.
// Pure functions returning a Mesh by value (thread-safe). Lengths in the scene's unit
// (SI: m), angles in degrees.
#include "dgtex/mesh.h"
#include "dgtex/mesh_error.h"

namespace dgtex {

// How a tri6 generator orders the corners of a cell's two triangles. A triangle's texels run
// along its edges from local vertex 0 (the tile's right angle).
// - sheared: both start at (u0, v0): (u0,v0) (u1,v0) (u1,v1) and (u0,v0) (u1,v1) (u0,v1).
//   Each texel grid runs along a cell side and the diagonal, so on a square cell its texels
//   are sheared, and a hypotenuse meets a leg across the cell sides.
// - square: they start at (u1, v0) and (u0, v1): (u1,v0) (u1,v1) (u0,v0) and (u0,v1)
//   (u0,v0) (u1,v1). Each texel grid runs along two cell sides (square texels on square
//   cells), the diagonal is both hypotenuses and legs meet legs, so any block of cells lies
//   on one texel lattice and its harmonic enrichments are solved by the tile multigrid
//   (mesh_texel_laplace.h) instead of algebraic multigrid.
// quad8 ignores it. Both give the same nodes and the same normals.
enum class TriangleSplit { sheared, square };

// Points (x, y, 0), x in [0, size_x], y in [0, size_y]; normal +z.
Mesh make_rectangle(double size_x, double size_y, int nx, int ny, ElementType type,
                    TriangleSplit split = TriangleSplit::sheared);

// Points (R sin t, y, R cos t), t between angle0_deg and angle1_deg (either order; the
// range may be at most 360 degrees), y in [0, length]; t = 0 is the top (z = R), the axis
// is y. Normal points outward (away from the y axis). A 360 degree range closes the seam:
// the nodes at t0 and t0 + 360 are shared, so those edges are interior (needs n_angle >= 3:
// with 2, two different edges would join the same pair of corner nodes).
Mesh make_cylinder(double radius, double length, double angle0_deg, double angle1_deg, int n_angle,
                   int n_length, ElementType type, TriangleSplit split = TriangleSplit::sheared);

// Centre at the origin, pole on +z: points (R sin p cos l, R sin p sin l, R cos p), polar
// angle p in [hole_deg, 90] degrees (hole_deg in (0, 90)), azimuth l in [0, 360) closed
// (needs n_azimuth >= 3). Normal outward. Boundary: the hole rim and the equator.
Mesh make_hemisphere(double radius, double hole_deg, int n_polar, int n_azimuth, ElementType type,
                     TriangleSplit split = TriangleSplit::sheared);

}  // namespace dgtex

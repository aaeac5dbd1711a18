#pragma once
// Checks that a mesh is usable by the shell solver, and per-element measures.
// Pure functions (thread-safe). Lengths in the mesh's unit (SI: m), areas in its square (m^2).
#include <string>

#include "dgtex/mesh.h"
#include "dgtex/mesh_error.h"

namespace dgtex {

// Throws MeshError (naming the element / node index and the value) unless:
//  - the element type is quad8 or tri6, positions hold #nodes x 3 values and elements
//    #elements x nodes_per_element values, with at least one element;
//  - every coordinate is finite;
//  - every node index is in [0, #nodes) and no element repeats a node;
//  - every node is used by some element (a free node has no stiffness: singular system);
//  - no element is degenerate: at each of its quadrature points the area Jacobian
//    |dx/dxi1 x dx/dxi2| must exceed 1e-10 x (element diameter)^2, where the diameter is the
//    largest distance between two of its nodes, and at each corner the signed Jacobian
//    (against the normal at the element's centre) must too (a reflex corner, two corners
//    at one point);
//  - no element is a sliver: diameter^2 / area at most kMaxElementAspect (a square has 2,
//    a right isosceles triangle 4; above it the stiffness is round-off, mesh_validation.cpp);
//  - build_topology succeeds (manifold, consistently oriented, shared midside nodes);
//  - no two neighbours fold back onto each other: their normals at the midpoint of their
//    shared edge at most acos(kMinNeighbourNormalCosine) = 172 degrees apart.
inline constexpr double kMaxElementAspect = 1e4;
inline constexpr double kMinNeighbourNormalCosine = -0.99;
void validate_mesh(const Mesh& mesh);

// A caution for boundary nodes that lie on other boundary nodes (within 1e-9 of the mesh's
// extent) without being joined to them: an OBJ whose seam repeats its vertices instead of
// sharing them, which runs as separate pieces (a plate split so deflected 1.54x as far;
// every face of a triangle soup fell on its own). Valid, so `dgtex run` only says so: one
// sentence naming how many nodes and one pair, or "" (a validated mesh).
std::string unwelded_seam_caution(const Mesh& mesh);

// Area of element e by its quadrature rule (exact for the flat undistorted elements,
// degree-5 accurate otherwise). Units: length^2.
double element_area(const Mesh& mesh, int e);

// Perimeter of element e: the length of its three or four curved edges, each by 5-point
// Gauss-Legendre quadrature. Units: length.
double element_perimeter(const Mesh& mesh, int e);

}  // namespace dgtex

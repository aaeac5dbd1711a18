#pragma once
// Element terms of the DG Kirchhoff-Love shell (shell report eqs. 32-33), corotated per
// quadrature point (eqs. 47-48). One element per work item; outputs are per element, so
// the parallel form equals the serial reference bitwise.
//
// Shapes: connectivity #elements x npe; positions #nodes x 3; sections #elements;
// rotations (optional) #elements x nq x 9 (row-major R per quadrature point, nq from
// element_quadrature(type)); blocks #elements x npe x npe x 9 (block (a,b) at
// (a*npe+b)*9, row-major 3x3); forces #elements x npe x 3.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Units: consistent (SI: positions m, E Pa, h m, density kg/m^3; blocks N/m, forces N, mass kg).
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/shape_functions.h"

namespace dgtex::kernels {

// Material of one element: Young's modulus, Poisson ratio, thickness, density.
struct ShellSection {
  double youngs_modulus;
  double poisson_ratio;
  double thickness;
  double density;
};

struct ElementBatch {
  ElementType type;
  std::int64_t count;
  const int* connectivity;
  const double* positions;
  const ShellSection* sections;
};

// Stiffness blocks of each element. With rotations, blocks are R K R^T per quadrature point
// and `forces` (may be null without rotations) receives the corrective term
// R K (I - R^T) X0 of eq. 48, to be added to the right-hand side.
void shell_element_stiffness(const ElementBatch& batch, const double* rotations, double* blocks, double* forces,
                             Execution execution = Execution::parallel);

// shell_element_stiffness with its rest-geometry part evaluated once: shell_element_rest_rows
// writes per (element e, point q), at (e nq + q) * shell_element_rest_row_stride, the weight
// w j0 and the membrane then bending rows of every basis function (npe x 9 each, the
// unrotated B of report eqs. 32-33); shell_element_stiffness_cached reads them instead of
// evaluating the geometry, and is bitwise shell_element_stiffness (same arithmetic).
std::int64_t shell_element_rest_row_stride(const ElementBatch& batch);  // doubles per point
void shell_element_rest_rows(const ElementBatch& batch, double* rest_rows, Execution execution = Execution::parallel);
void shell_element_stiffness_cached(const ElementBatch& batch, const double* rest_rows, const double* rotations,
                                    double* blocks, double* forces, Execution execution = Execution::parallel);

// The plain serial reference form of shell_element_stiffness (per point, block by block,
// as the report writes it); equal to it to round-off (~1e-15 relative), not bitwise.
void shell_element_stiffness_reference(const ElementBatch& batch, const double* rotations, double* blocks,
                                       double* forces);

// Deformation gradient F = [a1 a2 t][A1 A2 T0]^-1 at each quadrature point, from rest and
// current node positions (#nodes x 3 each). Output #elements x nq x 9.
void shell_element_deformation_gradients(const ElementBatch& batch, const double* current_positions, double* F,
                                         Execution execution = Execution::parallel);

// Consistent mass: rho h integral N^a N^b dA per element, #elements x npe x npe (times I3).
void shell_element_mass(const ElementBatch& batch, double* mass, Execution execution = Execution::parallel);

// Integral of N^a dA times (rho h) or 1: #elements x npe each.
void shell_element_load_weights(const ElementBatch& batch, double* area_weights, double* mass_weights,
                                Execution execution = Execution::parallel);

}  // namespace dgtex::kernels

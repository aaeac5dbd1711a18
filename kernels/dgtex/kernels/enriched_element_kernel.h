#pragma once
// Element terms of texture-enriched DG shells: membrane + bending stiffness (shell report
// eqs. 32-33), consistent mass and load weights, for the local basis of enriched_basis.h
// (npe standard functions, then the enriched ones), integrated with the quadrature of
// enriched_quadrature.h. Corotated per quadrature point like shell_element_kernel.h: the
// deformation gradient includes the enriched DOFs, whose rest value is zero, so their
// share of the corrective term R K (I - R^T) X0 vanishes.
//
// Shapes (W = batch.width, points as in enriched_quadrature.h):
//   blocks #elements x W x W x 9 (block (a, b) at (a*W+b)*9), forces #elements x W x 3,
//   mass #elements x W x W (times I3), weights #elements x W, rotations and F: one 3x3
//   (row-major) per quadrature point in the order of the point list. Padding slots are 0.
// current (deformation gradients): #(nodes + virtual nodes) x 3, indexed by the global
// nodes of enriched_global_nodes: current positions of nodes, then the current values of
// the enriched DOFs. One element per work item: the parallel form equals the serial one
// bitwise.
#include <cstdint>

#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/forall.h"

namespace dgtex::kernels {

struct EnrichedQuadrature {
  const std::int64_t* start;  // #elements + 1
  const double* points;       // (xi1, xi2, reference weight) per point
};

void enriched_element_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                const double* rotations, double* blocks, double* forces,
                                Execution execution = Execution::parallel);

void enriched_element_deformation_gradients(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                            const double* current, double* F,
                                            Execution execution = Execution::parallel);

void enriched_element_mass(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature, double* mass,
                           Execution execution = Execution::parallel);

void enriched_element_load_weights(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                   double* area_weights, double* mass_weights,
                                   Execution execution = Execution::parallel);

}  // namespace dgtex::kernels

#pragma once
// Which enriched nodes add something to the basis (thesis App. A.2).
//
// At node a the standard basis function N^a and the shifted enrichments
// (H_i - H_i(xi^a)) N^a of the functions with a in N_i are linearly independent exactly
// when {1, H_i, ...} is, restricted to the support of N^a (the elements incident to a;
// N^a vanishes only on lines there). App. A.2 shows this holds while every cut splits a
// component. Two segments that continue one crack (consecutive segments of one cut, a
// cut starting where another ends, a V of two cuts meeting at their ends) do not: on a
// node whose support the crack crosses completely both are the same +-1 Heaviside, so
// their enrichments coincide and the mass and stiffness matrices are singular. Such a
// node keeps the enrichment of the function that came first and drops the later ones;
// the basis spans the same space (the canonical one, App. A.2) with fewer DOFs.
//
// Test: Gram-Schmidt at each node over the active texel centres of its support, in
// function order, starting from the constant 1. A function whose residual after removing
// 1 and the earlier kept functions has an RMS below `tolerance` (H is O(1): +-1 data) does
// not keep the node. Exact dependencies (constant +-1 components, which the Laplace solve
// sets exactly) leave round-off; near dependencies (fragments, cut pieces running close
// to each other) are left to the mass test of ShellModel::set_enrichments. A support whose
// Gram matrix shows every function independent with a margin over the worst-case rounding
// skips the Gram-Schmidt (the same answer: all kept; the slinky's test 10 -> 4 ms a step).
#include <vector>

#include "dgtex/enrichment_function.h"
#include "dgtex/mesh.h"

namespace dgtex {

// For each function (in the given order) its nodes of N_i that add to the span at that
// node. node_elements[a]: the elements incident to node a; every one of them must have a
// texture in each function with a in N_i (throws std::invalid_argument naming the
// function, node and element otherwise).
std::vector<std::vector<int>> independent_enriched_nodes(const std::vector<std::vector<int>>& node_elements,
                                                         const std::vector<EnrichmentFunction>& functions,
                                                         double tolerance = 1e-6);

// f with N_i replaced by `nodes` (a sorted subset) and Omega_i by the elements of f that
// touch one of them.
EnrichmentFunction restrict_enriched_nodes(const Mesh& mesh, const EnrichmentFunction& f, std::vector<int> nodes);

}  // namespace dgtex

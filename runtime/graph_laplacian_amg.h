#pragma once
// Internal to the enrichment Laplace solve (mesh_texel_laplace.cpp): conjugate gradients
// preconditioned by smoothed-aggregation algebraic multigrid, for texel graphs that no
// planar patch or texel lattice holds (tri6 cells split sheared, rings of tri6 cells), where
// the tile multigrid does not apply. Why: CHOLMOD took ~40 ms for each of the fracture
// scene's 20k-unknown texel graphs (AMD's analysis half of it; the scene's cells were split
// sheared until session 45); a nested-dissection order instead of AMD was tried and
// rejected (1.3-1.4x AMD's fill on grids, 2.5-3x its flops on the fracture graphs).
//
// The hierarchy: aggregates grown greedily from the graph's rows in order (a node and its
// strong neighbours, then the rest joined to an adjacent aggregate), so an aggregate never
// spans a wall; the tentative interpolation is piecewise constant (a Laplacian's near
// null space), smoothed by one damped Jacobi step; coarse operators are Galerkin products;
// the coarsest level is factored densely. One V(1,1)-cycle of symmetric Gauss-Seidel
// (forward before, backward after the coarse correction) preconditions CG, so the
// preconditioner is symmetric positive definite. Serial and deterministic: the same bits on
// any thread count, and concurrent calls on different systems need no lock.
#include <Eigen/SparseCore>

namespace dgtex::detail {

using SparseRows = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

struct GraphAmgStats {
  int iterations = 0;           // CG iterations
  double relative_residual = 0;  // ||b - A x|| / ||b|| reached (the recursive residual)
  int levels = 0;
  double setup_ms = 0;
};

// Solves a x = b from x's values to ||b - a x|| <= tolerance * ||b||. a: symmetric positive
// definite with non-positive off-diagonal entries (a graph Laplacian whose every component
// touches Dirichlet data), every row with its diagonal entry, compressed
// (std::invalid_argument otherwise). Throws std::runtime_error when max_iterations do not
// reach the tolerance or a coarse level does not factor.
GraphAmgStats solve_graph_laplacian_amg(const SparseRows& a, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                        double tolerance, int max_iterations);

}  // namespace dgtex::detail

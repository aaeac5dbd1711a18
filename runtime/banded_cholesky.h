#pragma once
// Internal to the Laplace multigrid: the Cholesky factorisation of its coarsest level when
// coarsening stopped early (a channel narrower than the coarse spacing, e.g. the spiral: 32 x
// 32 nodes at T = 256). Numbered row by row, a grid operator's unknowns couple only within
// one grid row plus one node of each other, so the factor keeps that band: n * bw^2 / 2
// multiply-adds, ~0.5 M for 1024 unknowns (bandwidth 33), where CHOLMOD's analysis alone cost
// more (spiral T = 256 setup, 1 thread: 4.1 ms with CHOLMOD). Serial, so the factor and every
// solve are the same bits for any thread count and schedule (CHOLMOD's METIS ordering draws
// from a process-global random generator).
#include <vector>

#include <Eigen/SparseCore>

#include "multigrid_buffer.h"

namespace dgtex::detail {

class BandedCholesky {
 public:
  // Half bandwidth of a symmetric matrix: the largest |row - column| of a nonzero.
  static int bandwidth(const Eigen::SparseMatrix<double>& a);
  // Starts an n x n matrix of half bandwidth bw, all zero; set its lower triangle with
  // set_lower(), then factorize().
  void reset(int n, int bw);
  // A(row, column) = value, for column <= row <= column + bw.
  void set_lower(int row, int column, double value) {
    lower_[static_cast<std::size_t>(column) * stride_ + (row - column)] = value;
  }
  // Factors the matrix set since reset(); false if a pivot is not positive.
  bool factorize();
  // reset(), set_lower() and factorize() for the lower triangle of a (both may be given);
  // the tests' entry point (the multigrid fills the band from its stencil).
  bool factorize(const Eigen::SparseMatrix<double>& a);
  // x = A^-1 b.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  int size() const { return n_; }

  // The numeric loops work in chunks of this many entries over zero padding.
  static constexpr int chunk = 8;

 private:
  int n_ = 0, bw_ = 0, stride_ = 0;
  // Column j: L(j + d, j) at j * stride + d for d = 0 .. bw, then zeros (stride = bw + chunk).
  // Cached blocks (a hierarchy is built per solve; fresh pages cost ~50 us at spiral T = 256).
  MultigridBuffer lower_;
  MultigridBuffer rows_;           // row j: L(j, j - bw' + e) at j * bw' + e (bw' = bw rounded up)
  MultigridBuffer inverse_pivot_;  // 1 / L(j, j)
};

}  // namespace dgtex::detail

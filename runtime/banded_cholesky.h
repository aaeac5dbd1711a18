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

namespace dgtex::detail {

class BandedCholesky {
 public:
  // Half bandwidth of a symmetric matrix: the largest |row - column| of a nonzero.
  static int bandwidth(const Eigen::SparseMatrix<double>& a);
  // Factors the SPD matrix a (both triangles or the lower one given); false if a pivot is
  // not positive.
  bool factorize(const Eigen::SparseMatrix<double>& a);
  // x = A^-1 b.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  int size() const { return n_; }

 private:
  int n_ = 0, bw_ = 0;
  std::vector<double> band_;  // row i: L(i, i - bw) .. L(i, i), entries left of column 0 unused
  double& at(int i, int j) { return band_[static_cast<std::size_t>(i) * (bw_ + 1) + (j - i + bw_)]; }
  double at(int i, int j) const { return band_[static_cast<std::size_t>(i) * (bw_ + 1) + (j - i + bw_)]; }
};

}  // namespace dgtex::detail

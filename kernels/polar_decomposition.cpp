#include "dgtex/kernels/polar_decomposition.h"

#include <Eigen/Dense>

namespace dgtex::kernels {

void polar_rotation(const double F[9], double R[9]) {
  using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  const Mat3 f = Eigen::Map<const Mat3>(F);
  Eigen::JacobiSVD<Mat3> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 u = svd.matrixU();
  const Mat3 v = svd.matrixV();
  // Flip the axis of the smallest singular value if needed to keep a proper rotation.
  if ((u * v.transpose()).determinant() < 0) u.col(2) = -u.col(2);
  Eigen::Map<Mat3> rotation(R);
  rotation = u * v.transpose();
}

void polar_decomposition_batch(std::int64_t count, const double* F, double* R, Execution execution) {
  forall(count, [&](std::int64_t i) { polar_rotation(F + 9 * i, R + 9 * i); }, execution);
}

}  // namespace dgtex::kernels

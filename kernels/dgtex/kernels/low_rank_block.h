#pragma once
// A 3x3 block given by low-rank factors: B = sum_k l_k r_k^T over `rank` (even) pairs of
// 3-vectors, l_k at L + 3k and r_k at R + 3k. The terms are summed two at a time,
// B += l_2m r_2m^T + l_2m+1 r_2m+1^T, the order of the shell edge kernel (one point's
// penalty/consistency term and its symmetry term), so a block formed here from
// shell_edge_factors equals shell_edge_stiffness_merged's block bitwise.
// Kernel conventions: dgtex/kernels/forall.h. Units: those of the factors' product.
namespace dgtex::kernels {

inline void low_rank_block(int rank, const double* L, const double* R, double out[9]) {
  double blk[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (int k = 0; k < rank; k += 2) {
    const double* l0 = L + 3 * k;
    const double* l1 = l0 + 3;
    const double* r0 = R + 3 * k;
    const double* r1 = r0 + 3;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) blk[i * 3 + j] += l0[i] * r0[j] + l1[i] * r1[j];
  }
  for (int i = 0; i < 9; ++i) out[i] = blk[i];
}

}  // namespace dgtex::kernels

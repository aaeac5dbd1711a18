#pragma once
// Products of a matrix of 3x3 blocks, stored by block rows (the BlockAssembly pattern: CSR
// over node rows, 9 values a block, row-major), with vectors of 3 values a node: the
// corotated step's K u and its PCG's A p, every iteration.
//
// Why its own kernel: a block of 9 products summed into 3 scalar chains waits on the add
// latency (the accordion's fully coupled 147 nodes: 47 us a product, 5 products a step).
// Here the 9 entries of a block are one 8-lane vector and one scalar, the blocks of a row
// are dealt to 4 independent sums, and the vectors come spread, 9 values a node
// (spread_block_vector: x[3c + m mod 3] at 9c + m), so that a block and its x are both
// contiguous: 1.8-2x the scalar loop on AVX-512.
//
// Order of the sums (every path, and the references, round exactly alike: no FMA
// contraction, lanes never mix): in row r the block k = row_start[r] + q goes to stream
// q mod 4; per stream and entry m (0..8), s[m] = sum over its blocks in order of
// b_k[m] * x[3 c_k + m mod 3], from 0; t[m] = (s0[m] + s1[m]) + (s2[m] + s3[m]); and
// y[3r + i] = (t[3i] + t[3i + 1]) + t[3i + 2]. Scalar blocks (m_k I: an isotropic mass):
// per stream s[i] = sum of m_k * x[3 c_k + i], y[3r + i] = (s0[i] + s1[i]) + (s2[i] + s3[i]).
// Rows are independent: any split of the rows over threads gives the same bits.
// Keeps nothing; thread-safe on distinct outputs. Units: the blocks' times the vector's.
#include <cstdint>

#include "dgtex/kernels/vector_path.h"

namespace dgtex::kernels {

struct BlockRows {
  const std::int64_t* row_start = nullptr;  // rows + 1 offsets into the blocks
  const int* column = nullptr;              // node column of each block
};

// spread[9c + m] = x[3c + m % 3] for nodes c < nodes (9 x nodes values).
void spread_block_vector(std::int64_t nodes, const double* x, double* spread);

// y[3r + i] = (sum_k B_k x_{c_k})[i] for rows r in [first, last), x given spread.
void block_rows_product(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                        const double* spread, double* y, VectorPath path = VectorPath::best);
// y = K x as above and y_scalars = S x (scalar_rows_product's sums) in one pass, for K and S
// in the same pattern (the PCG's A p = a M p + b K p with an isotropic mass M).
void block_and_scalar_rows_product(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                                   const double* scalars, const double* spread, double* y, double* y_scalars,
                                   VectorPath path = VectorPath::best);
// Two vectors in one pass over the blocks (bitwise two block_rows_product calls).
void block_rows_product_pair(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                             const double* spread1, const double* spread2, double* y1, double* y2,
                             VectorPath path = VectorPath::best);
// y[3r + i] = sum_k m_k x_{c_k}[i]: blocks m_k I given by their scalars.
void scalar_rows_product(BlockRows rows, std::int64_t first, std::int64_t last, const double* scalars,
                         const double* spread, double* y, VectorPath path = VectorPath::best);

// The same sums entry by entry, from x itself (not spread): the references of the paths.
void block_rows_product_reference(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                                  const double* x, double* y);
void scalar_rows_product_reference(BlockRows rows, std::int64_t first, std::int64_t last, const double* scalars,
                                   const double* x, double* y);

}  // namespace dgtex::kernels

#pragma once
// For the enriched kernels: G += A^T A for a block of stacked rows A (the strain rows
// of several quadrature points), upper part only, and G += A^T B (accumulate_product),
// with register tiles and a code path per instruction set (AVX-512, AVX2, baseline
// x86-64 (the AVX2 path needs FMA); chosen at run time). Every entry (i, j >= i) is its own
// sum over the rows in order, started from 0, each product added by one fused multiply-add
// (rounded once), and then added to G (or stored, `overwrite`): every path and the
// references round exactly alike, so results depend neither on the machine's vector unit
// nor on the tile shape. Entries below the diagonal are scratch (never read).
// Shapes: A is rows x cols, G cols x cols, both row-major with row stride cols; cols must
// be a multiple of gram_column_multiple (pad A with zero columns). Thread-safe on distinct
// outputs; keeps nothing. Units: those of the rows' products.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "dgtex/kernels/vector_path.h"

namespace dgtex::kernels {

constexpr int gram_column_multiple = 8;

// path: the instruction-set path (vector_path.h); every path gives the same bits.
void accumulate_gram_upper(int rows, int cols, const double* A, double* G, bool overwrite,
                           VectorPath path = VectorPath::best);

// G += A^T B for blocks of rows A and B (rows x cols each, row-major, cols a multiple of
// gram_column_multiple: pad with zero columns), G cols x cols with row stride cols.
// upper: only the entries (i, j >= i) are summed (those below are scratch, as above; for
// products known to be symmetric), else all. accumulate_gram_upper is the upper A^T A.
void accumulate_product(int rows, int cols, const double* A, const double* B, double* G, bool overwrite,
                        bool upper, VectorPath path = VectorPath::best);

// Several Gram sums of the same rows with per-point weights, upper entries only:
//   G_k += sum_p w_pk sum_r a_pr a_pr^T   (k < count, r < rows_per_point),
// A holding each point's rows_per_point rows in turn (points x rows_per_point rows of cols,
// row-major), weights point by point (points x count). Why: the bending rows of a curved
// element's point enter six sums of the frame split (weights t_k t_l of the rotated normal),
// and one product of the point's rows per entry, scaled into each sum, costs about half of
// six products of scaled rows. Each entry (i, j >= i): per point in order, P = the sum from
// 0 over its rows in order of a_ri a_rj, then acc_k += w_pk P, from 0 (every product added
// by a fused multiply-add); finally stored (overwrite[k]) or added. Every path rounds alike,
// as above; entries below the diagonal are scratch. Cols a multiple of
// gram_column_multiple.
constexpr int max_weighted_grams = 6;
void accumulate_weighted_grams(int points, int rows_per_point, int cols, const double* A, const double* weights,
                               int count, double* const* G, const bool* overwrite, VectorPath path = VectorPath::best);
void accumulate_weighted_grams_reference(int points, int rows_per_point, int cols, const double* A,
                                         const double* weights, int count, double* const* G, const bool* overwrite);

// out[j] += (s * scales[j]) * g[j] for j < count, the add fused (the scaled gather of a G
// row into K).
void add_scaled_row(int count, double s, const double* scales, const double* g, double* out,
                    VectorPath path = VectorPath::best);

// The same sums, one entry at a time (the reference of the tiled paths).
void accumulate_gram_upper_reference(int rows, int cols, const double* A, double* G, bool overwrite);
void accumulate_product_reference(int rows, int cols, const double* A, const double* B, double* G, bool overwrite,
                                  bool upper);

// A = sum_r v_r v_r^T over rows v_r of length n (the API of SymmetricAccumulator), summed
// by accumulate_gram_upper in fixed blocks of `block_rows` rows (fewer when the caller knows
// there are fewer rows in all: the same sums): the result depends only on the row sequence,
// not on threads or the instruction set. Nothing is zero-filled beyond the row padding (the
// first block stores). One instance per thread.
class GramAccumulator {
 public:
  static constexpr int block_rows = 96;

  explicit GramAccumulator(int n, std::int64_t expected_rows = block_rows)
      : cols_(std::max(1, (n + gram_column_multiple - 1) / gram_column_multiple) * gram_column_multiple),
        capacity_(static_cast<int>(std::max<std::int64_t>(1, std::min<std::int64_t>(block_rows, expected_rows)))),
        rows_data_(static_cast<std::size_t>(capacity_) * cols_, 0.0),
        sum_(new double[static_cast<std::size_t>(cols_) * cols_]) {}

  // The next row (n entries, all to be written); commit it with push().
  double* next() { return rows_data_.data() + static_cast<std::size_t>(rows_) * cols_; }
  void push() {
    if (++rows_ == capacity_) flush();
  }
  void flush() {
    if (rows_ > 0) accumulate_gram_upper(rows_, cols_, rows_data_.data(), sum_.get(), !written_);
    written_ = written_ || rows_ > 0;
    rows_ = 0;
  }
  // Entry (i, j) of the sum (call flush() first).
  double operator()(int i, int j) const {
    if (!written_) return 0.0;
    return i <= j ? sum_[static_cast<std::size_t>(i) * cols_ + j] : sum_[static_cast<std::size_t>(j) * cols_ + i];
  }

 private:
  int cols_, capacity_;
  int rows_ = 0;
  bool written_ = false;
  std::vector<double> rows_data_;  // padding columns stay 0
  std::unique_ptr<double[]> sum_;
};

}  // namespace dgtex::kernels

#pragma once
// Accumulates A = sum_r v_r v_r^T (v_r: rows of length n) in chunks of rows, upper
// triangle only, so the result is exactly symmetric. The summation order depends only on the row sequence, so
// equal inputs give bitwise equal results on any thread.
// SymmetricAccumulator owns its n x n sum and a chunk of rows; one instance per thread
// (not thread-safe). Values keep the units of the rows' products.
#include <algorithm>
#include <vector>

namespace dgtex::kernels {

class SymmetricAccumulator {
 public:
  static constexpr int chunk = 96;

  explicit SymmetricAccumulator(int n)
      : n_(n), rows_data_(static_cast<std::size_t>(n) * chunk), sum_(static_cast<std::size_t>(n) * n, 0.0) {}

  int size() const { return n_; }
  // The next row (n entries, all to be written); commit it with push().
  double* next() { return rows_data_.data() + static_cast<std::size_t>(rows_) * n_; }
  void push() {
    if (++rows_ == chunk) flush();
  }
  void flush() {
    // Row i of the upper triangle stays in cache while the chunk's rows update it; the
    // inner loop runs over contiguous j (vectorises without reassociating any sum).
    for (int i = 0; i < n_; ++i) {
      double* out = sum_.data() + static_cast<std::size_t>(i) * n_;
      for (int r = 0; r < rows_; ++r) {
        const double* row = rows_data_.data() + static_cast<std::size_t>(r) * n_;
        const double a = row[i];
        if (a == 0) continue;
        for (int j = i; j < n_; ++j) out[j] += a * row[j];
      }
    }
    rows_ = 0;
  }
  // Entry (i, j) of the sum (call flush() first).
  double operator()(int i, int j) const {
    return i <= j ? sum_[static_cast<std::size_t>(i) * n_ + j] : sum_[static_cast<std::size_t>(j) * n_ + i];
  }

 private:
  int n_;
  int rows_ = 0;
  std::vector<double> rows_data_;
  std::vector<double> sum_;
};

}  // namespace dgtex::kernels

#include "dgtex/sparse_cholesky.h"

#include <cholmod.h>

#include <cstring>
#include <vector>

// Single-precision BLAS (Fortran interface of the system BLAS, OpenBLAS on Debian).
extern "C" {
void sgemv_(const char* trans, const int* m, const int* n, const float* alpha, const float* a, const int* lda,
            const float* x, const int* incx, const float* beta, float* y, const int* incy);
void strsv_(const char* uplo, const char* trans, const char* diag, const int* n, const float* a, const int* lda,
            float* x, const int* incx);
}

namespace dgtex {

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_sparse* matrix = nullptr;
  cholmod_factor* factor = nullptr;
  std::vector<float> single_values;  // supernodal L in float (same layout as factor->x)
  mutable std::vector<float> work, gathered;

  Impl() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.print = 0;
    common.error_handler = nullptr;
  }
  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common);
    if (matrix) cholmod_free_sparse(&matrix, &common);
    cholmod_finish(&common);
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;

bool SparseCholesky::analyzed() const { return impl_->factor != nullptr; }

void SparseCholesky::analyze(int n, const std::vector<int>& column_start, const std::vector<int>& row_index) {
  Impl& m = *impl_;
  if (m.factor) cholmod_free_factor(&m.factor, &m.common);
  if (m.matrix) cholmod_free_sparse(&m.matrix, &m.common);
  n_ = n;
  const size_t nnz = row_index.size();
  // stype -1: only the lower triangle is stored and used.
  m.matrix = cholmod_allocate_sparse(n, n, nnz, /*sorted=*/1, /*packed=*/1, /*stype=*/-1, CHOLMOD_REAL, &m.common);
  if (!m.matrix) throw std::runtime_error("CHOLMOD: out of memory allocating a " + std::to_string(n) + "x" + std::to_string(n) + " matrix");
  std::memcpy(m.matrix->p, column_start.data(), sizeof(int) * (n + 1));
  std::memcpy(m.matrix->i, row_index.data(), sizeof(int) * nnz);
  std::memset(m.matrix->x, 0, sizeof(double) * nnz);
  m.factor = cholmod_analyze(m.matrix, &m.common);
  if (!m.factor || m.common.status < CHOLMOD_OK)
    throw std::runtime_error("CHOLMOD: symbolic analysis failed (status " + std::to_string(m.common.status) + ")");
}

void SparseCholesky::factorize(const std::vector<double>& values) {
  Impl& m = *impl_;
  if (!m.factor) throw std::logic_error("SparseCholesky::factorize called before analyze");
  if (values.size() != m.matrix->nzmax) throw std::invalid_argument("SparseCholesky::factorize: value count does not match the pattern");
  std::memcpy(m.matrix->x, values.data(), sizeof(double) * values.size());
  cholmod_factorize(m.matrix, m.factor, &m.common);
  if (m.common.status == CHOLMOD_NOT_POSDEF || m.factor->minor < static_cast<size_t>(n_))
    throw NotPositiveDefinite("matrix not positive definite (non-positive pivot at column " +
                                  std::to_string(m.factor->minor) + " of " + std::to_string(n_) + ")",
                              static_cast<int>(m.factor->minor));
  if (m.common.status < CHOLMOD_OK)
    throw std::runtime_error("CHOLMOD: numeric factorisation failed (status " + std::to_string(m.common.status) + ")");
}

void SparseCholesky::solve(const std::vector<double>& b, std::vector<double>& x) const {
  Impl& m = *impl_;
  cholmod_dense* rhs = cholmod_allocate_dense(n_, 1, n_, CHOLMOD_REAL, &m.common);
  std::memcpy(rhs->x, b.data(), sizeof(double) * n_);
  cholmod_dense* sol = cholmod_solve(CHOLMOD_A, m.factor, rhs, &m.common);
  if (!sol) {
    cholmod_free_dense(&rhs, &m.common);
    throw std::runtime_error("CHOLMOD: solve failed (status " + std::to_string(m.common.status) + ")");
  }
  x.resize(n_);
  std::memcpy(x.data(), sol->x, sizeof(double) * n_);
  cholmod_free_dense(&sol, &m.common);
  cholmod_free_dense(&rhs, &m.common);
}

void SparseCholesky::copy_factor_to_single_precision() {
  Impl& m = *impl_;
  const cholmod_factor* f = m.factor;
  if (!f || !f->is_super || f->xtype != CHOLMOD_REAL || f->itype != CHOLMOD_INT)
    throw std::logic_error("SparseCholesky::copy_factor_to_single_precision needs a real supernodal factor (call factorize first)");
  const double* x = static_cast<const double*>(f->x);
  m.single_values.resize(f->xsize);
  for (size_t i = 0; i < f->xsize; ++i) m.single_values[i] = static_cast<float>(x[i]);
}

void SparseCholesky::solve_single_precision(const std::vector<double>& b, std::vector<double>& x) const {
  const Impl& m = *impl_;
  const cholmod_factor* f = m.factor;
  if (!f || m.single_values.size() != f->xsize)
    throw std::logic_error("SparseCholesky::solve_single_precision called without copy_factor_to_single_precision");
  const int* super = static_cast<const int*>(f->super);
  const int* pi = static_cast<const int*>(f->pi);
  const int* px = static_cast<const int*>(f->px);
  const int* rows = static_cast<const int*>(f->s);
  const int* perm = static_cast<const int*>(f->Perm);
  const float* L = m.single_values.data();
  const int nsuper = static_cast<int>(f->nsuper);
  std::vector<float>& y = m.work;
  std::vector<float>& t = m.gathered;
  y.resize(n_);
  for (int k = 0; k < n_; ++k) y[k] = static_cast<float>(b[perm[k]]);  // L L^T = P A P^T
  const int one = 1;
  const float plus = 1, minus = -1, zero = 0;
  // Per supernode: columns k1..k2-1, a dense nrow x ncol column-major block whose first
  // ncol rows are the diagonal triangle and whose other rows are listed in `rows`.
  for (int s = 0; s < nsuper; ++s) {  // forward, L y = P b
    const int k1 = super[s], ncol = super[s + 1] - k1, nrow = pi[s + 1] - pi[s], below = nrow - ncol;
    const float* X = L + px[s];
    strsv_("L", "N", "N", &ncol, X, &nrow, y.data() + k1, &one);
    if (below <= 0) continue;
    t.resize(below);
    sgemv_("N", &below, &ncol, &plus, X + ncol, &nrow, y.data() + k1, &one, &zero, t.data(), &one);
    const int* r = rows + pi[s] + ncol;
    for (int i = 0; i < below; ++i) y[r[i]] -= t[i];
  }
  for (int s = nsuper - 1; s >= 0; --s) {  // backward, L^T z = y
    const int k1 = super[s], ncol = super[s + 1] - k1, nrow = pi[s + 1] - pi[s], below = nrow - ncol;
    const float* X = L + px[s];
    if (below > 0) {
      t.resize(below);
      const int* r = rows + pi[s] + ncol;
      for (int i = 0; i < below; ++i) t[i] = y[r[i]];
      sgemv_("T", &below, &ncol, &minus, X + ncol, &nrow, t.data(), &one, &plus, y.data() + k1, &one);
    }
    strsv_("L", "T", "N", &ncol, X, &nrow, y.data() + k1, &one);
  }
  x.resize(n_);
  for (int k = 0; k < n_; ++k) x[perm[k]] = y[k];
}

std::int64_t SparseCholesky::factor_nonzeros() const {
  const cholmod_factor* f = impl_->factor;
  if (!f) return 0;
  if (f->is_super) return static_cast<std::int64_t>(f->xsize);
  return static_cast<std::int64_t>(f->nzmax);
}

}  // namespace dgtex

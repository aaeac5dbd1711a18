#include "dgtex/sparse_cholesky.h"

#include <cholmod.h>

#include <cstring>

namespace dgtex {

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_sparse* matrix = nullptr;
  cholmod_factor* factor = nullptr;

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

std::int64_t SparseCholesky::factor_nonzeros() const {
  const cholmod_factor* f = impl_->factor;
  if (!f) return 0;
  if (f->is_super) return static_cast<std::int64_t>(f->xsize);
  return static_cast<std::int64_t>(f->nzmax);
}

}  // namespace dgtex

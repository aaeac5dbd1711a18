#include "dgtex/sparse_cholesky.h"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "cholmod_lock.h"
#include "dgtex/kernels/threads_busy_beside.h"
#include "dense_cholesky.h"

namespace dgtex {

namespace {
// Below this many unknowns the subtrees are solved one after another (same arithmetic):
// waking the OpenMP team costs more than the solve.
constexpr int parallel_solve_size = 2000;

// Dense kernels of the single-precision solve on one supernode: X is its column-major
// nrow x ncol block (leading dimension nrow), the first ncol rows the diagonal triangle.
// Plain loops rather than BLAS: Debian's serial OpenBLAS is not safe for concurrent calls,
// and the subtrees below are solved concurrently. Sums run over 8 fixed lanes so that the
// compiler vectorises them without reassociating (the order is the code's, not the
// compiler's), so results do not depend on the build's vector width.
float lane_dot(const float* a, const float* b, int n) {
  float lane[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int i = 0;
  for (; i + 8 <= n; i += 8)
    for (int l = 0; l < 8; ++l) lane[l] += a[i + l] * b[i + l];
  for (int l = 0; i < n; ++i, ++l) lane[l] += a[i] * b[i];
  return ((lane[0] + lane[4]) + (lane[1] + lane[5])) + ((lane[2] + lane[6]) + (lane[3] + lane[7]));
}

// y = X_tri^-1 y, then below[i] = sum_j X[ncol + i, j] y[j].
void forward_supernode(const float* X, int nrow, int ncol, float* y, float* below) {
  for (int j = 0; j < ncol; ++j) {
    const float* column = X + static_cast<std::size_t>(j) * nrow;
    const float yj = y[j] / column[j];
    y[j] = yj;
    for (int i = j + 1; i < ncol; ++i) y[i] -= column[i] * yj;
  }
  const int rows_below = nrow - ncol;
  std::fill(below, below + rows_below, 0.0f);
  for (int j = 0; j < ncol; ++j) {
    const float* column = X + static_cast<std::size_t>(j) * nrow + ncol;
    const float yj = y[j];
    for (int i = 0; i < rows_below; ++i) below[i] += column[i] * yj;
  }
}

// y = X_tri^-T (y - X_below^T t), t the solution at the rows below.
void backward_supernode(const float* X, int nrow, int ncol, float* y, const float* t) {
  const int rows_below = nrow - ncol;
  for (int j = 0; j < ncol; ++j) y[j] -= lane_dot(X + static_cast<std::size_t>(j) * nrow + ncol, t, rows_below);
  for (int j = ncol - 1; j >= 0; --j) {
    const float* column = X + static_cast<std::size_t>(j) * nrow;
    y[j] = (y[j] - lane_dot(column + j + 1, y + j + 1, ncol - j - 1)) / column[j];
  }
}

}  // namespace

// Parallel schedule of the single-precision solve over the supernodal elimination tree:
// disjoint subtrees ("tasks", each a contiguous range of postordered supernodes) are
// solved concurrently; the supernodes above them ("top": the separators) serially. In
// the forward solve a task's updates of top rows go to its own accumulator, added to y in
// task order, so the arithmetic is fixed by the factor's structure, not by the threads.
struct SolveSchedule {
  std::vector<int> task_first, task_last;  // supernode ranges, in postorder
  std::vector<int> top;                    // top supernodes, ascending (postorder)
  std::vector<int> top_slot;               // per row of L: its index among top rows, or -1
  int top_rows = 0;
};

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_sparse* matrix = nullptr;
  cholmod_factor* factor = nullptr;
  std::vector<float> single_values;  // supernodal L in float (same layout as factor->x)
  SolveSchedule schedule;            // built with the first single-precision copy
  std::unique_ptr<detail::DenseCholesky> dense;  // instead of CHOLMOD for small systems
  mutable std::vector<float> work, top_updates;  // y; per task x top rows accumulators
  mutable std::vector<std::vector<float>> gathered;  // per task (forward, backward) scratch
  mutable std::vector<float> top_scratch;            // the same for the top supernodes
  // tril(P A P^T) (P the analysis's fill-reducing order) as cholmod_super_numeric takes it,
  // and per entry the index of its value in the caller's lower triangle. Built with the
  // analysis, so that a factorisation gathers the values straight into it:
  // cholmod_factorize forms it anew from a lower-stored A with two transposes each call.
  cholmod_sparse* permuted = nullptr;
  std::vector<int> permuted_source;

  Impl() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.print = 0;
    common.error_handler = nullptr;
  }
  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common);
    if (matrix) cholmod_free_sparse(&matrix, &common);
    if (permuted) cholmod_free_sparse(&permuted, &common);
    cholmod_finish(&common);
  }
};

SparseCholesky::SparseCholesky(int dense_max_unknowns)
    : impl_(std::make_unique<Impl>()), dense_max_unknowns_(dense_max_unknowns) {}
SparseCholesky::~SparseCholesky() = default;

bool SparseCholesky::factors_densely(int n, std::int64_t lower_nonzeros, int dense_max_unknowns) {
  const double lower_entries = 0.5 * n * (n + 1.0);
  return n <= dense_max_unknowns && (n <= 128 || static_cast<double>(lower_nonzeros) >= 0.25 * lower_entries);
}

bool SparseCholesky::analyzed() const { return impl_->factor != nullptr || impl_->dense != nullptr; }
bool SparseCholesky::dense() const { return impl_->dense != nullptr; }

void SparseCholesky::analyze(int n, const std::vector<int>& column_start, const std::vector<int>& row_index) {
  Impl& m = *impl_;
  if (m.factor) cholmod_free_factor(&m.factor, &m.common);
  if (m.matrix) cholmod_free_sparse(&m.matrix, &m.common);
  if (m.permuted) cholmod_free_sparse(&m.permuted, &m.common);
  m.permuted_source.clear();
  m.dense.reset();
  n_ = n;
  const size_t nnz = row_index.size();
  if (factors_densely(n, static_cast<std::int64_t>(nnz), dense_max_unknowns_)) {
    m.dense = std::make_unique<detail::DenseCholesky>();
    m.dense->set_pattern(n, column_start, row_index);
    return;
  }
  // stype -1: only the lower triangle is stored and used. The analysis reads the pattern
  // alone; values are allocated only where the factorisation reads this matrix (without
  // permuted: 8 bytes a stored entry, 1.4 MB for fracture's step matrix, 4.4 MB for the
  // cylinder's, that the usual path never touches).
  m.matrix = cholmod_allocate_sparse(n, n, nnz, /*sorted=*/1, /*packed=*/1, /*stype=*/-1, CHOLMOD_PATTERN, &m.common);
  if (!m.matrix) throw std::runtime_error("CHOLMOD: out of memory allocating a " + std::to_string(n) + "x" + std::to_string(n) + " matrix");
  std::memcpy(m.matrix->p, column_start.data(), sizeof(int) * (n + 1));
  std::memcpy(m.matrix->i, row_index.data(), sizeof(int) * nnz);
  m.schedule = SolveSchedule{};
  {
    const auto lock = detail::lock_cholmod();
    m.factor = cholmod_analyze(m.matrix, &m.common);
  }
  if (!m.factor || m.common.status < CHOLMOD_OK)
    throw std::runtime_error("CHOLMOD: symbolic analysis failed (status " + std::to_string(m.common.status) + ")");
  if (m.factor->is_super && m.factor->ordering != CHOLMOD_NATURAL) {
    build_permuted_lower();
  } else if (!cholmod_sparse_xtype(CHOLMOD_REAL, m.matrix, &m.common)) {
    throw std::runtime_error("CHOLMOD: out of memory allocating the values of a " + std::to_string(n) + "x" +
                             std::to_string(n) + " matrix");
  }
}

void SparseCholesky::build_permuted_lower() {
  Impl& m = *impl_;
  const int n = n_;
  const int* perm = static_cast<const int*>(m.factor->Perm);
  const int* column_start = static_cast<const int*>(m.matrix->p);
  const int* row_index = static_cast<const int*>(m.matrix->i);
  const int nnz = column_start[n];
  std::vector<int> position(n);  // of an unknown in the factor's order
  for (int k = 0; k < n; ++k) position[perm[k]] = k;
  // Entry t (row i >= column j) lands at (max, min) of (position[i], position[j]); its
  // rows are left unsorted within a column (the numeric factorisation scatters a column
  // through a map, in any order).
  m.permuted = cholmod_allocate_sparse(n, n, nnz, /*sorted=*/0, /*packed=*/1, /*stype=*/-1, CHOLMOD_REAL, &m.common);
  if (!m.permuted) throw std::runtime_error("CHOLMOD: out of memory allocating a " + std::to_string(n) + "x" + std::to_string(n) + " matrix");
  int* start = static_cast<int*>(m.permuted->p);
  int* rows = static_cast<int*>(m.permuted->i);
  std::fill(start, start + n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int t = column_start[j]; t < column_start[j + 1]; ++t)
      ++start[std::min(position[row_index[t]], position[j]) + 1];
  for (int c = 0; c < n; ++c) start[c + 1] += start[c];
  std::vector<int> next(start, start + n);
  m.permuted_source.resize(nnz);
  for (int j = 0; j < n; ++j)
    for (int t = column_start[j]; t < column_start[j + 1]; ++t) {
      const int a = position[row_index[t]], b = position[j];
      const int slot = next[std::min(a, b)]++;
      rows[slot] = std::max(a, b);
      m.permuted_source[slot] = t;
    }
}

void SparseCholesky::factorize(const std::vector<double>& values) {
  Impl& m = *impl_;
  if (m.dense) {
    m.dense->factorize(values);
    return;
  }
  if (!m.factor) throw std::logic_error("SparseCholesky::factorize called before analyze");
  if (values.size() != m.matrix->nzmax) throw std::invalid_argument("SparseCholesky::factorize: value count does not match the pattern");
  if (m.permuted) {
    double* x = static_cast<double*>(m.permuted->x);
    for (std::size_t k = 0; k < m.permuted_source.size(); ++k) x[k] = values[m.permuted_source[k]];
    double beta[2] = {0, 0};
    const auto lock = detail::lock_cholmod();
    detail::reserve_blas_workspace(lock);
    cholmod_super_numeric(m.permuted, nullptr, beta, m.factor, &m.common);
  } else {
    std::memcpy(m.matrix->x, values.data(), sizeof(double) * values.size());
    const auto lock = detail::lock_cholmod();
    detail::reserve_blas_workspace(lock);
    cholmod_factorize(m.matrix, m.factor, &m.common);
  }
  if (m.common.status == CHOLMOD_NOT_POSDEF || m.factor->minor < static_cast<size_t>(n_)) {
    // minor counts the factor's columns, in the fill-reducing order: the matrix's own is Perm's.
    const int minor = static_cast<int>(std::min(m.factor->minor, static_cast<size_t>(n_ - 1)));
    const int* perm = static_cast<const int*>(m.factor->Perm);
    const int column = perm ? perm[minor] : minor;
    throw NotPositiveDefinite("matrix not positive definite (non-positive pivot at column " + std::to_string(column) +
                                  " of " + std::to_string(n_) + ")",
                              column);
  }
  if (m.common.status < CHOLMOD_OK)
    throw std::runtime_error("CHOLMOD: numeric factorisation failed (status " + std::to_string(m.common.status) + ")");
}

void SparseCholesky::solve(const std::vector<double>& b, std::vector<double>& x) const {
  Impl& m = *impl_;
  if (m.dense) {
    m.dense->solve(b, x);
    return;
  }
  cholmod_dense* rhs = cholmod_allocate_dense(n_, 1, n_, CHOLMOD_REAL, &m.common);
  std::memcpy(rhs->x, b.data(), sizeof(double) * n_);
  cholmod_dense* sol = nullptr;
  {
    const auto lock = detail::lock_cholmod();
    sol = cholmod_solve(CHOLMOD_A, m.factor, rhs, &m.common);
  }
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
  if (m.dense) return m.dense->copy_factor_to_single_precision();
  const cholmod_factor* f = m.factor;
  if (!f || !f->is_super || f->xtype != CHOLMOD_REAL || f->itype != CHOLMOD_INT)
    throw std::logic_error("SparseCholesky::copy_factor_to_single_precision needs a real supernodal factor (call factorize first)");
  const double* x = static_cast<const double*>(f->x);
  m.single_values.resize(f->xsize);
  for (size_t i = 0; i < f->xsize; ++i) m.single_values[i] = static_cast<float>(x[i]);
  if (m.schedule.top_slot.empty()) build_solve_schedule();
}

void SparseCholesky::build_solve_schedule() {
  Impl& m = *impl_;
  const cholmod_factor* f = m.factor;
  const int* super = static_cast<const int*>(f->super);
  const int* pi = static_cast<const int*>(f->pi);
  const int* px = static_cast<const int*>(f->px);
  const int* rows = static_cast<const int*>(f->s);
  const int nsuper = static_cast<int>(f->nsuper);
  // Parent of a supernode: the one holding its first row below the diagonal block.
  std::vector<int> supernode_of_column(n_), parent(nsuper, -1), subtree_size(nsuper, 1);
  std::vector<double> work(nsuper);
  std::vector<std::vector<int>> children(nsuper);
  for (int s = 0; s < nsuper; ++s)
    for (int k = super[s]; k < super[s + 1]; ++k) supernode_of_column[k] = s;
  std::vector<int> roots;
  for (int s = 0; s < nsuper; ++s) {
    const int ncol = super[s + 1] - super[s], nrow = pi[s + 1] - pi[s];
    work[s] += static_cast<double>(px[s + 1] - px[s]);
    if (nrow > ncol) {
      parent[s] = supernode_of_column[rows[pi[s] + ncol]];
      children[parent[s]].push_back(s);
      work[parent[s]] += work[s];  // postorder: children come first
      subtree_size[parent[s]] += subtree_size[s];
    } else {
      roots.push_back(s);
    }
  }
  // Split the heaviest subtree into its children until none holds more than 1/4 of the
  // work: enough tasks to balance 2-4 threads, a fixed rule (the same for any count).
  double total = 0;  // work[s] is its subtree's by now
  for (int root : roots) total += work[root];
  std::vector<int> tasks = roots;
  std::vector<char> is_top(nsuper, 0);
  for (;;) {
    auto heaviest = std::max_element(tasks.begin(), tasks.end(), [&](int a, int b) { return work[a] < work[b]; });
    if (heaviest == tasks.end() || work[*heaviest] <= total / 4 || children[*heaviest].empty()) break;
    const int s = *heaviest;
    tasks.erase(heaviest);
    is_top[s] = 1;
    tasks.insert(tasks.end(), children[s].begin(), children[s].end());
  }
  std::sort(tasks.begin(), tasks.end());
  SolveSchedule schedule;
  for (int root : tasks) {
    schedule.task_first.push_back(root - subtree_size[root] + 1);
    schedule.task_last.push_back(root);
  }
  schedule.top_slot.assign(n_, -1);
  for (int s = 0; s < nsuper; ++s)
    if (is_top[s]) {
      schedule.top.push_back(s);
      for (int k = super[s]; k < super[s + 1]; ++k) schedule.top_slot[k] = schedule.top_rows++;
    }
  m.schedule = std::move(schedule);
}

void SparseCholesky::solve_single_precision(const std::vector<double>& b, std::vector<double>& x) const {
  const Impl& m = *impl_;
  if (m.dense) {
    m.dense->solve_single_precision(b, x);
    return;
  }
  const cholmod_factor* f = m.factor;
  if (!f || m.single_values.size() != f->xsize)
    throw std::logic_error("SparseCholesky::solve_single_precision called without copy_factor_to_single_precision");
  const int* super = static_cast<const int*>(f->super);
  const int* pi = static_cast<const int*>(f->pi);
  const int* px = static_cast<const int*>(f->px);
  const int* rows = static_cast<const int*>(f->s);
  const int* perm = static_cast<const int*>(f->Perm);
  const float* L = m.single_values.data();
  const SolveSchedule& schedule = m.schedule;
  const int tasks = static_cast<int>(schedule.task_first.size());
  std::vector<float>& y = m.work;
  y.resize(n_);
  for (int k = 0; k < n_; ++k) y[k] = static_cast<float>(b[perm[k]]);  // L L^T = P A P^T
  m.top_updates.assign(static_cast<std::size_t>(tasks) * schedule.top_rows, 0.0f);
  m.gathered.resize(tasks);
  // Per supernode: columns k1..k2-1, a dense nrow x ncol column-major block whose first
  // ncol rows are the diagonal triangle and whose other rows are listed in `rows`.
  auto forward = [&](int s, std::vector<float>& t, float* top_updates) {
    const int k1 = super[s], ncol = super[s + 1] - k1, nrow = pi[s + 1] - pi[s], below = nrow - ncol;
    t.resize(std::max(below, 0));
    forward_supernode(L + px[s], nrow, ncol, y.data() + k1, t.data());
    const int* r = rows + pi[s] + ncol;
    for (int i = 0; i < below; ++i) {
      const int slot = top_updates ? schedule.top_slot[r[i]] : -1;
      if (slot >= 0)
        top_updates[slot] += t[i];
      else
        y[r[i]] -= t[i];
    }
  };
  auto backward = [&](int s, std::vector<float>& t) {
    const int k1 = super[s], ncol = super[s + 1] - k1, nrow = pi[s + 1] - pi[s], below = nrow - ncol;
    t.resize(std::max(below, 0));
    const int* r = rows + pi[s] + ncol;
    for (int i = 0; i < below; ++i) t[i] = y[r[i]];
    backward_supernode(L + px[s], nrow, ncol, y.data() + k1, t.data());
  };
  // Forward, L y = P b: the subtrees, then their updates of the top rows in task order,
  // then the top supernodes. Backward, L^T z = y, in the reverse order.
#pragma omp parallel for schedule(dynamic, 1) if (n_ >= parallel_solve_size) num_threads(kernels::parallel_team_size())
  for (int task = 0; task < tasks; ++task)
    for (int s = schedule.task_first[task]; s <= schedule.task_last[task]; ++s)
      forward(s, m.gathered[task], m.top_updates.data() + static_cast<std::size_t>(task) * schedule.top_rows);
  for (int s : schedule.top)
    for (int k = super[s]; k < super[s + 1]; ++k)
      for (int task = 0; task < tasks; ++task)
        y[k] -= m.top_updates[static_cast<std::size_t>(task) * schedule.top_rows + schedule.top_slot[k]];
  for (int s : schedule.top) forward(s, m.top_scratch, nullptr);
  for (auto s = schedule.top.rbegin(); s != schedule.top.rend(); ++s) backward(*s, m.top_scratch);
#pragma omp parallel for schedule(dynamic, 1) if (n_ >= parallel_solve_size) num_threads(kernels::parallel_team_size())
  for (int task = 0; task < tasks; ++task)
    for (int s = schedule.task_last[task]; s >= schedule.task_first[task]; --s) backward(s, m.gathered[task]);
  x.resize(n_);
  for (int k = 0; k < n_; ++k) x[perm[k]] = y[k];
}

std::vector<double> SparseCholesky::pivots() const {
  const Impl& m = *impl_;
  if (m.dense) return m.dense->pivots();
  if (!m.factor || !m.factor->is_super || !m.factor->x || m.factor->itype != CHOLMOD_INT)
    throw std::logic_error("SparseCholesky::pivots needs a numeric supernodal factor (call factorize first)");
  const cholmod_factor& L = *m.factor;
  const int* super = static_cast<const int*>(L.super);  // an int factor (CHOLMOD_INT)
  const int* pi = static_cast<const int*>(L.pi);
  const int* px = static_cast<const int*>(L.px);
  const auto* perm = static_cast<const int*>(L.Perm);
  const auto* x = static_cast<const double*>(L.x);
  std::vector<double> out(n_);
  for (std::size_t s = 0; s < L.nsuper; ++s) {
    const std::int64_t rows = pi[s + 1] - pi[s];
    for (int k = 0; k < super[s + 1] - super[s]; ++k) {
      const double l = x[px[s] + k * rows + k];  // column-major block of `rows` rows
      const int column = super[s] + k;
      out[perm ? perm[column] : column] = l * l;
    }
  }
  return out;
}

std::int64_t SparseCholesky::factor_nonzeros() const {
  if (impl_->dense) return impl_->dense->factor_nonzeros();
  const cholmod_factor* f = impl_->factor;
  if (!f) return 0;
  if (f->is_super) return static_cast<std::int64_t>(f->xsize);
  return static_cast<std::int64_t>(f->nzmax);
}

}  // namespace dgtex

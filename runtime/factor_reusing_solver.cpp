#include "dgtex/factor_reusing_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "dgtex/kernels/forall.h"
#include "dgtex/shell_model.h"
#include "api_argument_checks.h"

namespace dgtex {

namespace {
// Chunks of the deterministic reductions: a fixed count, so the summation order does not
// depend on how many threads share them.
constexpr std::int64_t dot_chunks = 64;
// Vector loops shorter than this run serially: an axpy over the cylinder scene's 8835 DOFs
// takes a few microseconds, less than waking the OpenMP team, and every parallel region
// leaves the other threads spinning while the (serial) triangular solves run.
constexpr std::int64_t parallel_vector_length = 1 << 15;
kernels::Execution vector_execution(std::size_t n) {
  return static_cast<std::int64_t>(n) >= parallel_vector_length ? kernels::Execution::parallel : kernels::Execution::serial;
}
// An entry of A x from those of M x and K x (0 at a fixed DOF): the one formula of multiply()
// and of pcg's initial residual from a given K x, so both give the same bits.
double scaled_sum_entry(const ScaledBlockSum& A, bool free, double mass_x, double stiffness_x) {
  return free ? A.mass_scale * mass_x + A.stiffness_scale * stiffness_x : 0.0;
}
}  // namespace

std::vector<char> element_local_blocks(const std::vector<double>& mass) {
  std::vector<char> kept(mass.size() / 9, 0);
  for (std::size_t k = 0; k < kept.size(); ++k)
    for (int i = 0; i < 9; ++i) kept[k] |= mass[9 * k + i] != 0;
  return kept;
}

double element_local_dropped_radius(const BlockAssembly& pattern, const std::vector<char>& kept,
                                    const std::vector<char>& free, const std::vector<double>& mass,
                                    const ScaledBlockSum& A) {
  const std::int64_t nodes = pattern.num_nodes();
  const std::vector<std::int64_t>& row_start = pattern.row_start();
  const std::vector<int>& column = pattern.column();
  const std::vector<double>& K = *A.stiffness;
  std::vector<double> diagonal(3 * static_cast<std::size_t>(nodes), 0.0);
  for (std::int64_t r = 0; r < nodes; ++r)
    for (std::int64_t k = row_start[r]; k < row_start[r + 1]; ++k)
      if (column[k] == r)
        for (int i = 0; i < 3; ++i) diagonal[3 * r + i] = A.mass_scale * mass[9 * k + 4 * i] + A.stiffness_scale * K[9 * k + 4 * i];
  // scale[d] = 1 / sqrt(A_dd) on free DOFs, 0 on fixed ones (not summed).
  std::vector<double> scale(diagonal.size(), 0.0);
  for (std::size_t d = 0; d < diagonal.size(); ++d) {
    if (!free[d]) continue;
    if (!(diagonal[d] > 0)) return std::numeric_limits<double>::infinity();
    scale[d] = 1 / std::sqrt(diagonal[d]);
  }
  // The dropped blocks have no mass (element_local_blocks): A_ij = stiffness_scale K_ij.
  const double stiffness_scale = std::abs(A.stiffness_scale);
  std::vector<double> row_radius(static_cast<std::size_t>(nodes), 0.0);
  kernels::forall(
      nodes,
      [&](std::int64_t r) {
        double sums[3] = {0, 0, 0};
        for (std::int64_t k = row_start[r]; k < row_start[r + 1]; ++k) {
          if (kept[k]) continue;
          const double* s = scale.data() + 3 * static_cast<std::int64_t>(column[k]);
          for (int i = 0; i < 3; ++i)
            sums[i] += std::abs(K[9 * k + 3 * i]) * s[0] + std::abs(K[9 * k + 3 * i + 1]) * s[1] +
                       std::abs(K[9 * k + 3 * i + 2]) * s[2];
        }
        for (int i = 0; i < 3; ++i) row_radius[r] = std::max(row_radius[r], stiffness_scale * sums[i] * scale[3 * r + i]);
      },
      block_product_execution(pattern));
  return row_radius.empty() ? 0.0 : *std::max_element(row_radius.begin(), row_radius.end());
}

FactorReuseStatistics operator+(const FactorReuseStatistics& a, const FactorReuseStatistics& b) {
  FactorReuseStatistics sum = b;
  sum.solves += a.solves;
  sum.factorizations += a.factorizations;
  sum.iterations += a.iterations;
  sum.factorize_ms += a.factorize_ms;
  sum.precondition_ms += a.precondition_ms;
  sum.element_local_fallbacks += a.element_local_fallbacks;
  sum.stale_factor_failures += a.stale_factor_failures;
  return sum;
}

double deterministic_dot(const std::vector<double>& x, const std::vector<double>& y) {
  const std::int64_t n = static_cast<std::int64_t>(x.size());
  double partial[dot_chunks];
  kernels::forall(
      dot_chunks,
      [&](std::int64_t c) {
        const std::int64_t begin = n * c / dot_chunks, end = n * (c + 1) / dot_chunks;
        double s = 0;
        for (std::int64_t i = begin; i < end; ++i) s += x[i] * y[i];
        partial[c] = s;
      },
      vector_execution(x.size()));
  double sum = 0;
  for (double s : partial) sum += s;
  return sum;
}

FactorReusingSolver::FactorReusingSolver(const BlockAssembly& pattern, const FreeDofSystem& system,
                                         const std::vector<double>& mass, FactorReuseOptions options)
    : pattern_(pattern), system_(system), mass_(mass), options_(options) {
  const std::int64_t blocks = pattern.num_blocks();
  if (static_cast<std::int64_t>(mass.size()) == blocks * 9 && blocks_are_isotropic(mass)) {
    mass_scalar_.resize(blocks);
    for (std::int64_t k = 0; k < blocks; ++k) mass_scalar_[k] = mass[9 * k];
  }
  free_.resize(system.num_dofs());
  summed_.resize(system.num_dofs());
  for (int d = 0; d < system.num_dofs(); ++d) {
    free_[d] = system.is_unknown(d);
    summed_[d] = free_[d] || system.is_dependent(d);
  }
  if (static_cast<std::int64_t>(mass.size()) == blocks * 9) element_local_blocks_ = element_local_blocks(mass);
  for (char kept : element_local_blocks_) element_local_differs_ |= !kept;
  if (system.has_dependents()) element_local_differs_ = false;  // its blocks would leave the ties out
  whole_pattern_dense_ =
      SparseCholesky::factors_densely(system.size(), static_cast<std::int64_t>(system.row_index().size()));
  large_dense_ = whole_pattern_dense_ && system.size() >= SparseCholesky::dense_single_precision_min_unknowns;
  set_options(options);
}

void FactorReusingSolver::set_options(const FactorReuseOptions& options) {
  // A tolerance of 1 or more took the extrapolated guess as the solution (0 iterations);
  // 0, NaN or no iterations made every step refactorise and end "ill-conditioned".
  if (!(options.relative_tolerance > 0 && options.relative_tolerance < 1))
    throw std::invalid_argument("FactorReuseOptions: relative_tolerance " +
                                detail::short_number(options.relative_tolerance) + "; expected a number in (0, 1), e.g. 1e-8");
  if (options.max_iterations < 1)
    throw std::invalid_argument("FactorReuseOptions: max_iterations " + std::to_string(options.max_iterations) +
                                "; expected an integer >= 1");
  for (const auto& [name, value] : {std::pair{"refactor_after_iterations", options.refactor_after_iterations},
                                    {"large_dense_refactor_after_iterations", options.large_dense_refactor_after_iterations}})
    if (value < 0)  // 0: every solve that iterates at all factorises the next system
      throw std::invalid_argument(std::string("FactorReuseOptions: ") + name + " " + std::to_string(value) +
                                  "; expected an integer >= 0");
  if (!(options.element_local_max_dropped_radius >= 0))
    throw std::invalid_argument("FactorReuseOptions: element_local_max_dropped_radius " +
                                detail::short_number(options.element_local_max_dropped_radius) + "; expected a number >= 0");
  const bool ruled_out = element_local_dropped_radius_ > options.element_local_max_dropped_radius;
  const bool element_local = options.preconditioner_pattern == PreconditionerPattern::element_local &&
                             element_local_differs_ && !whole_pattern_dense_ && stats_.element_local_fallbacks == 0 &&
                             !ruled_out;
  if (element_local != use_element_local_) factor_current_ = false, factorization_pending_ = false;
  use_element_local_ = element_local;
  options_ = options;
}

void FactorReusingSolver::fall_back_to_full_pattern() {
  use_element_local_ = false;
  factor_current_ = false;
  ++stats_.element_local_fallbacks;
  element_local_factor_.reset();
}

void FactorReusingSolver::judge_element_local(const ScaledBlockSum& A) {
  if (!std::isnan(element_local_dropped_radius_)) return;
  element_local_dropped_radius_ = dgtex::element_local_dropped_radius(pattern_, element_local_blocks_, free_, mass_, A);
  if (element_local_dropped_radius_ > options_.element_local_max_dropped_radius) use_element_local_ = false;
}

void FactorReusingSolver::gather_element_local(const ScaledBlockSum& A) {
  if (!element_local_system_) {
    std::vector<char> fixed(free_.size());
    for (size_t d = 0; d < free_.size(); ++d) fixed[d] = !free_[d];
    element_local_system_ = std::make_unique<FreeDofSystem>(pattern_, fixed, &element_local_blocks_);
  }
  element_local_system_->gather(mass_.data(), A.mass_scale, A.stiffness->data(), A.stiffness_scale, values_);
}

void FactorReusingSolver::factorize_element_local_values() {
  if (!element_local_factor_) element_local_factor_ = std::make_unique<SparseCholesky>();
  if (!element_local_factor_->analyzed())
    element_local_factor_->analyze(element_local_system_->size(), element_local_system_->column_start(),
                                   element_local_system_->row_index());
  try {
    element_local_factor_->factorize(values_);
  } catch (const NotPositiveDefinite&) {
    fall_back_to_full_pattern();  // the dropped couplings were needed: A itself is checked next
    return;
  }
  if (options_.single_precision_preconditioner) element_local_factor_->copy_factor_to_single_precision();
}

void FactorReusingSolver::factorize_full_values(SparseCholesky& cholesky) {
  if (!cholesky.analyzed()) cholesky.analyze(system_.size(), system_.column_start(), system_.row_index());
  cholesky.factorize(values_);
  if (options_.single_precision_preconditioner) cholesky.copy_factor_to_single_precision();
}

void FactorReusingSolver::factorize_pending() {
  if (!factorization_pending_) return;
  factorization_pending_ = false;
  const auto start = std::chrono::steady_clock::now();
  bool factored = true;
  if (use_element_local_) {
    factorize_element_local_values();
    factored = use_element_local_;  // false: it fell back, the next solve factorises the whole pattern
  } else {
    try {
      factorize_full_values(*pending_factor_);
    } catch (const NotPositiveDefinite&) {
      factored = false;  // the next solve factorises its own matrix, and reports it if that fails too
    }
  }
  stats_.factorize_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  factor_current_ = factored;
  if (factored) ++stats_.factorizations;
}

void FactorReusingSolver::factorize(const ScaledBlockSum& A, SparseCholesky& cholesky) {
  const auto start = std::chrono::steady_clock::now();
  if (use_element_local_) judge_element_local(A);
  if (use_element_local_) {
    gather_element_local(A);
    factorize_element_local_values();
  }
  if (!use_element_local_) {
    system_.gather(mass_.data(), A.mass_scale, A.stiffness->data(), A.stiffness_scale, values_);
    factorize_full_values(cholesky);
  }
  stats_.factorize_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  factor_current_ = true;
  ++stats_.factorizations;
}

void FactorReusingSolver::precondition(const SparseCholesky& cholesky, const std::vector<double>& r,
                                       std::vector<double>& z) {
  const auto start = std::chrono::steady_clock::now();
  // Both systems have the same free DOFs, so either restricts and expands alike.
  const SparseCholesky& factor = use_element_local_ ? *element_local_factor_ : cholesky;
  system_.restrict_vector(r, reduced_in_);
  if (options_.single_precision_preconditioner)
    factor.solve_single_precision(reduced_in_, reduced_out_);
  else
    factor.solve(reduced_in_, reduced_out_);
  system_.expand_vector(reduced_out_, z);
  stats_.precondition_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void FactorReusingSolver::spread(const std::vector<double>& x) const {
  spread_.resize(3 * x.size());
  kernels::spread_block_vector(pattern_.num_nodes(), x.data(), spread_.data());
}

void FactorReusingSolver::multiply_mass_rows(std::int64_t first, std::int64_t last, double* y) const {
  if (mass_scalar_.empty())
    kernels::block_rows_product(pattern_.rows(), first, last, mass_.data(), spread_.data(), y);
  else
    kernels::scalar_rows_product(pattern_.rows(), first, last, mass_scalar_.data(), spread_.data(), y);
}

void FactorReusingSolver::multiply_mass(const std::vector<double>& x, std::vector<double>& y) const {
  y.resize(x.size());
  spread(x);
  for_row_ranges(pattern_, [&](std::int64_t first, std::int64_t last) { multiply_mass_rows(first, last, y.data()); });
}

void FactorReusingSolver::multiply(const ScaledBlockSum& A, const std::vector<double>& x, std::vector<double>& y) const {
  y.resize(x.size());
  k_product_.resize(x.size());
  m_product_.resize(x.size());
  spread(x);
  // The same products as pcg's initial residual from a given K x.
  for_row_ranges(pattern_, [&](std::int64_t first, std::int64_t last) {
    if (mass_scalar_.empty()) {
      kernels::block_rows_product(pattern_.rows(), first, last, A.stiffness->data(), spread_.data(), k_product_.data());
      multiply_mass_rows(first, last, m_product_.data());
    } else {
      kernels::block_and_scalar_rows_product(pattern_.rows(), first, last, A.stiffness->data(), mass_scalar_.data(),
                                             spread_.data(), k_product_.data(), m_product_.data());
    }
    for (std::int64_t d = 3 * first; d < 3 * last; ++d)
      y[d] = scaled_sum_entry(A, summed_[d], m_product_[d], k_product_[d]);
  });
  system_.collect(y);
}

int FactorReusingSolver::pcg(const ScaledBlockSum& A, const std::vector<double>& b, std::vector<double>& x,
                             const SparseCholesky& cholesky, double& relative_residual,
                             const std::vector<double>* kx) {
  const size_t n = b.size();
  if (kx) {  // A x from the given K x
    multiply_mass(x, q_);
    for (size_t d = 0; d < n; ++d) q_[d] = scaled_sum_entry(A, summed_[d], q_[d], (*kx)[d]);
    system_.collect(q_);
  } else {
    multiply(A, x, q_);
  }
  r_.resize(n);
  b_free_.resize(n);
  for (size_t d = 0; d < n; ++d) b_free_[d] = summed_[d] ? b[d] : 0.0;
  system_.collect(b_free_);  // T^T b: dependent entries act through their sources
  for (size_t d = 0; d < n; ++d) r_[d] = b_free_[d] - q_[d];
  const double b_norm = std::sqrt(deterministic_dot(b_free_, b_free_));
  if (!std::isfinite(b_norm))
    throw std::runtime_error("FactorReusingSolver: the right-hand side is not finite (has the state diverged? try a "
                             "smaller time step)");
  if (b_norm == 0) {
    std::fill(x.begin(), x.end(), 0.0);
    relative_residual = 0;
    return 0;
  }
  relative_residual = std::sqrt(deterministic_dot(r_, r_)) / b_norm;
  if (relative_residual <= options_.relative_tolerance) return 0;
  precondition(cholesky, r_, z_);
  p_ = z_;
  double rz = deterministic_dot(r_, z_);
  for (int it = 1; it <= options_.max_iterations; ++it) {
    multiply(A, p_, q_);
    const double pq = deterministic_dot(p_, q_);
    if (!(pq > 0)) return -1;  // A not positive definite along p, or breakdown
    const double alpha = rz / pq;
    kernels::forall(
        static_cast<std::int64_t>(n),
        [&](std::int64_t d) {
          x[d] += alpha * p_[d];
          r_[d] -= alpha * q_[d];
        },
        vector_execution(n));
    relative_residual = std::sqrt(deterministic_dot(r_, r_)) / b_norm;
    if (relative_residual <= options_.relative_tolerance) return it;
    precondition(cholesky, r_, z_);
    const double rz_next = deterministic_dot(r_, z_);
    const double beta = rz_next / rz;
    rz = rz_next;
    kernels::forall(
        static_cast<std::int64_t>(n), [&](std::int64_t d) { p_[d] = z_[d] + beta * p_[d]; }, vector_execution(n));
  }
  return -1;
}

void FactorReusingSolver::solve(const ScaledBlockSum& A, const std::vector<double>& b, std::vector<double>& x,
                                SparseCholesky& cholesky, const std::vector<double>* stiffness_times_x) {
  detail::check_size("FactorReusingSolver::solve", "b", b.size(), "#dofs", free_.size());
  detail::check_size("FactorReusingSolver::solve", "x", x.size(), "#dofs", free_.size());
  if (stiffness_times_x)
    detail::check_size("FactorReusingSolver::solve", "stiffness_times_x", stiffness_times_x->size(), "#dofs", free_.size());
  ++stats_.solves;
  for (size_t d = 0; d < x.size(); ++d)
    if (!free_[d]) x[d] = 0;
  system_.distribute(x);  // the iterates stay T x_free: PCG's steps p are expanded so too
  if (system_.size() == 0) {  // every DOF held: nothing to solve
    stats_.last_iterations = 0;
    stats_.last_relative_residual = 0;
    return;
  }
  factorize_pending();  // if the caller did not run it beside its assembly
  const bool fresh = !factor_current_;
  if (fresh) factorize(A, cholesky);
  guess_ = x;
  double residual = 0;
  int iterations = pcg(A, b, x, cholesky, residual, stiffness_times_x);
  int wasted = 0;
  if (iterations < 0 && !fresh) {
    // The old factor no longer preconditions well enough: factorise this matrix.
    ++stats_.stale_factor_failures;
    wasted += options_.max_iterations;
    factorize(A, cholesky);
    x = guess_;
    iterations = pcg(A, b, x, cholesky, residual, stiffness_times_x);  // x is the guess again
  }
  if (iterations < 0 && use_element_local_) {
    // Even a fresh element-local factor is too far from A: use the whole pattern.
    wasted += options_.max_iterations;
    fall_back_to_full_pattern();
    factorize(A, cholesky);
    x = guess_;
    iterations = pcg(A, b, x, cholesky, residual, stiffness_times_x);
  }
  if (iterations < 0)
    throw std::runtime_error("FactorReusingSolver: no convergence to relative residual " +
                             detail::short_number(options_.relative_tolerance) + " even with a fresh factor (residual " +
                             detail::short_number(residual) + "); the system is ill-conditioned");
  // Judged by the factor now held (a fresh one after a failed attempt).
  const int refactor_after =
      large_dense_ ? options_.large_dense_refactor_after_iterations : options_.refactor_after_iterations;
  if (iterations > refactor_after) {
    if (options_.overlap_factorization) {
      // A_k now: the caller overwrites its K before the next solve.
      if (use_element_local_) {
        gather_element_local(A);
      } else {
        system_.gather(mass_.data(), A.mass_scale, A.stiffness->data(), A.stiffness_scale, values_);
        pending_factor_ = &cholesky;
      }
      factorization_pending_ = true;
    } else {
      factor_current_ = false;
    }
  }
  iterations += wasted;
  stats_.iterations += iterations;
  stats_.last_iterations = iterations;
  stats_.last_relative_residual = residual;
}

}  // namespace dgtex

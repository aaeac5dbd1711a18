#include "graph_laplacian_amg.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

// Measured on the fracture scene's cut update at t = 0.2 (three texel graphs of 5.9k, 19.6k
// and 19.6k unknowns, tolerance 1e-6, 1 thread): 7-9 CG iterations, 3-4 levels, operator
// complexity 1.4. On a 140 x 140 grid (19.6k unknowns, 1 thread, 2-core Xeon): with Eigen's
// sparse products the setup took 11.2-11.7 ms; with the Gustavson products over plain
// compressed rows here 9.4-9.9 ms, 5.3-6.9 ms when malloc keeps its memory (the rest is
// first-touch page faults), and the 8 CG iterations ~10 ms: a solve ~15-20 ms where CHOLMOD
// (simplicial, AMD) took ~40 ms. With the smoother's lower and upper parts apart (session
// 44, best of 100-150 calls in one process): the grid's 7 iterations 5.2-7.0 ms instead of
// 7.1-7.4, a fracture graph's 9 iterations 9.3 ms instead of 11.6-12.7.

namespace dgtex::detail {
namespace {

// Coarsening stops at this many nodes (factored densely: ~2e7 multiply-adds, once) ...
constexpr int kDenseCoarsestNodes = 400;
// ... or when a level keeps more than this share of the nodes of the one above (the
// coarsest is then factored sparse).
constexpr double kStalledCoarsening = 0.8;
// |a_ij| >= kStrength sqrt(a_ii a_jj): a coupling that aggregation follows. A texel graph's
// couplings are all strong (1 against degrees <= 4); coarse levels' weak corner couplings
// are left out.
constexpr double kStrength = 0.08;

// Compressed rows: row i holds columns[offsets[i] .. offsets[i + 1]) (any order).
struct Rows {
  int rows = 0, columns_count = 0;
  std::vector<int> offsets{0}, columns;
  std::vector<double> values;
};

Rows rows_of(const SparseRows& a) {
  if (!a.isCompressed())
    throw std::invalid_argument("solve_graph_laplacian_amg: the matrix must be compressed (makeCompressed)");
  Rows r;
  r.rows = static_cast<int>(a.rows()), r.columns_count = static_cast<int>(a.cols());
  r.offsets.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.rows() + 1);
  r.columns.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  r.values.assign(a.valuePtr(), a.valuePtr() + a.nonZeros());
  return r;
}

Rows transpose(const Rows& a) {
  Rows t;
  t.rows = a.columns_count, t.columns_count = a.rows;
  t.offsets.assign(t.rows + 1, 0);
  for (int c : a.columns) ++t.offsets[c + 1];
  for (int i = 0; i < t.rows; ++i) t.offsets[i + 1] += t.offsets[i];
  t.columns.resize(a.columns.size()), t.values.resize(a.values.size());
  std::vector<int> next(t.offsets.begin(), t.offsets.end() - 1);
  for (int i = 0; i < a.rows; ++i)
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) {
      const int slot = next[a.columns[e]]++;
      t.columns[slot] = i, t.values[slot] = a.values[e];
    }
  return t;
}

// a * b, row by row into a dense accumulator (Gustavson); each row's columns in the order
// they first appear, so the result is the same on every run.
Rows multiply(const Rows& a, const Rows& b) {
  Rows c;
  c.rows = a.rows, c.columns_count = b.columns_count;
  c.offsets.reserve(a.rows + 1);
  std::size_t bound = 0;  // the products to add: at least the entries of c
  for (int k : a.columns) bound += b.offsets[k + 1] - b.offsets[k];
  c.columns.reserve(bound), c.values.reserve(bound);
  std::vector<int> slot(b.columns_count, -1);
  for (int i = 0; i < a.rows; ++i) {
    const int row_start = static_cast<int>(c.columns.size());
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) {
      const int k = a.columns[e];
      const double v = a.values[e];
      for (int f = b.offsets[k]; f < b.offsets[k + 1]; ++f) {
        const int j = b.columns[f];
        if (slot[j] < row_start) {
          slot[j] = static_cast<int>(c.columns.size());
          c.columns.push_back(j), c.values.push_back(v * b.values[f]);
        } else {
          c.values[slot[j]] += v * b.values[f];
        }
      }
    }
    c.offsets.push_back(static_cast<int>(c.columns.size()));
  }
  return c;
}

void multiply(const Rows& a, const std::vector<double>& x, std::vector<double>& y) {
  for (int i = 0; i < a.rows; ++i) {
    double s = 0;
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) s += a.values[e] * x[a.columns[e]];
    y[i] = s;
  }
}

std::vector<double> diagonal_of(const Rows& a) {
  std::vector<double> d(a.rows, 0.0);
  for (int i = 0; i < a.rows; ++i)
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e)
      if (a.columns[e] == i) d[i] += a.values[e];
  return d;
}

// The aggregate of every node, in three passes over the rows in order: (1) a node whose
// strong neighbours are all free starts an aggregate with them; (2) a node left over joins
// the first-pass aggregate it couples to most strongly; (3) the rest start aggregates with
// their free strong neighbours (an isolated node on its own).
std::vector<int> aggregate(const Rows& a, const std::vector<double>& diagonal, int& count) {
  std::vector<char> strong(a.columns.size(), 0);
  for (int i = 0; i < a.rows; ++i)
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) {
      const int j = a.columns[e];
      strong[e] = j != i && std::abs(a.values[e]) >= kStrength * std::sqrt(diagonal[i] * diagonal[j]);
    }
  std::vector<int> of(a.rows, -1);
  count = 0;
  for (int i = 0; i < a.rows; ++i) {
    if (of[i] >= 0) continue;
    bool free = true, coupled = false;
    for (int e = a.offsets[i]; e < a.offsets[i + 1] && free; ++e)
      if (strong[e]) coupled = true, free = of[a.columns[e]] < 0;
    if (!free || !coupled) continue;
    of[i] = count;
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e)
      if (strong[e]) of[a.columns[e]] = count;
    ++count;
  }
  const std::vector<int> first_pass = of;
  for (int i = 0; i < a.rows; ++i) {
    if (of[i] >= 0) continue;
    double strongest = 0;
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e)
      if (strong[e] && first_pass[a.columns[e]] >= 0 && std::abs(a.values[e]) > strongest)
        strongest = std::abs(a.values[e]), of[i] = first_pass[a.columns[e]];
  }
  for (int i = 0; i < a.rows; ++i) {
    if (of[i] >= 0) continue;
    of[i] = count;
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e)
      if (strong[e] && of[a.columns[e]] < 0) of[a.columns[e]] = count;
    ++count;
  }
  return of;
}

// P = (I - omega D^-1 A) P_tentative, P_tentative(i, aggregate of i) = 1, with omega =
// 4 / (3 rho) and rho >= the spectral radius of D^-1 A by Gershgorin.
Rows smoothed_interpolation(const Rows& a, const std::vector<double>& diagonal, const std::vector<int>& of,
                            int count) {
  double rho = 0;
  for (int i = 0; i < a.rows; ++i) {
    double row_sum = 0;
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) row_sum += std::abs(a.values[e]);
    rho = std::max(rho, row_sum / diagonal[i]);
  }
  const double omega = 4.0 / (3.0 * rho);
  Rows p;
  p.rows = a.rows, p.columns_count = count;
  p.offsets.reserve(a.rows + 1);
  p.columns.reserve(a.columns.size() + a.rows), p.values.reserve(a.columns.size() + a.rows);
  std::vector<int> slot(count, -1);
  for (int i = 0; i < a.rows; ++i) {
    const int row_start = static_cast<int>(p.columns.size());
    auto add = [&](int aggregate_index, double value) {
      if (slot[aggregate_index] < row_start) {
        slot[aggregate_index] = static_cast<int>(p.columns.size());
        p.columns.push_back(aggregate_index), p.values.push_back(value);
      } else {
        p.values[slot[aggregate_index]] += value;
      }
    };
    add(of[i], 1.0);
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) add(of[a.columns[e]], -omega * a.values[e] / diagonal[i]);
    p.offsets.push_back(static_cast<int>(p.columns.size()));
  }
  return p;
}

// A's strictly lower and strictly upper parts, each row's columns in A's order (increasing
// on the finest level, the texel graph's): the Gauss-Seidel sweeps sum the terms of values
// already final first and those updated in the sweep last, so that on the finest level one
// neighbour's update waits on two operations instead of on the whole row's sum.
struct Triangles {
  Rows lower, upper;
};

Triangles triangles_of(const Rows& a) {
  Triangles t;
  for (Rows* part : {&t.lower, &t.upper}) {
    part->rows = a.rows, part->columns_count = a.columns_count;
    part->offsets.assign(a.rows + 1, 0);
  }
  for (int i = 0; i < a.rows; ++i) {
    int below = 0, above = 0;
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) (a.columns[e] < i ? below : above) += a.columns[e] != i;
    t.lower.offsets[i + 1] = t.lower.offsets[i] + below, t.upper.offsets[i + 1] = t.upper.offsets[i] + above;
  }
  for (Rows* part : {&t.lower, &t.upper}) part->columns.resize(part->offsets.back()), part->values.resize(part->offsets.back());
  for (int i = 0; i < a.rows; ++i) {
    int below = t.lower.offsets[i], above = t.upper.offsets[i];
    for (int e = a.offsets[i]; e < a.offsets[i + 1]; ++e) {
      const int j = a.columns[e];
      if (j < i) t.lower.columns[below] = j, t.lower.values[below++] = a.values[e];
      if (j > i) t.upper.columns[above] = j, t.upper.values[above++] = a.values[e];
    }
  }
  return t;
}

struct Level {
  Rows a;
  std::vector<double> diagonal, inverse_diagonal;
  Triangles triangles;  // the smoother's copy of A's off-diagonal part (not on the coarsest)
  Rows p, r;  // interpolation from the next coarser level and its transpose (not on the coarsest)
  std::vector<double> x, b, residual;
};

class Hierarchy {
 public:
  explicit Hierarchy(const SparseRows& a) {
    levels_.emplace_back();
    levels_.back().a = rows_of(a);
    levels_.back().diagonal = diagonal_of(levels_.back().a);
    while (levels_.back().a.rows > kDenseCoarsestNodes) {
      Level& fine = levels_.back();
      int count = 0;
      const std::vector<int> of = aggregate(fine.a, fine.diagonal, count);
      if (count > kStalledCoarsening * fine.a.rows) break;
      fine.p = smoothed_interpolation(fine.a, fine.diagonal, of, count);
      fine.r = transpose(fine.p);
      Rows coarse = multiply(fine.r, multiply(fine.a, fine.p));
      levels_.emplace_back();
      levels_.back().a = std::move(coarse);
      levels_.back().diagonal = diagonal_of(levels_.back().a);
    }
    for (std::size_t l = 0; l + 1 < levels_.size(); ++l) levels_[l].triangles = triangles_of(levels_[l].a);
    for (Level& level : levels_) {
      level.inverse_diagonal.resize(level.a.rows);
      for (int i = 0; i < level.a.rows; ++i) level.inverse_diagonal[i] = 1.0 / level.diagonal[i];
      level.x.resize(level.a.rows), level.b.resize(level.a.rows), level.residual.resize(level.a.rows);
    }
    const Rows& coarsest = levels_.back().a;
    std::vector<Eigen::Triplet<double, int>> entries;
    for (int i = 0; i < coarsest.rows; ++i)
      for (int e = coarsest.offsets[i]; e < coarsest.offsets[i + 1]; ++e)
        entries.emplace_back(i, coarsest.columns[e], coarsest.values[e]);
    Eigen::SparseMatrix<double> matrix(coarsest.rows, coarsest.rows);
    matrix.setFromTriplets(entries.begin(), entries.end());
    bool factored = false;
    if (coarsest.rows <= kDenseCoarsestNodes) {
      dense_.compute(Eigen::MatrixXd(matrix));
      factored = dense_.info() == Eigen::Success;
    } else {
      sparse_.compute(matrix);
      factored = sparse_.info() == Eigen::Success;
    }
    if (!factored) throw std::runtime_error("the coarsest level is not positive definite");
  }

  int levels() const { return static_cast<int>(levels_.size()); }
  const Rows& finest() const { return levels_.front().a; }

  // z = M r: one V(1,1)-cycle from zero.
  void precondition(const std::vector<double>& r, std::vector<double>& z) {
    levels_.front().b = r;
    cycle(0);
    z = levels_.front().x;
  }

 private:
  void cycle(std::size_t l) {
    Level& level = levels_[l];
    if (l + 1 == levels_.size()) {
      const Eigen::Map<const Eigen::VectorXd> b(level.b.data(), level.a.rows);
      Eigen::Map<Eigen::VectorXd> x(level.x.data(), level.a.rows);
      x = level.a.rows <= kDenseCoarsestNodes ? Eigen::VectorXd(dense_.solve(b)) : Eigen::VectorXd(sparse_.solve(b));
      return;
    }
    forward_sweep_from_zero(level);
    // After a forward sweep from zero, b - A x is minus the upper part times x: each row's
    // lower part and diagonal were met exactly by the sweep.
    const Rows& upper = level.triangles.upper;
    for (int i = 0; i < level.a.rows; ++i) {
      double s = 0;
      for (int e = upper.offsets[i]; e < upper.offsets[i + 1]; ++e) s -= upper.values[e] * level.x[upper.columns[e]];
      level.residual[i] = s;
    }
    Level& coarse = levels_[l + 1];
    multiply(level.r, level.residual, coarse.b);
    cycle(l + 1);
    for (int i = 0; i < level.a.rows; ++i)
      for (int e = level.p.offsets[i]; e < level.p.offsets[i + 1]; ++e)
        level.x[i] += level.p.values[e] * coarse.x[level.p.columns[e]];
    backward_sweep(level);
  }

  // Forward Gauss-Seidel from x = 0: the upper part multiplies zeros.
  static void forward_sweep_from_zero(Level& level) {
    const Rows& lower = level.triangles.lower;
    for (int i = 0; i < lower.rows; ++i) {
      double s = level.b[i];
      for (int e = lower.offsets[i]; e < lower.offsets[i + 1]; ++e) s -= lower.values[e] * level.x[lower.columns[e]];
      level.x[i] = s * level.inverse_diagonal[i];
    }
  }

  // Backward Gauss-Seidel: the lower part (values of the previous iterate) first, then the
  // upper part from its farthest column to the row just below, updated last.
  static void backward_sweep(Level& level) {
    const Rows& lower = level.triangles.lower;
    const Rows& upper = level.triangles.upper;
    for (int i = lower.rows - 1; i >= 0; --i) {
      double s = level.b[i];
      for (int e = lower.offsets[i]; e < lower.offsets[i + 1]; ++e) s -= lower.values[e] * level.x[lower.columns[e]];
      for (int e = upper.offsets[i + 1] - 1; e >= upper.offsets[i]; --e) s -= upper.values[e] * level.x[upper.columns[e]];
      level.x[i] = s * level.inverse_diagonal[i];
    }
  }

  std::vector<Level> levels_;
  Eigen::LLT<Eigen::MatrixXd> dense_;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> sparse_;
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

}  // namespace

GraphAmgStats solve_graph_laplacian_amg(const SparseRows& a, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                        double tolerance, int max_iterations) {
  GraphAmgStats stats;
  const int n = static_cast<int>(a.rows());
  const double b_norm = b.norm();
  if (b_norm == 0) {
    x.setZero();
    return stats;
  }
  std::vector<double> r(n), z(n), p(n), q(n);
  {
    const Eigen::VectorXd residual = b - a * x;
    std::copy(residual.data(), residual.data() + n, r.begin());
  }
  double r_norm = std::sqrt(dot(r, r));
  stats.relative_residual = r_norm / b_norm;
  if (r_norm <= tolerance * b_norm) return stats;

  const auto start = std::chrono::steady_clock::now();
  Hierarchy hierarchy(a);
  stats.levels = hierarchy.levels();
  stats.setup_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  hierarchy.precondition(r, z);
  p = z;
  double rz = dot(r, z);
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    multiply(hierarchy.finest(), p, q);
    const double pq = dot(p, q);
    if (!(pq > 0)) break;  // not positive definite, or a NaN
    const double alpha = rz / pq;
    for (int i = 0; i < n; ++i) x[i] += alpha * p[i], r[i] -= alpha * q[i];
    r_norm = std::sqrt(dot(r, r));
    stats.iterations = iteration;
    stats.relative_residual = r_norm / b_norm;
    if (r_norm <= tolerance * b_norm) return stats;
    hierarchy.precondition(r, z);
    const double rz_next = dot(r, z);
    const double beta = rz_next / rz;
    for (int i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
    rz = rz_next;
  }
  throw std::runtime_error("algebraic multigrid CG: relative residual " + std::to_string(stats.relative_residual) +
                           " after " + std::to_string(stats.iterations) + " iterations (tolerance " +
                           std::to_string(tolerance) + ")");
}

}  // namespace dgtex::detail

#include "seamed_patch_laplace.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/stage_timer.h"

namespace dgtex::detail {

namespace {
// Relative residual of the initial guess above which the chain's solution replaces it.
constexpr double fresh_start_residual = 0.1;
}  // namespace

LaplaceSolveStats solve_seamed_patch_laplace(kernels::TexelTile& tile, const std::vector<SeamCoupling>& seams,
                                             const LaplaceMultigridOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  validate_laplace_tile(tile);
  const int w = tile.width, h = tile.height, n = w * h;
  const auto free_texel = [&](int t) { return !(tile.flags[t] & (kernels::dirichlet | kernels::inactive)); };
  for (const SeamCoupling& s : seams)
    if (s.a < 0 || s.b < 0 || s.a >= n || s.b >= n || s.a == s.b || (tile.flags[s.a] & kernels::inactive) ||
        (tile.flags[s.b] & kernels::inactive) || (!free_texel(s.a) && !free_texel(s.b)))
      throw std::invalid_argument("seamed patch Laplace: seam (" + std::to_string(s.a) + ", " + std::to_string(s.b) +
                                  ") must join two active texels of the " + std::to_string(w) + "x" +
                                  std::to_string(h) + " tile, at least one free");

  LaplaceMultigrid chain(tile, options);
  std::vector<char> unknown(n, 0);
  for (int t = 0; t < n; ++t) {
    unknown[t] = chain.is_unknown(t);
    if (free_texel(t) && !unknown[t])
      throw std::runtime_error("seamed patch Laplace: texel " + std::to_string(t) +
                               " has Dirichlet data only across a seam");
  }
  std::vector<std::uint8_t> bits;
  kernels::classify_laplace_texels(tile, bits);
  // Seam partners in compressed rows (few texels have any: one edge of the patch).
  std::vector<int> partner_start(static_cast<std::size_t>(n) + 1, 0), partner;
  for (const SeamCoupling& s : seams) ++partner_start[s.a + 1], ++partner_start[s.b + 1];
  for (int t = 0; t < n; ++t) partner_start[t + 1] += partner_start[t];
  partner.resize(partner_start[n]);
  {
    std::vector<int> next(partner_start.begin(), partner_start.end() - 1);
    for (const SeamCoupling& s : seams) partner[next[s.a]++] = s.b, partner[next[s.b]++] = s.a;
  }

  // The CG's passes over the patch, one row per work item with per-row partial sums added
  // in row order (deterministic for any thread count): y = A x at the unknowns (the grid
  // couplings, the degree counting Dirichlet neighbours too, then one coupling per seam
  // partner) with sum p . (A p) fused in.
  std::vector<double> rows(h);
  const auto sum_rows = [&] {
    double sum = 0;
    for (double v : rows) sum += v;
    return sum;
  };
  const auto apply_and_dot = [&](const std::vector<double>& x, std::vector<double>& y) {
    kernels::forall(h, [&](std::int64_t j) {
      double dot = 0;
      for (int t = static_cast<int>(j) * w; t < (static_cast<int>(j) + 1) * w; ++t) {
        if (!unknown[t]) {
          y[t] = 0;
          continue;
        }
        const std::uint8_t m = bits[t];
        const int first = partner_start[t], last = partner_start[t + 1];
        double v = (kernels::laplace_degree(m) + static_cast<double>(last - first)) * x[t];
        if (m & kernels::couples_west_unknown) v -= x[t - 1];
        if (m & kernels::couples_east_unknown) v -= x[t + 1];
        if (m & kernels::couples_south_unknown) v -= x[t - w];
        if (m & kernels::couples_north_unknown) v -= x[t + w];
        for (int k = first; k < last; ++k)
          if (unknown[partner[k]]) v -= x[partner[k]];
        y[t] = v;
        dot += x[t] * v;
      }
      rows[j] = dot;
    });
    return sum_rows();
  };
  // Sum over the patch of f(t), by rows.
  const auto row_sum = [&](auto f) {
    kernels::forall(h, [&](std::int64_t j) {
      double sum = 0;
      for (int t = static_cast<int>(j) * w; t < (static_cast<int>(j) + 1) * w; ++t) sum += f(t);
      rows[j] = sum;
    });
    return sum_rows();
  };
  // b: values of coupled Dirichlet texels, grid neighbours and seam partners.
  std::vector<double> b(n, 0.0), x(n, 0.0), r(n), z, p, q(n);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int t = tile.index(i, j);
      if (!unknown[t]) continue;
      auto data = [&](bool coupled, int o) {
        if (coupled && (tile.flags[o] & (kernels::dirichlet | kernels::inactive)) == kernels::dirichlet)
          b[t] += tile.values[o];
      };
      data(i > 0 && kernels::texels_coupled_east(tile, i - 1, j), t - 1);
      data(i + 1 < w && kernels::texels_coupled_east(tile, i, j), t + 1);
      data(j > 0 && kernels::texels_coupled_north(tile, i, j - 1), t - w);
      data(j + 1 < h && kernels::texels_coupled_north(tile, i, j), t + w);
      for (int k = partner_start[t]; k < partner_start[t + 1]; ++k) data(true, partner[k]);
      if (options.warm_start && std::isfinite(tile.values[t])) x[t] = tile.values[t];
    }
  LaplaceSolveStats stats;
  const double b_norm = std::sqrt(row_sum([&](int t) { return b[t] * b[t]; }));
  const auto residual = [&] {
    apply_and_dot(x, q);
    const double r0 = row_sum([&](int t) {
      r[t] = b[t] - q[t];
      return r[t] * r[t];
    });
    return b_norm > 0 ? std::sqrt(r0) / b_norm : 0.0;
  };
  double relative = residual();
  // A poor start (a new enrichment: x = 0) goes to the open chain's solution first, by the
  // same hierarchy's own solver (~0.5x the cost of a CG iteration per cycle). Near-Neumann
  // rings (slinky: a short new cut segment on a closed cylinder) took 34 iterations from
  // x = 0 and take 6 chain cycles + 21 iterations from there; the chain's solution is wrong
  // only near the seam. A warm start (the previous H) is kept as it is.
  if (relative > fresh_start_residual) {
    kernels::TexelTile open = tile;
    for (int t = 0; t < n; ++t)
      if (unknown[t]) open.values[t] = x[t];
    try {
      chain.solve(open);
      for (int t = 0; t < n; ++t)
        if (unknown[t]) x[t] = open.values[t];
      relative = residual();
    } catch (const std::runtime_error&) {
      // the chain did not converge: CG goes on from its own start
    }
  }
  if (relative > options.tolerance) {
    chain.precondition(r, z);
    p = z;
    double rz = row_sum([&](int t) { return r[t] * z[t]; });
    while (relative > options.tolerance && stats.iterations < options.max_cycles) {
      const double pq = apply_and_dot(p, q);
      if (!(pq > 0)) break;
      const double alpha = rz / pq;
      // x += alpha p, r -= alpha q, and r . r in one pass.
      const double rr = row_sum([&](int t) {
        x[t] += alpha * p[t];
        r[t] -= alpha * q[t];
        return r[t] * r[t];
      });
      ++stats.iterations;
      relative = std::sqrt(rr) / b_norm;
      if (relative <= options.tolerance) break;
      chain.precondition(r, z);
      const double rz_next = row_sum([&](int t) { return r[t] * z[t]; });
      const double beta = rz_next / rz;
      rz = rz_next;
      kernels::forall(h, [&](std::int64_t j) {
        for (int t = static_cast<int>(j) * w; t < (static_cast<int>(j) + 1) * w; ++t) p[t] = z[t] + beta * p[t];
      });
    }
    // The true residual, not the recursive one.
    apply_and_dot(x, q);
    relative = std::sqrt(row_sum([&](int t) { return (b[t] - q[t]) * (b[t] - q[t]); })) / b_norm;
  }
  if (!(relative <= options.tolerance))
    throw std::runtime_error("seamed patch Laplace: relative residual " + std::to_string(relative) + " after " +
                             std::to_string(stats.iterations) + " iterations");
  for (int t = 0; t < n; ++t)
    if (free_texel(t)) tile.values[t] = x[t];
  stats.relative_residual = relative;
  stats.ms = ms_since(start);
  return stats;
}

}  // namespace dgtex::detail

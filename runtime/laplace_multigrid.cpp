#include "dgtex/laplace_multigrid.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include "dgtex/kernels/multigrid_galerkin.h"
#include "dgtex/kernels/multigrid_residual.h"
#include "dgtex/kernels/multigrid_smooth.h"
#include "dgtex/kernels/multigrid_transfer.h"
#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex {
using kernels::Execution;
using kernels::GridShape;

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

// Levels smaller than this run serially: a parallel region costs more than the work.
constexpr long parallel_min_nodes = 16384;

double sum_in_order(const std::vector<double>& rows) {
  double sum = 0;
  for (double v : rows) sum += v;
  return sum;
}

}  // namespace

struct LaplaceMultigrid::Hierarchy {
  struct Level {
    GridShape shape;
    Execution execution = Execution::serial;
    std::vector<double> x, b, r;
    std::vector<std::uint8_t> active;       // node has an unknown (prolongation mask)
    std::vector<double> c, e, n, ne, nw;    // 9-point operator (levels >= 1)
    std::vector<double> p[8];               // interpolation to the next finer level (levels >= 1)
    kernels::Stencil9View stencil() const { return {c.data(), e.data(), n.data(), ne.data(), nw.data()}; }
    kernels::InterpolationView interpolation() const {
      return {p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data(), p[5].data(), p[6].data(), p[7].data()};
    }
  };

  LaplaceMultigridOptions options;
  int width = 0, height = 0;
  std::vector<std::uint8_t> tile_flags;  // to check solve() gets the same tile
  std::vector<std::uint8_t> bits;        // level-0 operator, padded layout
  std::vector<Level> levels;
  std::vector<double> row_partial;       // per-row partial sums (deterministic reductions)
  std::vector<double> cg_z, cg_p, cg_q;  // preconditioned CG vectors (level-0 layout)
  std::vector<std::int64_t> coarsest_nodes;
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> coarsest_factor;
  int orphans_at_stop = 0;
  double setup_ms = 0;

  Execution execution_for(GridShape shape) const {
    return (options.execution == Execution::parallel && static_cast<long>(shape.nx) * shape.ny >= parallel_min_nodes)
               ? Execution::parallel : Execution::serial;
  }

  void build(const kernels::TexelTile& tile) {
    width = tile.width;
    height = tile.height;
    tile_flags = tile.flags;
    std::vector<std::uint8_t> tile_bits;
    kernels::classify_laplace_texels(tile, tile_bits);

    Level fine;
    fine.shape = {width, height};
    fine.execution = execution_for(fine.shape);
    bits.assign(fine.shape.padded_size(), 0);
    fine.active.assign(fine.shape.padded_size(), 0);
    for (int j = 0; j < height; ++j)
      for (int i = 0; i < width; ++i) {
        bits[fine.shape.at(i, j)] = tile_bits[tile.index(i, j)];
        fine.active[fine.shape.at(i, j)] = (tile_bits[tile.index(i, j)] & kernels::is_unknown) ? 1 : 0;
      }
    fine.x.assign(fine.shape.padded_size(), 0.0);
    fine.b = fine.r = fine.x;
    levels.clear();
    levels.push_back(std::move(fine));

    while (static_cast<long>(levels.back().shape.nx) * levels.back().shape.ny > options.coarsest_nodes &&
           (levels.back().shape.nx > 1 || levels.back().shape.ny > 1)) {
      const std::size_t l = levels.size() - 1;
      Level coarse;
      coarse.shape = levels[l].shape.coarser();
      coarse.execution = execution_for(coarse.shape);
      const std::size_t size = coarse.shape.padded_size();
      for (auto* v : {&coarse.x, &coarse.b, &coarse.r, &coarse.c, &coarse.e, &coarse.n, &coarse.ne, &coarse.nw})
        v->assign(size, 0.0);
      for (auto& v : coarse.p) v.assign(size, 0.0);
      kernels::InterpolationArrays p{coarse.p[0].data(), coarse.p[1].data(), coarse.p[2].data(), coarse.p[3].data(),
                                     coarse.p[4].data(), coarse.p[5].data(), coarse.p[6].data(), coarse.p[7].data()};
      kernels::Stencil9Arrays a{coarse.c.data(), coarse.e.data(), coarse.n.data(), coarse.ne.data(), coarse.nw.data()};
      const Execution ex = levels[l].execution;
      if (l == 0) {
        kernels::build_interpolation_texels(levels[0].shape, bits.data(), p, ex);
        kernels::galerkin_texels(levels[0].shape, bits.data(), p.view(), a, ex);
      } else {
        kernels::build_interpolation_stencil9(levels[l].shape, levels[l].stencil(), p, ex);
        kernels::galerkin_stencil9(levels[l].shape, levels[l].stencil(), p.view(), a, ex);
      }
      const int orphans = count_orphans(levels[l], coarse);
      if (orphans > options.max_orphans) {
        orphans_at_stop = orphans;
        break;  // this coarsening would lose part of the domain: solve level l directly
      }
      coarse.active.assign(size, 0);
      for (std::size_t t = 0; t < size; ++t) coarse.active[t] = coarse.c[t] > 0 ? 1 : 0;
      levels.push_back(std::move(coarse));
    }
    factor_coarsest();
    std::size_t rows = 0;
    for (const Level& level : levels) rows = std::max<std::size_t>(rows, level.shape.ny);
    row_partial.assign(rows, 0.0);
    if (options.use_as_cg_preconditioner) {
      cg_z.assign(levels[0].shape.padded_size(), 0.0);
      cg_p = cg_q = cg_z;
    }
  }

  // Active fine nodes (not coarse points) whose interpolation row is zero: parts of the
  // domain (channels narrower than the coarse spacing) the coarse level cannot represent.
  static int count_orphans(const Level& fine, const Level& coarse) {
    const kernels::InterpolationView p = coarse.interpolation();
    int orphans = 0;
    for (int J = 0; J < coarse.shape.ny; ++J)
      for (int I = 0; I < coarse.shape.nx; ++I) {
        const std::int64_t c = coarse.shape.at(I, J);
        auto check = [&](int i, int j, double weight_sum) {
          if (i < fine.shape.nx && j < fine.shape.ny && fine.active[fine.shape.at(i, j)] && weight_sum == 0.0) ++orphans;
        };
        check(2 * I + 1, 2 * J, std::abs(p.xw[c]) + std::abs(p.xe[c]));
        check(2 * I, 2 * J + 1, std::abs(p.ys[c]) + std::abs(p.yn[c]));
        check(2 * I + 1, 2 * J + 1, std::abs(p.sw[c]) + std::abs(p.se[c]) + std::abs(p.nw[c]) + std::abs(p.ne[c]));
      }
    return orphans;
  }

  // Sparse Cholesky (CHOLMOD) of the coarsest operator restricted to its nodes with
  // unknowns (SPD: every column of P holds a unit entry at its own fine node).
  void factor_coarsest() {
    const Level& level = levels.back();
    const bool texels = levels.size() == 1;
    coarsest_nodes.clear();
    const GridShape g = level.shape;
    std::vector<int> index(g.padded_size(), -1);
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        if (level.active[g.at(i, j)]) {
          index[g.at(i, j)] = static_cast<int>(coarsest_nodes.size());
          coarsest_nodes.push_back(g.at(i, j));
        }
    const int n = static_cast<int>(coarsest_nodes.size());
    std::vector<Eigen::Triplet<double>> entries;
    const std::int64_t s = g.stride();
    for (int k = 0; k < n; ++k) {
      const std::int64_t t = coarsest_nodes[k];
      auto couple = [&](std::int64_t other, double value) {
        if (index[other] >= 0 && value != 0.0) entries.emplace_back(index[other], k, value);
      };
      if (texels) {
        const std::uint8_t m = bits[t];
        couple(t, kernels::laplace_degree(m));
        if (m & kernels::couples_west_unknown) couple(t - 1, -1.0);
        if (m & kernels::couples_east_unknown) couple(t + 1, -1.0);
        if (m & kernels::couples_south_unknown) couple(t - s, -1.0);
        if (m & kernels::couples_north_unknown) couple(t + s, -1.0);
        continue;
      }
      couple(t, level.c[t]);
      couple(t + 1, level.e[t]);
      couple(t - 1, level.e[t - 1]);
      couple(t + s, level.n[t]);
      couple(t - s, level.n[t - s]);
      couple(t + s + 1, level.ne[t]);
      couple(t - s - 1, level.ne[t - s - 1]);
      couple(t + s - 1, level.nw[t]);
      couple(t - s + 1, level.nw[t - s + 1]);
    }
    Eigen::SparseMatrix<double> m(n, n);
    m.setFromTriplets(entries.begin(), entries.end());
    if (n > 0) coarsest_factor.compute(m);
    if (n > 0 && coarsest_factor.info() != Eigen::Success)
      throw std::runtime_error("Laplace multigrid: the coarsest operator (" + std::to_string(n) +
                               " nodes) is not positive definite; this is a bug, please report the tile");
  }

  void smooth(std::size_t l, bool forward, int sweeps) {
    Level& level = levels[l];
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      if (l == 0) {
        for (int k = 0; k < 2; ++k)
          kernels::smooth_texels_color(level.shape, bits.data(), level.b.data(), level.x.data(), forward ? k : 1 - k,
                                       level.execution);
      } else {
        for (int k = 0; k < 4; ++k)
          kernels::smooth_stencil9_color(level.shape, level.stencil(), level.b.data(), level.x.data(),
                                         forward ? k : 3 - k, level.execution);
      }
    }
  }

  void residual(std::size_t l, double* row_norm2) {
    Level& level = levels[l];
    if (l == 0)
      kernels::residual_texels(level.shape, bits.data(), level.b.data(), level.x.data(), level.r.data(), row_norm2,
                               level.execution);
    else
      kernels::residual_stencil9(level.shape, level.stencil(), level.b.data(), level.x.data(), level.r.data(),
                                 row_norm2, level.execution);
  }

  void solve_coarsest() {
    Level& level = levels.back();
    const int n = static_cast<int>(coarsest_nodes.size());
    if (n == 0) return;
    Eigen::VectorXd rhs(n);
    for (int k = 0; k < n; ++k) rhs[k] = level.b[coarsest_nodes[k]];
    const Eigen::VectorXd solution = coarsest_factor.solve(rhs);
    for (int k = 0; k < n; ++k) level.x[coarsest_nodes[k]] = solution[k];
  }

  // One cycle on level l for A_l x_l = b_l, improving x_l in place.
  void cycle(std::size_t l, MultigridCycle type) {
    if (l + 1 == levels.size()) {
      solve_coarsest();
      return;
    }
    Level& level = levels[l];
    Level& coarse = levels[l + 1];
    smooth(l, true, options.pre_smoothing);
    residual(l, nullptr);
    kernels::restrict_residual(level.shape, coarse.shape, coarse.interpolation(), level.r.data(), coarse.b.data(),
                               coarse.execution);
    std::fill(coarse.x.begin(), coarse.x.end(), 0.0);
    cycle(l + 1, type);
    if (type == MultigridCycle::f) cycle(l + 1, MultigridCycle::v);
    kernels::prolong_correction(level.shape, coarse.shape, coarse.interpolation(), coarse.x.data(),
                                level.active.data(), level.x.data(), level.execution);
    smooth(l, false, options.post_smoothing);
  }

  double level0_residual_norm() {
    residual(0, row_partial.data());
    row_partial.resize(levels[0].shape.ny);
    const double norm = std::sqrt(sum_in_order(row_partial));
    return norm;
  }

  // Deterministic dot product over the level-0 layout (rows summed in order).
  double dot(const std::vector<double>& a, const std::vector<double>& b) {
    const GridShape g = levels[0].shape;
    row_partial.resize(g.ny);
    kernels::forall(
        g.ny,
        [&](std::int64_t j) {
          const std::int64_t row = g.at(0, static_cast<int>(j));
          double sum = 0;
          for (int i = 0; i < g.nx; ++i) sum += a[row + i] * b[row + i];
          row_partial[j] = sum;
        },
        levels[0].execution);
    return sum_in_order(row_partial);
  }
};

LaplaceMultigrid::LaplaceMultigrid(const kernels::TexelTile& tile, LaplaceMultigridOptions options)
    : hierarchy_(std::make_unique<Hierarchy>()) {
  const auto start = Clock::now();
  validate_laplace_tile(tile);
  if (!(options.tolerance > 0) || options.max_cycles < 1 || options.pre_smoothing < 0 || options.post_smoothing < 0 ||
      options.pre_smoothing + options.post_smoothing < 1 || options.coarsest_nodes < 1)
    throw std::invalid_argument(
        "Laplace multigrid: invalid options (need tolerance > 0, max_cycles >= 1, pre/post smoothing >= 0 with at "
        "least one sweep, coarsest_nodes >= 1)");
  if (options.use_as_cg_preconditioner &&
      (options.cycle != MultigridCycle::v || options.pre_smoothing != options.post_smoothing))
    throw std::invalid_argument(
        "Laplace multigrid: a CG preconditioner must be symmetric: use V-cycles with pre_smoothing == post_smoothing "
        "(got " + std::to_string(options.pre_smoothing) + " and " + std::to_string(options.post_smoothing) + ")");
  hierarchy_->options = options;
  hierarchy_->build(tile);
  hierarchy_->setup_ms = ms_since(start);
}

LaplaceMultigrid::~LaplaceMultigrid() = default;
LaplaceMultigrid::LaplaceMultigrid(LaplaceMultigrid&&) noexcept = default;
LaplaceMultigrid& LaplaceMultigrid::operator=(LaplaceMultigrid&&) noexcept = default;
int LaplaceMultigrid::level_count() const { return static_cast<int>(hierarchy_->levels.size()); }
double LaplaceMultigrid::setup_ms() const { return hierarchy_->setup_ms; }
const LaplaceMultigridOptions& LaplaceMultigrid::options() const { return hierarchy_->options; }

LaplaceSolveStats LaplaceMultigrid::solve(kernels::TexelTile& tile, std::vector<LaplaceConvergencePoint>* history) {
  const auto start = Clock::now();
  Hierarchy& h = *hierarchy_;
  validate_laplace_tile(tile);
  if (tile.width != h.width || tile.height != h.height || tile.flags != h.tile_flags)
    throw std::invalid_argument("Laplace multigrid: solve() got a tile whose size or flags differ from the " +
                                std::to_string(h.width) + "x" + std::to_string(h.height) +
                                " tile the hierarchy was built for; build a new LaplaceMultigrid");
  auto& fine = h.levels[0];
  const GridShape g = fine.shape;
  const LaplaceMultigridOptions& o = h.options;

  // Right-hand side (coupled Dirichlet neighbours) and initial guess, one row per index.
  kernels::forall(
      g.ny,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        for (int i = 0; i < g.nx; ++i) {
          const std::int64_t t = g.at(i, j);
          fine.b[t] = 0.0;
          fine.x[t] = 0.0;
          if (!(h.bits[t] & kernels::is_unknown)) continue;
          const int k = tile.index(i, j);
          double b = 0;
          auto add = [&](bool coupled, int nb) {
            if (coupled && (tile.flags[nb] & kernels::dirichlet)) b += tile.values[nb];
          };
          add(i > 0 && kernels::texels_coupled_east(tile, i - 1, j), k - 1);
          add(kernels::texels_coupled_east(tile, i, j), k + 1);
          add(j > 0 && kernels::texels_coupled_north(tile, i, j - 1), k - g.nx);
          add(kernels::texels_coupled_north(tile, i, j), k + g.nx);
          fine.b[t] = b;
          if (o.warm_start && std::isfinite(tile.values[k])) fine.x[t] = tile.values[k];
        }
      },
      fine.execution);

  LaplaceSolveStats stats;
  const double b_norm = std::sqrt(h.dot(fine.b, fine.b));
  auto record = [&](double relative) {
    if (history) history->push_back({ms_since(start), relative});
  };
  if (b_norm > 0) {
    double relative = h.level0_residual_norm() / b_norm;
    record(relative);
    if (!o.use_as_cg_preconditioner) {
      while (relative > o.tolerance && stats.iterations < o.max_cycles) {
        h.cycle(0, o.cycle);
        ++stats.iterations;
        relative = h.level0_residual_norm() / b_norm;
        record(relative);
      }
    } else if (relative > o.tolerance) {
      // Preconditioned CG on the residual equation: z = V-cycle(r) with zero initial guess.
      std::vector<double> x = fine.x, r = fine.r, b = fine.b;
      auto precondition = [&]() {
        fine.b = r;
        std::fill(fine.x.begin(), fine.x.end(), 0.0);
        h.cycle(0, MultigridCycle::v);
        h.cg_z.swap(fine.x);
      };
      precondition();
      h.cg_p = h.cg_z;
      double rz = h.dot(r, h.cg_z);
      while (relative > o.tolerance && stats.iterations < o.max_cycles) {
        kernels::apply_texels(g, h.bits.data(), h.cg_p.data(), h.cg_q.data(), h.row_partial.data(), fine.execution);
        h.row_partial.resize(g.ny);
        const double pq = sum_in_order(h.row_partial);
        if (!(pq > 0)) break;  // the search direction vanished: converged to round-off
        const double alpha = rz / pq;
        kernels::forall(
            g.ny,
            [&](std::int64_t j) {
              const std::int64_t row = g.at(0, static_cast<int>(j));
              double norm2 = 0;
              for (int i = 0; i < g.nx; ++i) {
                x[row + i] += alpha * h.cg_p[row + i];
                r[row + i] -= alpha * h.cg_q[row + i];
                norm2 += r[row + i] * r[row + i];
              }
              h.row_partial[j] = norm2;
            },
            fine.execution);
        relative = std::sqrt(sum_in_order(h.row_partial)) / b_norm;
        ++stats.iterations;
        record(relative);
        if (relative <= o.tolerance) break;
        precondition();
        const double rz_new = h.dot(r, h.cg_z);
        const double beta = rz_new / rz;
        rz = rz_new;
        kernels::forall(
            g.ny,
            [&](std::int64_t j) {
              const std::int64_t row = g.at(0, static_cast<int>(j));
              for (int i = 0; i < g.nx; ++i) h.cg_p[row + i] = h.cg_z[row + i] + beta * h.cg_p[row + i];
            },
            fine.execution);
      }
      fine.x.swap(x);
      fine.b.swap(b);
      relative = h.level0_residual_norm() / b_norm;  // the true residual, not the recursive one
    }
    stats.relative_residual = relative;
    if (!(relative <= o.tolerance))
      throw std::runtime_error("Laplace multigrid: relative residual " + std::to_string(relative) + " after " +
                               std::to_string(stats.iterations) + " cycles, tolerance " + std::to_string(o.tolerance) +
                               " not reached; raise max_cycles or use the cholmod solver");
  } else {
    record(0.0);
    std::fill(fine.x.begin(), fine.x.end(), 0.0);
  }

  // Write back: unknowns get the solution, other free texels (no Dirichlet data) 0.
  kernels::forall(
      g.ny,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        for (int i = 0; i < g.nx; ++i) {
          const int k = tile.index(i, j);
          if (tile.flags[k] & (kernels::dirichlet | kernels::inactive)) continue;
          tile.values[k] = (h.bits[g.at(i, j)] & kernels::is_unknown) ? fine.x[g.at(i, j)] : 0.0;
        }
      },
      fine.execution);
  stats.ms = ms_since(start);
  return stats;
}

LaplaceSolveStats solve_laplace_multigrid(kernels::TexelTile& tile, const LaplaceMultigridOptions& options,
                                          std::vector<LaplaceConvergencePoint>* history) {
  const auto start = Clock::now();
  LaplaceMultigrid multigrid(tile, options);
  LaplaceSolveStats stats = multigrid.solve(tile, history);
  stats.ms = ms_since(start);
  return stats;
}

}  // namespace dgtex

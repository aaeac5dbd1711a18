#include "seamed_patch_laplace.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/SparseCore>

#include "banded_cholesky.h"
#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_residual.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/stage_timer.h"

namespace dgtex::detail {

namespace {
// Relative residual of the initial guess above which the chain's solution replaces it.
constexpr double fresh_start_residual = 0.1;
// Texels (Chebyshev distance) around each seam texel in the preconditioner's exact strip
// solve: slinky's ring gets 8 columns x 128 rows. Radius 0 / 1 / 3 took 20 / 16 / 13
// iterations on that ring from 0 in a prototype (30 without the strip).
constexpr int seam_strip_radius = 3;
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

  // The CG runs on the multigrid's padded level-0 layout, so the grid part of y = A x and
  // p . A p come from its vector kernels (kernels::apply_texels and the fused direction
  // update); the seam couplings are added after, texel by texel (few: one patch edge).
  const kernels::GridShape g{w, h};
  const std::size_t padded = g.padded_size();
  const auto at = [&](int t) { return g.at(t % w, t / w); };
  std::vector<std::uint8_t> bits(padded);
  kernels::classify_laplace_texels_padded(tile, bits.data());
  // A part of the ring whose only Dirichlet data lie across a seam has no unknowns in the
  // open chain. Then the chain (the preconditioner's tile) pins the free seam texels as
  // Dirichlet texels, so every part touching a seam has data there; the exact strip solves
  // below cover the pinned texels, whose values do not matter to the preconditioner. The
  // operator's bytes are then the pinned tile's, with the pinned texels made unknowns again
  // and their neighbours coupled to them. (Pinning only where needed: on slinky's step-17
  // ring it doubles the iterations, 7 -> 15.)
  std::vector<char> on_seam(n, 0);
  for (const SeamCoupling& c : seams) on_seam[c.a] = on_seam[c.b] = 1;
  bool pin = false;
  for (int t = 0; t < n && !pin; ++t) pin = free_texel(t) && !(bits[at(t)] & kernels::is_unknown);
  kernels::TexelTile pinned;
  if (pin) {
    pinned = tile;
    for (int t = 0; t < n; ++t)
      if (on_seam[t] && free_texel(t)) pinned.flags[t] |= kernels::dirichlet;
    kernels::classify_laplace_texels_padded(pinned, bits.data());
    for (int t = 0; t < n; ++t) {
      if (!(on_seam[t] && free_texel(t))) continue;
      const int i = t % w, j = t / w;
      // Neighbours: unknowns of the pinned classification, or pinned seam texels themselves.
      const auto ring_unknown = [&](int o) {
        return (bits[at(o)] & kernels::is_unknown) || (on_seam[o] && free_texel(o));
      };
      int degree = 0;  // coupled active neighbours, Dirichlet ones included
      std::uint8_t b = kernels::is_unknown;
      const auto link = [&](bool coupled, int o, std::uint8_t toward, std::uint8_t back) {
        if (!coupled) return;
        ++degree;
        if (!ring_unknown(o)) return;
        b |= toward;
        bits[at(o)] |= back;
      };
      link(i > 0 && kernels::texels_coupled_east(tile, i - 1, j), t - 1, kernels::couples_west_unknown,
           kernels::couples_east_unknown);
      link(i + 1 < w && kernels::texels_coupled_east(tile, i, j), t + 1, kernels::couples_east_unknown,
           kernels::couples_west_unknown);
      link(j > 0 && kernels::texels_coupled_north(tile, i, j - 1), t - w, kernels::couples_south_unknown,
           kernels::couples_north_unknown);
      link(j + 1 < h && kernels::texels_coupled_north(tile, i, j), t + w, kernels::couples_north_unknown,
           kernels::couples_south_unknown);
      bits[at(t)] = b | static_cast<std::uint8_t>(degree << kernels::degree_shift);
    }
  }
  // Coarse levels and the strip factor only once a solve needs them (below): a warm start
  // that meets the tolerance already (a settled enrichment solved again for a new wall
  // elsewhere) needs neither.
  const kernels::TexelTile& chain_tile = pin ? pinned : tile;
  LaplaceMultigrid chain(chain_tile, options, LaplaceMultigrid::CoarseLevels::on_demand);
  std::vector<char> unknown(n, 0);
  for (int t = 0; t < n; ++t) {
    unknown[t] = (bits[at(t)] & kernels::is_unknown) != 0;
    if (free_texel(t) && !unknown[t])
      throw std::runtime_error("seamed patch Laplace: texel " + std::to_string(t) +
                               " is in a part of the ring without Dirichlet data");
  }
  // Seam partners per seam texel (padded indices), each unknown seam texel listed once, its
  // partners in the order of `seams`.
  std::vector<std::int64_t> seam_texel;
  std::vector<int> partner_start = {0};
  std::vector<std::int64_t> partner;
  {
    std::vector<std::pair<int, std::int64_t>> ends;  // (seam texel, partner)
    ends.reserve(2 * seams.size());
    for (const SeamCoupling& c : seams) ends.emplace_back(c.a, at(c.b)), ends.emplace_back(c.b, at(c.a));
    std::stable_sort(ends.begin(), ends.end(),
                     [](const auto& one, const auto& other) { return one.first < other.first; });
    for (std::size_t e = 0; e < ends.size();) {
      const int t = ends[e].first;
      std::size_t last = e;
      while (last < ends.size() && ends[last].first == t) ++last;
      if (unknown[t]) {
        seam_texel.push_back(at(t));
        for (; e < last; ++e) partner.push_back(ends[e].second);
        partner_start.push_back(static_cast<int>(partner.size()));
      }
      e = last;
    }
  }
  const auto is_unknown = [&](std::int64_t k) { return (bits[k] & kernels::is_unknown) != 0; };
  // y += S x at the seam texels; returns the seam share of x . y.
  const auto add_seams = [&](const std::vector<double>& x, std::vector<double>& y) {
    double dot = 0;
    for (std::size_t s = 0; s < seam_texel.size(); ++s) {
      const std::int64_t k = seam_texel[s];
      double v = static_cast<double>(partner_start[s + 1] - partner_start[s]) * x[k];
      for (int m = partner_start[s]; m < partner_start[s + 1]; ++m)
        if (is_unknown(partner[m])) v -= x[partner[m]];
      y[k] += v;
      dot += x[k] * v;
    }
    return dot;
  };
  std::vector<double> rows(h);
  const auto sum_rows = [&] {
    double sum = 0;
    for (double v : rows) sum += v;
    return sum;
  };
  const kernels::Execution execution = options.execution;
  // y = A x (0 off the unknowns) and x . y.
  const auto apply_and_dot = [&](const std::vector<double>& x, std::vector<double>& y) {
    kernels::apply_texels(g, bits.data(), x.data(), y.data(), rows.data(), execution);
    const double grid = sum_rows();
    return grid + add_seams(x, y);
  };
  // Sum over the padded rows of f(k) for the texels k of row j.
  const auto row_sum = [&](auto f) {
    kernels::forall(
        h,
        [&](std::int64_t j) {
          double sum = 0;
          const std::int64_t first = g.at(0, static_cast<int>(j));
          for (std::int64_t k = first; k < first + w; ++k) sum += f(k);
          rows[j] = sum;
        },
        execution);
    return sum_rows();
  };
  // b: values of coupled Dirichlet texels, grid neighbours and seam partners.
  std::vector<double> b(padded, 0.0), x(padded, 0.0), r(padded, 0.0), q(padded, 0.0);
  std::vector<double> z, p;  // once CG runs (a warm start often meets the tolerance); p copies z
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int t = tile.index(i, j);
      if (!unknown[t]) continue;
      const std::int64_t k = g.at(i, j);
      auto data = [&](bool coupled, int o) {
        if (coupled && (tile.flags[o] & (kernels::dirichlet | kernels::inactive)) == kernels::dirichlet)
          b[k] += tile.values[o];
      };
      data(i > 0 && kernels::texels_coupled_east(tile, i - 1, j), t - 1);
      data(i + 1 < w && kernels::texels_coupled_east(tile, i, j), t + 1);
      data(j > 0 && kernels::texels_coupled_north(tile, i, j - 1), t - w);
      data(j + 1 < h && kernels::texels_coupled_north(tile, i, j), t + w);
      if (options.warm_start && std::isfinite(tile.values[t])) x[k] = tile.values[t];
    }
  for (const SeamCoupling& c : seams) {
    auto data = [&](int t, int o) {
      if (unknown[t] && (tile.flags[o] & (kernels::dirichlet | kernels::inactive)) == kernels::dirichlet)
        b[at(t)] += tile.values[o];
    };
    data(c.a, c.b), data(c.b, c.a);
  }
  // The preconditioner: the chain's V-cycle between two exact solves on the seam strip
  // (the unknowns within seam_strip_radius texels of a seam texel), symmetric multiplicative
  // Schwarz: z = D^-1 r_S, then z += M (r - A z), then z += D^-1 (r - A z)_S. The V-cycle
  // sees the seams as walls; the strip solves put their couplings back where it errs most.
  // Slinky's step-17 ring from x = 0: 34 -> 14 iterations.
  std::vector<std::int64_t> strip;  // padded indices, ordered for a narrow band
  // The strip and the unknowns coupled to it: where A z can differ from 0 while z is 0 off the
  // strip (sorted padded indices).
  std::vector<std::int64_t> strip_halo;
  BandedCholesky strip_factor;
  Eigen::VectorXd strip_r, strip_z;
  const auto factor_strip = [&] {
    std::vector<char> in_strip(padded, 0);
    for (const std::int64_t k : seam_texel) {
      const int i = static_cast<int>(k % g.stride()) - 1, j = static_cast<int>(k / g.stride()) - 1;
      for (int dj = -seam_strip_radius; dj <= seam_strip_radius; ++dj)
        for (int di = -seam_strip_radius; di <= seam_strip_radius; ++di) {
          const int ii = i + di, jj = j + dj;
          if (ii >= 0 && jj >= 0 && ii < w && jj < h && is_unknown(g.at(ii, jj))) in_strip[g.at(ii, jj)] = 1;
        }
    }
    // Row by row or column by column, whichever couples nearer neighbours in the order.
    std::vector<std::int64_t> by_rows, by_columns;
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
        if (in_strip[g.at(i, j)]) by_rows.push_back(g.at(i, j));
    for (int i = 0; i < w; ++i)
      for (int j = 0; j < h; ++j)
        if (in_strip[g.at(i, j)]) by_columns.push_back(g.at(i, j));
    // The strip's block of A, lower triangle, in a given order.
    const auto block = [&](const std::vector<std::int64_t>& order) {
      std::unordered_map<std::int64_t, int> position;
      for (std::size_t m = 0; m < order.size(); ++m) position.emplace(order[m], static_cast<int>(m));
      std::vector<Eigen::Triplet<double>> entries;
      for (std::size_t m = 0; m < order.size(); ++m) {
        const std::int64_t k = order[m];
        const std::uint8_t bk = bits[k];
        double diagonal = kernels::laplace_degree(bk);
        const auto couple = [&](std::int64_t o) {
          const auto it = position.find(o);
          if (it != position.end() && it->second < static_cast<int>(m))
            entries.emplace_back(static_cast<int>(m), it->second, -1.0);
        };
        if (bk & kernels::couples_west_unknown) couple(k - 1);
        if (bk & kernels::couples_east_unknown) couple(k + 1);
        if (bk & kernels::couples_south_unknown) couple(k - g.stride());
        if (bk & kernels::couples_north_unknown) couple(k + g.stride());
        const auto s = std::lower_bound(seam_texel.begin(), seam_texel.end(), k);
        if (s != seam_texel.end() && *s == k) {
          const std::size_t at_seam = static_cast<std::size_t>(s - seam_texel.begin());
          diagonal += partner_start[at_seam + 1] - partner_start[at_seam];
          for (int p = partner_start[at_seam]; p < partner_start[at_seam + 1]; ++p)
            if (is_unknown(partner[p])) couple(partner[p]);
        }
        entries.emplace_back(static_cast<int>(m), static_cast<int>(m), diagonal);
      }
      Eigen::SparseMatrix<double> a(static_cast<int>(order.size()), static_cast<int>(order.size()));
      a.setFromTriplets(entries.begin(), entries.end());
      return a;
    };
    Eigen::SparseMatrix<double> rows_block = block(by_rows), columns_block = block(by_columns);
    const bool use_rows = BandedCholesky::bandwidth(rows_block) <= BandedCholesky::bandwidth(columns_block);
    strip = use_rows ? by_rows : by_columns;
    if (!strip_factor.factorize(use_rows ? rows_block : columns_block)) strip.clear();  // (SPD: not expected)
    strip_r.resize(static_cast<Eigen::Index>(strip.size()));
    // Grid couplings only: a seam partner of a strip texel is a seam texel, in the strip itself.
    for (const std::int64_t k : strip) {
      strip_halo.push_back(k);
      const std::uint8_t bk = bits[k];
      if (bk & kernels::couples_west_unknown) strip_halo.push_back(k - 1);
      if (bk & kernels::couples_east_unknown) strip_halo.push_back(k + 1);
      if (bk & kernels::couples_south_unknown) strip_halo.push_back(k - g.stride());
      if (bk & kernels::couples_north_unknown) strip_halo.push_back(k + g.stride());
    }
    std::sort(strip_halo.begin(), strip_halo.end());
    strip_halo.erase(std::unique(strip_halo.begin(), strip_halo.end()), strip_halo.end());
  };
  // strip_z = D^-1 f on the strip, f(k) the value at strip texel k.
  const auto strip_solve = [&](auto&& f) {
    for (std::size_t m = 0; m < strip.size(); ++m) strip_r[static_cast<Eigen::Index>(m)] = f(strip[m]);
    strip_factor.solve(strip_r, strip_z);
  };
  // az = A u at the listed texels (grid part, then the seams: every seam texel is listed).
  std::vector<double> az;  // allocated with z (below)
  const auto apply_at = [&](const std::vector<double>& u, const std::vector<std::int64_t>& texels) {
    kernels::apply_texels_at(g, bits.data(), u.data(), texels.data(), static_cast<std::int64_t>(texels.size()),
                             az.data());
    add_seams(u, az);
  };
  // The multigrid's preconditioner reads and writes per tile texel (unpadded). z_strip holds
  // the first strip solve's correction on the strip and 0 everywhere else.
  std::vector<double> r_tile, z_tile, z_strip;  // allocated with z (below)
  const auto precondition = [&] {
    const bool with_strip = !strip.empty();
    // The V-cycle's input: r - A z_strip, which differs from r only on the strip's halo.
    if (with_strip) {
      strip_solve([&](std::int64_t k) { return r[k]; });
      for (std::size_t m = 0; m < strip.size(); ++m) z_strip[strip[m]] = strip_z[static_cast<Eigen::Index>(m)];
    }
    kernels::forall(
        h,
        [&](std::int64_t j) { std::copy_n(r.data() + g.at(0, static_cast<int>(j)), w, r_tile.data() + j * w); },
        execution);
    if (with_strip) {
      apply_at(z_strip, strip_halo);
      for (const std::int64_t k : strip_halo) {
        const int i = static_cast<int>(k % g.stride()) - 1, j = static_cast<int>(k / g.stride()) - 1;
        r_tile[static_cast<std::size_t>(j) * w + i] = r[k] - az[k];
      }
    }
    chain.precondition(r_tile, z_tile);
    kernels::forall(
        h,
        [&](std::int64_t j) {
          const std::int64_t first = g.at(0, static_cast<int>(j));
          const double* from = z_tile.data() + j * w;
          for (int i = 0; i < w; ++i) z[first + i] = (with_strip ? z_strip[first + i] : 0.0) + from[i];
        },
        execution);
    // Then z += D^-1 (r - A z) on the strip.
    if (with_strip) {
      apply_at(z, strip);
      strip_solve([&](std::int64_t k) { return r[k] - az[k]; });
      for (std::size_t m = 0; m < strip.size(); ++m) z[strip[m]] += strip_z[static_cast<Eigen::Index>(m)];
    }
    return row_sum([&](std::int64_t k) { return r[k] * z[k]; });
  };

  LaplaceSolveStats stats;
  const double b_norm = std::sqrt(row_sum([&](std::int64_t k) { return b[k] * b[k]; }));
  const auto residual = [&] {
    apply_and_dot(x, q);
    const double r0 = row_sum([&](std::int64_t k) {
      r[k] = b[k] - q[k];
      return r[k] * r[k];
    });
    return b_norm > 0 ? std::sqrt(r0) / b_norm : 0.0;
  };
  double relative = residual();
  // A poor start (a new enrichment: x = 0) goes to the open chain's solution first, by the
  // same hierarchy's own solver (~0.5x the cost of a CG iteration per cycle). Slinky's
  // step-17 ring (a short new cut segment on a closed cylinder) takes 14 iterations from
  // x = 0 and 6 chain cycles + 7 iterations from there; the chain's solution is wrong only
  // near the seam. A warm start (the previous H) is kept as it is.
  if (relative > fresh_start_residual) {
    kernels::TexelTile open = chain_tile;  // the seam texels keep their current values as data
    for (int t = 0; t < n; ++t)
      if (unknown[t]) open.values[t] = x[at(t)];
    try {
      chain.solve(open);
      for (int t = 0; t < n; ++t)
        if (unknown[t]) x[at(t)] = open.values[t];
      relative = residual();
    } catch (const std::runtime_error&) {
      // the chain did not converge: CG goes on from its own start
    }
  }
  if (relative > options.tolerance) {
    for (std::vector<double>* padded_vector : {&z, &az, &z_strip}) padded_vector->assign(padded, 0.0);
    r_tile.resize(n), z_tile.resize(n);
    factor_strip();
    double rz = precondition();
    p = z;
    double pq = apply_and_dot(p, q);
    while (stats.iterations < options.max_cycles) {
      if (!(pq > 0)) break;
      const double alpha = rz / pq;
      // x += alpha p, r -= alpha q, and r . r in one pass.
      const double rr = row_sum([&](std::int64_t k) {
        x[k] += alpha * p[k];
        r[k] -= alpha * q[k];
        return r[k] * r[k];
      });
      ++stats.iterations;
      relative = std::sqrt(rr) / b_norm;
      if (relative <= options.tolerance) break;
      const double rz_next = precondition();
      const double beta = rz_next / rz;
      rz = rz_next;
      // p = z + beta p and q = A p (grid part) in one pass, then the seams.
      kernels::update_direction_and_apply_texels(g, bits.data(), z.data(), beta, p.data(), q.data(), rows.data(),
                                                 execution);
      pq = sum_rows();
      pq += add_seams(p, q);
    }
    // The true residual, not the recursive one.
    relative = residual();
  }
  if (!(relative <= options.tolerance))
    throw std::runtime_error("seamed patch Laplace: relative residual " + std::to_string(relative) + " after " +
                             std::to_string(stats.iterations) + " iterations");
  for (int t = 0; t < n; ++t)
    if (free_texel(t)) tile.values[t] = x[at(t)];
  stats.relative_residual = relative;
  stats.ms = ms_since(start);
  return stats;
}

}  // namespace dgtex::detail

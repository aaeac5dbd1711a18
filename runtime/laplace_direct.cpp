#include "dgtex/laplace_direct.h"

#include <chrono>
#include <stdexcept>
#include <string>

#include <Eigen/CholmodSupport>

#include "dgtex/kernels/multigrid_unknowns.h"
#include "cholmod_lock.h"

namespace dgtex {

TexelLaplaceSystem assemble_texel_laplace_system(const kernels::TexelTile& tile) {
  using namespace kernels;
  validate_laplace_tile(tile);
  std::vector<std::uint8_t> bits;
  classify_laplace_texels(tile, bits);
  const int w = tile.width, h = tile.height;
  TexelLaplaceSystem system;
  system.unknown_of_texel.assign(bits.size(), -1);
  for (int t = 0; t < static_cast<int>(bits.size()); ++t)
    if (bits[t] & is_unknown) {
      system.unknown_of_texel[t] = static_cast<int>(system.texel_of_unknown.size());
      system.texel_of_unknown.push_back(t);
    }
  const int n = static_cast<int>(system.texel_of_unknown.size());
  system.b = Eigen::VectorXd::Zero(n);
  // Columns in texel order: south, west, self, east, north are increasing texel indices,
  // so the compressed matrix is filled directly without sorting.
  system.A.resize(n, n);
  if (n == 0) return system;  // reserve() on an empty matrix leaves Eigen reading past its index array
  system.A.reserve(Eigen::VectorXi::Constant(n, 5));
  for (int k = 0; k < n; ++k) {
    const int t = system.texel_of_unknown[k], i = t % w, j = t / w;
    auto couple = [&](bool coupled, int nb) {
      if (!coupled) return;
      const int col = system.unknown_of_texel[nb];
      if (col >= 0) system.A.insert(col, k) = -1.0;  // symmetric: column k, row col
      else system.b[k] += tile.values[nb];          // coupled non-unknown = Dirichlet texel
    };
    couple(j > 0 && texels_coupled_north(tile, i, j - 1), t - w);
    couple(i > 0 && texels_coupled_east(tile, i - 1, j), t - 1);
    system.A.insert(k, k) = static_cast<double>(laplace_degree(bits[t]));
    couple(texels_coupled_east(tile, i, j), t + 1);
    couple(texels_coupled_north(tile, i, j), t + w);
  }
  system.A.makeCompressed();
  (void)h;
  return system;
}

void scatter_texel_laplace_solution(const TexelLaplaceSystem& system, const Eigen::VectorXd& x, kernels::TexelTile& tile) {
  for (std::size_t t = 0; t < tile.flags.size(); ++t)
    if (!(tile.flags[t] & (kernels::dirichlet | kernels::inactive))) tile.values[t] = 0.0;
  for (std::size_t k = 0; k < system.texel_of_unknown.size(); ++k) tile.values[system.texel_of_unknown[k]] = x[k];
}

LaplaceSolveStats solve_laplace_direct(kernels::TexelTile& tile) {
  const auto start = std::chrono::steady_clock::now();
  const TexelLaplaceSystem system = assemble_texel_laplace_system(tile);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(system.b.size());
  LaplaceSolveStats stats;
  if (system.b.size() > 0 && system.b.squaredNorm() > 0) {
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky;
    const auto lock = detail::lock_cholmod();  // held through the solve below
    detail::reserve_blas_workspace(lock);
    cholesky.compute(system.A);
    if (cholesky.info() != Eigen::Success)
      throw std::runtime_error("Laplace solve: CHOLMOD could not factor the " + std::to_string(system.b.size()) +
                               "-unknown texel Laplacian (not positive definite or out of memory)");
    x = cholesky.solve(system.b);
    if (cholesky.info() != Eigen::Success || !x.allFinite())
      throw std::runtime_error("Laplace solve: CHOLMOD solve failed for " + std::to_string(system.b.size()) + " unknowns");
    stats.relative_residual = (system.b - system.A * x).norm() / system.b.norm();
  }
  scatter_texel_laplace_solution(system, x, tile);
  stats.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace dgtex

#pragma once
// Side-by-side timing of the solvers for the harmonic texel problem on identical systems
// (used by `dgtex bench laplace` and examples/bench_laplace.cpp). Every solver stops at
// the same relative residual ||b - A x|| / ||b|| of the reduced system.
// Plain functions that return their measurements (nothing kept); they use all OpenMP
// threads, so run one at a time. Times in ms, residuals relative (dimensionless).
#include <string>
#include <vector>

#include "dgtex/kernels/texel_grid.h"
#include "dgtex/laplace_direct.h"
#include "dgtex/laplace_multigrid.h"

namespace dgtex {

// multigrid: default options; multigrid_robust: coarse_solve_tolerance = 0.02 (level 1 solved
// by inner CG in every cycle, see LaplaceMultigridOptions).
enum class LaplaceBenchSolver { multigrid, multigrid_robust, cholmod, cholmod_solve, eigen_ichol_cg, boomeramg };

std::string laplace_bench_solver_name(LaplaceBenchSolver solver);
// Throws std::invalid_argument listing the valid names.
LaplaceBenchSolver parse_laplace_bench_solver(const std::string& name);
const std::vector<LaplaceBenchSolver>& all_laplace_bench_solvers();

struct LaplaceBenchRun {
  double ms = 0;            // best of the repeats (cholmod_solve: the solve after a factorisation)
  double residual = 0;      // relative residual of the result, measured on `system`
  int iterations = 0;
  double setup_ms = 0;      // multigrid: hierarchy setup within ms (of the best run); else 0
  std::vector<LaplaceConvergencePoint> history;  // residual against time (if requested)
};

// Runs `solver` `repeat` times from a zero initial guess on `problem` (whose reduced
// system is `system`) to relative residual `tolerance`. boomeramg initialises MPI (one
// rank) on first use, as Debian's hypre requires.
LaplaceBenchRun run_laplace_bench_solver(LaplaceBenchSolver solver, const kernels::TexelTile& problem,
                                         const TexelLaplaceSystem& system, double tolerance, int repeat,
                                         bool record_history);

// Achieved memory bandwidth (GB/s) of one red-black sweep of the texel smoother as the
// multigrid runs it (kernels::smooth_texels_sweep, one streaming pass) on an open T x T
// tile (bytes: x read + written, b and flag bytes read) and of a plain array copy of the
// same size (bytes read + written), in the same run.
struct SmootherBandwidth {
  double smoother_gb_per_s = 0;
  double copy_gb_per_s = 0;
};
SmootherBandwidth measure_smoother_bandwidth(int T, int repeat);

}  // namespace dgtex

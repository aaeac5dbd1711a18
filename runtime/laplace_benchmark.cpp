#include "dgtex/laplace_benchmark.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

// HYPRE needs MPI's C interface only. MPI's C++ bindings would be compiled into this
// library as 216 exported weak MPI:: symbols, which a program built against another MPI
// would get in place of its own.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_ls.h>
#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>

#include "dgtex/kernels/multigrid_smooth.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/stage_timer.h"
#include "cholmod_lock.h"

namespace dgtex {
namespace {

using Clock = std::chrono::steady_clock;

double relative_residual(const TexelLaplaceSystem& system, const Eigen::VectorXd& x) {
  const double b = system.b.norm();
  return b > 0 ? (system.b - system.A * x).norm() / b : 0.0;
}

// Runs `attempt(max_iterations)` with doubling caps to sample residual against time for
// solvers without a per-iteration callback.
template <class Attempt>
void sample_history(Attempt attempt, int iterations, std::vector<LaplaceConvergencePoint>& history) {
  for (int cap = 1; cap < iterations; cap *= 2) history.push_back(attempt(cap));
}

void ensure_mpi() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) {
    int argc = 0;
    char** argv = nullptr;
    MPI_Init(&argc, &argv);
    std::atexit([] {
      int finalised = 0;
      MPI_Finalized(&finalised);
      if (!finalised) MPI_Finalize();
    });
  }
}

// BoomerAMG as a stand-alone solver (hypre defaults: HMIS coarsening, ext+i interpolation,
// hybrid Gauss-Seidel) to the given relative residual; returns time, residual, iterations.
LaplaceBenchRun boomeramg_solve(const TexelLaplaceSystem& system, double tolerance, int max_iterations) {
  ensure_mpi();
  const int n = static_cast<int>(system.b.size());
  const auto start = Clock::now();
  HYPRE_IJMatrix ij_a;
  HYPRE_IJMatrixCreate(MPI_COMM_WORLD, 0, n - 1, 0, n - 1, &ij_a);
  HYPRE_IJMatrixSetObjectType(ij_a, HYPRE_PARCSR);
  HYPRE_IJMatrixInitialize(ij_a);
  const Eigen::SparseMatrix<double, Eigen::RowMajor> a = system.A;
  for (int row = 0; row < n; ++row) {
    HYPRE_Int count = a.outerIndexPtr()[row + 1] - a.outerIndexPtr()[row];
    HYPRE_BigInt r = row;
    std::vector<HYPRE_BigInt> cols(a.innerIndexPtr() + a.outerIndexPtr()[row], a.innerIndexPtr() + a.outerIndexPtr()[row + 1]);
    HYPRE_IJMatrixSetValues(ij_a, 1, &count, &r, cols.data(), a.valuePtr() + a.outerIndexPtr()[row]);
  }
  HYPRE_IJMatrixAssemble(ij_a);
  HYPRE_ParCSRMatrix par_a;
  HYPRE_IJMatrixGetObject(ij_a, reinterpret_cast<void**>(&par_a));
  std::vector<HYPRE_BigInt> rows(n);
  for (int k = 0; k < n; ++k) rows[k] = k;
  std::vector<double> zeros(n, 0.0);
  HYPRE_IJVector ij_b, ij_x;
  for (HYPRE_IJVector* v : {&ij_b, &ij_x}) {
    HYPRE_IJVectorCreate(MPI_COMM_WORLD, 0, n - 1, v);
    HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(*v);
  }
  HYPRE_IJVectorSetValues(ij_b, n, rows.data(), system.b.data());
  HYPRE_IJVectorSetValues(ij_x, n, rows.data(), zeros.data());
  HYPRE_IJVectorAssemble(ij_b);
  HYPRE_IJVectorAssemble(ij_x);
  HYPRE_ParVector par_b, par_x;
  HYPRE_IJVectorGetObject(ij_b, reinterpret_cast<void**>(&par_b));
  HYPRE_IJVectorGetObject(ij_x, reinterpret_cast<void**>(&par_x));
  HYPRE_Solver solver;
  HYPRE_BoomerAMGCreate(&solver);
  HYPRE_BoomerAMGSetPrintLevel(solver, 0);
  HYPRE_BoomerAMGSetTol(solver, tolerance);
  HYPRE_BoomerAMGSetMaxIter(solver, max_iterations);
  HYPRE_BoomerAMGSetup(solver, par_a, par_b, par_x);
  HYPRE_BoomerAMGSolve(solver, par_a, par_b, par_x);
  LaplaceBenchRun run;
  run.ms = ms_since(start);
  HYPRE_Int iterations = 0;
  HYPRE_BoomerAMGGetNumIterations(solver, &iterations);
  run.iterations = iterations;
  Eigen::VectorXd x(n);
  HYPRE_IJVectorGetValues(ij_x, n, rows.data(), x.data());
  run.residual = relative_residual(system, x);
  HYPRE_BoomerAMGDestroy(solver);
  HYPRE_IJMatrixDestroy(ij_a);
  HYPRE_IJVectorDestroy(ij_b);
  HYPRE_IJVectorDestroy(ij_x);
  return run;
}

LaplaceBenchRun run_once(LaplaceBenchSolver solver, const kernels::TexelTile& problem, const TexelLaplaceSystem& system,
                         double tolerance, bool record_history) {
  LaplaceBenchRun run;
  switch (solver) {
    case LaplaceBenchSolver::multigrid:
    case LaplaceBenchSolver::multigrid_robust: {
      kernels::TexelTile tile = problem;
      LaplaceMultigridOptions options;
      options.tolerance = tolerance;
      options.warm_start = false;
      if (solver == LaplaceBenchSolver::multigrid_robust) options.coarse_solve_tolerance = 0.02;
      const auto start = Clock::now();
      LaplaceMultigrid multigrid(tile, options);
      const LaplaceSolveStats stats = multigrid.solve(tile, record_history ? &run.history : nullptr);
      run.ms = ms_since(start);
      run.setup_ms = multigrid.setup_ms();
      for (LaplaceConvergencePoint& point : run.history) point.ms += run.setup_ms;  // time since the call, as for the others
      run.iterations = stats.iterations;
      Eigen::VectorXd x(system.b.size());
      for (int k = 0; k < x.size(); ++k) x[k] = tile.values[system.texel_of_unknown[k]];
      run.residual = relative_residual(system, x);
      break;
    }
    case LaplaceBenchSolver::cholmod:
    case LaplaceBenchSolver::cholmod_solve: {
      auto start = Clock::now();
      Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky;
      const auto lock = detail::lock_cholmod();  // as dgtex's own CHOLMOD calls (cholmod_lock.h)
      detail::reserve_blas_workspace(lock);
      cholesky.compute(system.A);
      if (cholesky.info() != Eigen::Success) throw std::runtime_error("bench: CHOLMOD factorisation failed");
      if (solver == LaplaceBenchSolver::cholmod_solve) start = Clock::now();
      const Eigen::VectorXd x = cholesky.solve(system.b);
      run.ms = ms_since(start);
      run.residual = relative_residual(system, x);
      if (record_history) run.history = {{0.0, 1.0}, {run.ms, run.residual}};
      break;
    }
    case LaplaceBenchSolver::eigen_ichol_cg: {
      auto solve = [&](int cap) {
        const auto start = Clock::now();
        Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                                 Eigen::IncompleteCholesky<double>> cg;
        cg.setTolerance(tolerance);
        cg.setMaxIterations(cap);
        cg.compute(system.A);
        const Eigen::VectorXd x = cg.solve(system.b);
        LaplaceBenchRun r;
        r.ms = ms_since(start);
        r.iterations = static_cast<int>(cg.iterations());
        r.residual = relative_residual(system, x);
        return r;
      };
      run = solve(100000);
      if (record_history) {
        run.history.push_back({0.0, 1.0});
        sample_history([&](int cap) { const LaplaceBenchRun r = solve(cap); return LaplaceConvergencePoint{r.ms, r.residual}; },
                       run.iterations, run.history);
        run.history.push_back({run.ms, run.residual});
      }
      break;
    }
    case LaplaceBenchSolver::boomeramg: {
      run = boomeramg_solve(system, tolerance, 1000);
      if (record_history) {
        run.history.push_back({0.0, 1.0});
        sample_history([&](int cap) { const LaplaceBenchRun r = boomeramg_solve(system, tolerance, cap); return LaplaceConvergencePoint{r.ms, r.residual}; },
                       run.iterations, run.history);
        run.history.push_back({run.ms, run.residual});
      }
      break;
    }
  }
  return run;
}

}  // namespace

std::string laplace_bench_solver_name(LaplaceBenchSolver solver) {
  switch (solver) {
    case LaplaceBenchSolver::multigrid: return "multigrid";
    case LaplaceBenchSolver::multigrid_robust: return "multigrid_robust";
    case LaplaceBenchSolver::cholmod: return "cholmod";
    case LaplaceBenchSolver::cholmod_solve: return "cholmod_solve";
    case LaplaceBenchSolver::eigen_ichol_cg: return "eigen_ichol_cg";
    case LaplaceBenchSolver::boomeramg: return "boomeramg";
  }
  return "unknown";
}

const std::vector<LaplaceBenchSolver>& all_laplace_bench_solvers() {
  static const std::vector<LaplaceBenchSolver> solvers = {LaplaceBenchSolver::multigrid,
                                                          LaplaceBenchSolver::multigrid_robust, LaplaceBenchSolver::cholmod,
                                                          LaplaceBenchSolver::cholmod_solve,
                                                          LaplaceBenchSolver::eigen_ichol_cg, LaplaceBenchSolver::boomeramg};
  return solvers;
}

LaplaceBenchSolver parse_laplace_bench_solver(const std::string& name) {
  for (LaplaceBenchSolver s : all_laplace_bench_solvers())
    if (laplace_bench_solver_name(s) == name) return s;
  throw std::invalid_argument("unknown solver '" + name +
                              "'; valid: multigrid, multigrid_robust, cholmod, cholmod_solve, eigen_ichol_cg, boomeramg");
}

LaplaceBenchRun run_laplace_bench_solver(LaplaceBenchSolver solver, const kernels::TexelTile& problem,
                                         const TexelLaplaceSystem& system, double tolerance, int repeat,
                                         bool record_history) {
  if (system.b.size() == 0) throw std::invalid_argument("bench: the problem has no unknowns");
  LaplaceBenchRun best;
  best.ms = std::numeric_limits<double>::infinity();
  for (int k = 0; k < std::max(1, repeat); ++k) {
    LaplaceBenchRun run = run_once(solver, problem, system, tolerance, record_history && k == 0);
    if (k == 0) best.history = std::move(run.history);
    if (run.ms < best.ms) {
      best.ms = run.ms;
      best.residual = run.residual;
      best.iterations = run.iterations;
      best.setup_ms = run.setup_ms;
    }
  }
  return best;
}

SmootherBandwidth measure_smoother_bandwidth(int T, int repeat) {
  const kernels::TexelTile tile = make_laplace_domain(LaplaceDomain::open, T);
  const kernels::GridShape g{T, T};
  std::vector<std::uint8_t> bits(g.padded_size(), 0);
  kernels::classify_laplace_texels_padded(tile, bits.data());
  std::vector<double> x(g.padded_size(), 0.5), b(g.padded_size(), 0.25), copy_src(g.padded_size(), 1.0),
      copy_dst(g.padded_size(), 0.0);
  double best_smooth = 1e300, best_copy = 1e300;
  for (int k = 0; k < std::max(1, repeat); ++k) {
    auto start = Clock::now();
    kernels::smooth_texels_sweep(g, bits.data(), b.data(), x.data(), k % 2 == 0);
    best_smooth = std::min(best_smooth, ms_since(start));
    start = Clock::now();
    const std::int64_t n = static_cast<std::int64_t>(copy_src.size());
    const std::int64_t chunk = 4096;
    kernels::forall((n + chunk - 1) / chunk, [&](std::int64_t c) {
      const std::int64_t begin = c * chunk, end = std::min(n, begin + chunk);
      std::memcpy(copy_dst.data() + begin, copy_src.data() + begin, (end - begin) * sizeof(double));
    });
    best_copy = std::min(best_copy, ms_since(start));
    copy_src[k % n] += copy_dst[(k * 7) % n];  // keep the copy observable
  }
  const double cells = static_cast<double>(g.padded_size());
  SmootherBandwidth bw;
  bw.smoother_gb_per_s = cells * (8 + 8 + 8 + 1) / (best_smooth * 1e6);
  bw.copy_gb_per_s = cells * 16 / (best_copy * 1e6);
  return bw;
}

}  // namespace dgtex

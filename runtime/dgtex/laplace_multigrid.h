#pragma once
// Geometric multigrid for the harmonic texel problem (dgtex/kernels/multigrid_unknowns.h):
// red-black Gauss-Seidel on the texel level (5-point operator applied straight from one
// flag byte per texel, nothing stored), black-box (operator-dependent, Galerkin) 9-point
// coarse levels that keep cuts as walls, a dense (small), band (narrow) or CHOLMOD (large)
// Cholesky on the coarsest level, used as V/F-cycles or as the preconditioner of conjugate
// gradients (the default: see laplace_multigrid.cpp for the measurements behind it).
// LaplaceMultigrid owns its level hierarchy (built from the tile at construction, the
// coarse levels then or on demand; no reference kept to the tile). Not thread-safe per
// instance; solve() uses all OpenMP threads. Values dimensionless, times in ms.
#include <memory>
#include <vector>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/texel_grid.h"
#include "dgtex/laplace_problem.h"

namespace dgtex {

enum class MultigridCycle { v, f };

struct LaplaceMultigridOptions {
  double tolerance = 1e-6;        // stop at relative residual ||b - A x|| / ||b|| <= tolerance
  int max_cycles = 100;           // cycles (or preconditioned CG iterations); throws if not converged
  MultigridCycle cycle = MultigridCycle::v;
  int pre_smoothing = 1;          // red-black (coarse: 4-colour) Gauss-Seidel sweeps before ...
  int post_smoothing = 1;         // ... and after the coarse correction (equal for CG)
  bool use_as_cg_preconditioner = true;  // one symmetric V-cycle per CG iteration
  // Tiles with at least this many texels keep the preconditioner's levels >= 1 (operators,
  // interpolation, x, b, r) in float: half their memory traffic; level 0, the outer CG and
  // its residual test stay double (CG reaches 1e-12 in the same iterations). Only with
  // use_as_cg_preconditioner and the plain cycle (coarse_solve_tolerance = 0). 0: always.
  // The default takes T = 256 tiles in (it was 2^17 before the setup's uniform regions made
  // the float setup cheap: see laplace_multigrid.cpp, session 9); smaller tiles not measured.
  long single_precision_min_texels = 1l << 16;
  bool warm_start = true;         // initial guess = tile.values of the unknowns (else 0)
  kernels::Execution execution = kernels::Execution::parallel;
  // Robust cycle for domains with features narrower than the coarse grids (a 2-texel
  // bridge, narrow channels): > 0 solves level 1 in every cycle by conjugate gradients
  // preconditioned with its own V-cycle, to this relative residual (at most 50 iterations);
  // the outer CG then uses the flexible (Polak-Ribiere) update. See laplace_multigrid.cpp.
  double coarse_solve_tolerance = 0;
  int coarsest_nodes = 64;        // coarsen until a level has at most this many nodes ...
  int max_orphans = 0;            // ... or until coarsening would leave more active nodes
                                  // without interpolation (channels narrower than the coarse
                                  // spacing), where the level is small enough to factor in
                                  // band form (~2e7 multiply-adds; larger levels coarsen on
                                  // and leave such nodes to the smoother); the last level is
                                  // solved by sparse Cholesky
};

// One point of a convergence history: time since the solve started and relative residual.
struct LaplaceConvergencePoint {
  double ms = 0;
  double relative_residual = 0;
};

// The multigrid hierarchy for one tile's flags (walls, Dirichlet and inactive texels);
// solve() may be called repeatedly with new Dirichlet values / warm starts.
class LaplaceMultigrid {
 public:
  // When the coarse levels are built: with the level-0 operator at construction, or by the
  // first solve() or precondition() that needs them. A solve whose warm start already meets
  // the tolerance needs none: an enrichment solved again because a wall appeared elsewhere in
  // its elements often is one (the slinky: 421 of its 1,232 multigrid solves).
  enum class CoarseLevels { at_construction, on_demand };
  explicit LaplaceMultigrid(const kernels::TexelTile& tile, LaplaceMultigridOptions options = {},
                            CoarseLevels coarse_levels = CoarseLevels::at_construction);
  ~LaplaceMultigrid();
  LaplaceMultigrid(LaplaceMultigrid&&) noexcept;
  LaplaceMultigrid& operator=(LaplaceMultigrid&&) noexcept;

  // Solves on `tile` (same width, height and flags as at construction) in place. Throws
  // std::invalid_argument for a different tile, std::runtime_error if the tolerance is not
  // reached within max_cycles. history, if given, receives one point per cycle (and the start).
  LaplaceSolveStats solve(kernels::TexelTile& tile, std::vector<LaplaceConvergencePoint>* history = nullptr);

  // z = M r with M the CG preconditioner (one symmetric V-cycle from zero): r and z are
  // per tile texel (tile.index(i, j)); r is read only at the unknowns (free texels of a
  // component with Dirichlet data), z is 0 elsewhere. For callers that precondition a
  // related operator with this hierarchy (e.g. the texel graph of a ring of elements, of
  // which this tile is the ring cut open). M is symmetric positive definite on the unknowns
  // and, like solve(), independent of the thread count. Needs use_as_cg_preconditioner and
  // the plain cycle (coarse_solve_tolerance = 0).
  void precondition(const std::vector<double>& r, std::vector<double>& z);
  // Whether texel t (tile.index(i, j)) is an unknown of the hierarchy.
  bool is_unknown(int t) const;

  int level_count() const;  // the levels built so far
  double setup_ms() const;   // the setup so far (with on-demand coarse levels, theirs once built)
  const LaplaceMultigridOptions& options() const;

 private:
  struct Hierarchy;
  std::unique_ptr<Hierarchy> hierarchy_;
};

// Setup + solve in one call (stats.ms includes the setup; coarse levels on demand).
LaplaceSolveStats solve_laplace_multigrid(kernels::TexelTile& tile, const LaplaceMultigridOptions& options = {},
                                          std::vector<LaplaceConvergencePoint>* history = nullptr);

}  // namespace dgtex

#include "dgtex/laplace_multigrid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <strings.h>
#include <type_traits>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "dgtex/kernels/multigrid_galerkin.h"
#include "dgtex/kernels/multigrid_residual.h"
#include "dgtex/kernels/multigrid_smooth.h"
#include "dgtex/kernels/multigrid_transfer.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/stage_timer.h"
#include "api_argument_checks.h"
#include "banded_cholesky.h"
#include "grid_nested_dissection.h"
#include "multigrid_buffer.h"

// Choices, measured with T=256/1024 single-element solves to 1e-6 from zero (1 thread):
// - V(1,1) as CG preconditioner (default): 6 iterations on open/slit/accordion (0.085 per
//   iteration) where stand-alone V(1,1) cycles need 10 (0.23); V(2,2)-CG needs 5 but costs
//   the same time; F-cycles alone do not help the hard domains (spiral 0.69 per cycle).
// - Level 0 streams: each red-black sweep is one pass over the rows (the second colour lags
//   one row), the black residual after a forward sweep is zero so only red residuals are
//   formed and restricted, the coarse correction goes to red nodes only (black is
//   recomputed next), the CG's r.z comes out of the last sweep and p-update + A p + p.Ap are
//   one pass. Together with the setup below: T=256 open 17.6 -> ~8 ms, T=1024 551 -> ~215 ms
//   (CPU time on a loaded 2-core machine; `dgtex bench laplace` gives wall times).
// - Robust cycle (options.coarse_solve_tolerance > 0, not the default): solves level 1 in
//   every cycle by CG with its own V-cycle to 2% (the outer CG then flexible). It was the
//   only way to 0.1 per cycle on spiral and chad while coarse interpolation lost energy at
//   wall corners (13-22 iterations); since interpolation is built from the lumped 5-point
//   stencil (multigrid_galerkin.h) the plain cycle needs 6-7 there, so the robust cycle only
//   adds cost (spiral T=512: 6 plain iterations, 18.7 ms with 2 threads). Kept as an option.
// - Setup: components by union-find over texel runs instead of a per-texel flood fill
//   (T=1024: ~100 -> ~23 ms), Galerkin products unrolled at compile time (T=1024 level 0:
//   60-100 -> ~10 ms), dense Cholesky for coarsest levels up to 400 unknowns (CHOLMOD's
//   analysis alone costs more for the usual 8x8 level).
// - Memory and passes (setup + solve, CPU time, 1 thread, best of 10-40, old/new side by side):
//   the level and CG arrays come zeroed from a size-keyed block cache / huge pages instead of
//   fresh 4 KiB pages filled by vector::assign (multigrid_buffer.h), 9 -> 6 level-0 arrays
//   (z stays in levels[0].x, q shares levels[0].r, no saved rhs), the rhs pass also forms
//   ||b|| and r = b for a zero initial guess, and the setup's union-find skips repeated
//   unions: open T = 256 8.4 -> 7.0 ms (setup 2.9 -> 1.7), T = 1024 224 -> 176 ms (setup 64
//   -> 36). Tried and rejected: vectorised (omp simd, both colours + blend) red-black rows:
//   2x slower than the stride-2 scalar loop (SSE2/AVX2, gathers of 1/degree); W-cycles
//   below level 0 or 1: spiral T = 512 17 -> 15-17 iterations (W from level 0: 11, but
//   slower); see also the spiral note in multigrid_galerkin.h.
// - Session 5 (setup): most level arrays come from the block cache without zero-filling
//   (frame_zeroed_buffer: ghosts zeroed, interior written before any read; a NaN-poison
//   test guards that): open T = 1024 setup 39 -> 32 ms, total 174 -> 164 ms, T = 256 7.4 ->
//   7.2 ms (1 thread, best of 3 x 15, same binary). Orphan count and coarse activity are one
//   row-parallel pass. Setup at T = 1024 before (1 thread, loaded machine, ~45 ms): level
//   0 -> 1 interpolation + Galerkin 14-18 ms, zero-filling cached blocks ~12 ms, level 1 -> 2
//   1-6 ms. The first setup of a size also pays for faulting in and clearing its fresh pages
//   (~40k faults at T = 1024; no huge-page advice since session 58, multigrid_buffer.h).
// - Session 5 (threads): with OMP_WAIT_POLICY=active, levels from 4096 nodes run parallel
//   (see parallel_min_nodes): open T = 256 7.0 -> 4.4 ms, T = 512 20.7 -> 19.3 ms (idle
//   machine, 2 threads). Not with the default policy: on a loaded machine (other processes
//   on both cores) every barrier can wait a time slice, and 2-thread T = 256 solves took
//   0.2 -> 5 s.
// - Session 6 (float cycle): from 2^17 texels (options.single_precision_min_texels) levels
//   >= 1 are built and cycled in float (level 0, the outer CG and its test stay double; CG
//   needs the same iterations and residuals to 1e-12). `dgtex bench laplace --repeat 5`, idle
//   machine, 2 threads, old/new alternating, ms (setup): active policy open T = 512 17.3 ->
//   16.3, T = 1024 79 -> 73 (18 -> 18.5), spiral 1024 79 -> 77, chad 1024 87 -> 82; passive
//   open 1024 90 -> 83, chad 1024 101 -> 94, T = 512 -1..-2 ms. Not at T = 256 (setup +0.2
//   ms of 4.1, float Galerkin converts every weight; cycles ~equal: L2-resident). 1 thread,
//   open T = 1024: solve part 126 -> 110 ms (coarse sweeps/residuals ~20% faster, level 0
//   unchanged: it is ~60% of a cycle). Not done: level-0 z in float, float arithmetic in the
//   Galerkin product, an F-cycle / nested-iteration start, one parallel region per cycle.
// - Session 7 (vector rows, kernels/multigrid_rows.h): groups of four interior texels and
//   all 9-point groups as 4-lane vectors, no gathers (unlike the rejected omp simd rows
//   above), same-row neighbours from registers. Callgrind, open T = 256: level-0 loops 626M
//   -> 175M instructions per 10 solves; idle machine, active policy, 2 threads, old/new
//   alternating: open T = 1024 64-77 -> 49-67 ms (README has the table).
// - Session 9: AVX-512 forms of the level-0 loops that read flag bytes (multigrid_rows.h), and
//   the float cycle from 2^16 texels (T = 256; since session 8's uniform regions the float
//   setup no longer costs more than it saves). Idle machine, active policy, 2 threads, best
//   of 20, old (8aa86c3) / new alternating three times, T = 256 ms: open 2.68-2.79 -> 2.39,
//   slit 2.65-3.40 -> 2.37-2.45, spiral 3.67-3.87 -> 3.33-3.41, accordion 3.70-3.83 ->
//   3.33-3.41, chad 3.12-3.40 -> 2.71-2.77. T = 1024 unchanged (31-38 ms). Tried and
//   reverted: four partial sums in the band factor and a row-oriented back substitution
//   (spiral and accordion T = 256 4.31-4.41 -> 4.27-4.39 ms, noise), as in session 8.
// - Session 10: the band factor right-looking with chunked vector axpys (banded_cholesky.h),
//   filled straight from the stencil; fused AVX-512 row pairs for the level-0 sweeps (first
//   colour on row j with the lagged second colour on row j - 1), with prefetches; loads
//   ordered against 4K aliasing between the page-aligned level arrays; two dependent loops
//   in one parallel region (forall_then). Idle machine, active policy, 2 threads, best of
//   20, old (6a04959) / new alternating three times, T = 256 ms:
//   spiral 3.12-3.19 -> 2.58-2.70, accordion 3.12-3.26 -> 2.54-2.64, open 2.20-2.25 ->
//   2.11-2.61; T = 1024 open 30-33 -> 28-30; smoother at T = 1024 45-49 % -> 54-67 % of the
//   copy bandwidth (README). Tried, no gain: the coarse cycle as one thread team whose
//   kernels share loops (`omp for`) instead of a parallel region each.
namespace dgtex {
using kernels::Execution;
using kernels::GridShape;

namespace {

using Clock = std::chrono::steady_clock;

// Levels smaller than this run serially: a parallel region costs more than the work.
// The cost depends on how idle OpenMP threads wait. Sleeping (passive) or spinning a while
// then sleeping (libgomp's default): tens of us, and on a shared machine a barrier may wait
// for a descheduled thread; on the 2-core machine (idle), open T = 256: 9.1 ms serial against
// 14.3 ms with 2 threads at bound 16384, so the bound is 131072 (T = 256 serial, T = 512
// 47 -> 36-39 ms, T = 1024 182 -> 151 ms). With OMP_WAIT_POLICY=active (the user says the
// cores are ours) a region costs ~1 us: bound 4096, open T = 256 7.0 -> 4.4 ms (bound 1024:
// 4.7 ms, within the noise; idle machine, 2 threads, best of 20). Read once per process.
long parallel_min_nodes() {
  static const long bound = [] {
    const char* policy = std::getenv("OMP_WAIT_POLICY");
    return (policy && strcasecmp(policy, "active") == 0) ? 4096l : 131072l;
  }();
  return bound;
}

// Level 0 forms and restricts its red residual in one pass (restrict_red_residual_texels)
// from this many nodes on; below, where the level fits the cache, the two-pass form is
// cheaper (the one-pass form evaluates cell-centre residuals twice). Setup + solve, CPU,
// 1 thread, open: T = 256 6.9 -> 7.4 ms one-pass, T = 512 33 ms both, T = 1024 188 -> 180 ms.
constexpr long fused_restriction_min_nodes = 1l << 19;
// Coarsest levels up to this many unknowns are factored densely; larger ones in band form
// while n * bandwidth^2 stays below banded_coarsest_max_work (a 64 x 64 grid: ~1.7e7, a few
// ms), else by CHOLMOD (nested dissection wins on wide grids).
constexpr int dense_coarsest_max = 400;
constexpr double banded_coarsest_max_work = 2e7;

using detail::FloatMultigridBuffer;
using detail::MultigridBuffer;

MultigridBuffer frame_buffer(GridShape g) { return detail::frame_zeroed_buffer(g.stride(), g.ny + 2); }
template <class Buffer>
Buffer frame_zeroed(GridShape g) {
  if constexpr (std::is_same_v<Buffer, FloatMultigridBuffer>)
    return detail::frame_zeroed_float_buffer(g.stride(), g.ny + 2);
  else
    return detail::frame_zeroed_buffer(g.stride(), g.ny + 2);
}

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
    MultigridBuffer x, b, r;
    std::vector<std::uint8_t> active;       // node has an unknown (prolongation mask)
    MultigridBuffer c, e, n, ne, nw;        // 9-point operator (levels >= 1)
    MultigridBuffer p[8];                   // interpolation to the next finer level (levels >= 1)
    kernels::Stencil9View stencil() const { return {c.data(), e.data(), n.data(), ne.data(), nw.data()}; }
    kernels::InterpolationView interpolation() const {
      return {p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data(), p[5].data(), p[6].data(), p[7].data()};
    }
    // Levels >= 1 of the single-precision cycle use these instead of the double arrays above.
    FloatMultigridBuffer xf, bf, rf, cf, ef, nf, nef, nwf, pf[8];
  };
  // A level's buffers in double or float (to allocate them).
  template <class Buffer>
  struct LevelBuffers {
    Buffer* x;
    Buffer* b;
    Buffer* r;
    Buffer* operator_and_interpolation[13];
  };
  template <class Real>
  static auto arrays_of(Level& v) {
    if constexpr (std::is_same_v<Real, float>)
      return LevelBuffers<FloatMultigridBuffer>{
          &v.xf, &v.bf, &v.rf,
          {&v.cf, &v.ef, &v.nf, &v.nef, &v.nwf, &v.pf[0], &v.pf[1], &v.pf[2], &v.pf[3], &v.pf[4], &v.pf[5], &v.pf[6],
           &v.pf[7]}};
    else
      return LevelBuffers<MultigridBuffer>{
          &v.x, &v.b, &v.r,
          {&v.c, &v.e, &v.n, &v.ne, &v.nw, &v.p[0], &v.p[1], &v.p[2], &v.p[3], &v.p[4], &v.p[5], &v.p[6], &v.p[7]}};
  }
  // The arrays a level's cycle works on, in double or float.
  template <class Real>
  struct CycleArrays {
    Real* x;
    Real* b;
    Real* r;
    std::size_t size;
    kernels::Stencil9ViewOf<Real> a;
    kernels::InterpolationViewOf<Real> p;  // to the next finer level
  };
  template <class Real>
  static CycleArrays<Real> arrays(Level& v) {
    if constexpr (std::is_same_v<Real, float>)
      return {v.xf.data(), v.bf.data(), v.rf.data(), v.xf.size(),
              {v.cf.data(), v.ef.data(), v.nf.data(), v.nef.data(), v.nwf.data()},
              {v.pf[0].data(), v.pf[1].data(), v.pf[2].data(), v.pf[3].data(), v.pf[4].data(), v.pf[5].data(),
               v.pf[6].data(), v.pf[7].data()}};
    else
      return {v.x.data(), v.b.data(), v.r.data(), v.x.size(), v.stencil(), v.interpolation()};
  }

  LaplaceMultigridOptions options;
  int width = 0, height = 0;
  std::vector<std::uint8_t> tile_flags;  // to check solve() gets the same tile
  std::vector<std::uint8_t> bits;        // level-0 operator, padded layout
  std::vector<Level> levels;
  std::vector<double> row_partial;       // per-row partial sums (deterministic reductions)
  std::vector<int> row_orphans;          // per coarse row, during the setup
  // Preconditioned CG vectors (level-0 layout). q = A p lives from its product to the next
  // update of x and r, never across a cycle, so it shares levels[0].r (the cycle's residual)
  // unless the robust cycle's flexible CG needs q after the cycle: 2 of 9 level-0 arrays
  // fewer (with the rhs kept in the preconditioner's slot, see solve()). T = 1024: 17 MB less
  // memory to fault in and clear per setup (25 MB with cg_z, below).
  // The preconditioned residual z stays where the cycle leaves it, in levels[0].x: it is
  // dead once the direction p is updated, before the next cycle starts (one array fewer).
  MultigridBuffer cg_p, cg_q;
  std::vector<std::int64_t> coarsest_nodes;
  // Simplicial: on the slinky's 97 x 33 coarsest level (3k unknowns) it factored in half
  // the supernodal code's time (1.7 against 3.5 ms with the analysis, 1 thread).
  Eigen::CholmodSimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower> coarsest_factor;
  Eigen::LLT<Eigen::MatrixXd> coarsest_dense;  // used up to dense_coarsest_max unknowns
  detail::BandedCholesky coarsest_banded;       // then while its band is narrow
  enum class CoarsestFactor { dense, banded, cholmod } coarsest_kind = CoarsestFactor::dense;
  MultigridBuffer cg_x, cg_r;                // preconditioned CG iterate and residual
  MultigridBuffer k_x, k_r, k_z, k_p, k_q, k_b, k_zero;  // level-1 CG of the robust cycle
  std::vector<double> coarse_rows;
  static constexpr int coarse_solve_max_iterations = 50;
  bool robust_coarse_solve() const { return options.coarse_solve_tolerance > 0 && levels.size() > 2; }
  int orphans_at_stop = 0;
  double setup_ms = 0;
  bool coarse_levels_built = false;
  bool float_cycle = false;  // levels >= 1 of the preconditioner in float (single_precision_min_texels)

  Execution execution_for(GridShape shape) const {
    return (options.execution == Execution::parallel && static_cast<long>(shape.nx) * shape.ny >= parallel_min_nodes())
               ? Execution::parallel : Execution::serial;
  }

  // Level 0: the texels' operator bits and the solve's vectors.
  void build_fine(const kernels::TexelTile& tile) {
    width = tile.width;
    height = tile.height;
    tile_flags = tile.flags;
    Level fine;
    fine.shape = {width, height};
    fine.execution = execution_for(fine.shape);
    bits.resize(fine.shape.padded_size());
    kernels::classify_laplace_texels_padded(tile, bits.data(), fine.execution);
    fine.active.resize(fine.shape.padded_size());
    kernels::forall(
        fine.shape.ny + 2,
        [&](std::int64_t j) {
          const std::int64_t row = j * fine.shape.stride();
          for (std::int64_t t = row; t < row + fine.shape.stride(); ++t)
            fine.active[t] = (bits[t] & kernels::is_unknown) ? 1 : 0;
        },
        fine.execution);
    // The solve's first pass writes every level-0 entry (frame_zeroed_buffer).
    for (auto* v : {&fine.x, &fine.b, &fine.r}) *v = frame_buffer(fine.shape);
    levels.clear();
    // Room for every coarse level (each halves a dimension of at most 2^31): solve() holds a
    // reference to level 0 while it has the coarse levels built.
    levels.reserve(std::numeric_limits<int>::digits + 2);
    levels.push_back(std::move(fine));
    float_cycle = static_cast<long>(width) * height >= options.single_precision_min_texels &&
                  options.use_as_cg_preconditioner &&
                  options.coarse_solve_tolerance == 0 &&
                  options.pre_smoothing > 0 && options.post_smoothing > 0;
  }

  // The coarse levels, the coarsest factor and the CG vectors, once (setup_ms grows by their time).
  void ensure_coarse_levels() {
    if (coarse_levels_built) return;
    const auto start = Clock::now();
    build_coarse_levels();
    coarse_levels_built = true;
    setup_ms += ms_since(start);
  }

  void build_coarse_levels() {
    while (static_cast<long>(levels.back().shape.nx) * levels.back().shape.ny > options.coarsest_nodes &&
           (levels.back().shape.nx > 1 || levels.back().shape.ny > 1)) {
      const std::size_t l = levels.size() - 1;
      Level coarse;
      coarse.shape = levels[l].shape.coarser();
      coarse.execution = execution_for(coarse.shape);
      const int orphans = float_cycle ? build_coarse_level<float>(levels[l], coarse, l == 0)
                                      : build_coarse_level<double>(levels[l], coarse, l == 0);
      // Orphans: this coarsening would lose part of the domain, so level l is solved
      // directly. Exception: a level too large to factor cheaply (as a band: nodes x
      // (row + 2)^2 multiply-adds) whose orphans are isolated (at most one per 4096 nodes)
      // keeps coarsening and leaves them to the smoother and CG. A single orphan beside
      // slinky's ghost texels (386 x 130 patch) had stopped its hierarchy at the texels, and
      // CHOLMOD factored all 50k of them every step (220-330 ms); with 7 levels the setup is
      // 0.6 ms and CG takes 6 iterations. One per 2048 nodes since session 45: fracture's
      // lattice patches (square-split tri6, 136 x 194) have 7 orphans at level 0 (one per
      // 3770), and stopping there factored 26k texels (43-53 ms) where 10 CG iterations take
      // 6.5 ms. Channels (the spiral: 80 orphans at 128 x 128) still stop.
      const double nodes = static_cast<double>(levels[l].shape.nx) * levels[l].shape.ny;
      const double band = levels[l].shape.nx + 2.0;
      const bool cheap_to_factor = nodes * band * band <= banded_coarsest_max_work;
      const bool isolated = orphans <= nodes / 2048;
      if (orphans > options.max_orphans && (cheap_to_factor || !isolated)) {
        orphans_at_stop = orphans;
        break;
      }
      levels.push_back(std::move(coarse));
    }
    if (float_cycle)
      factor_coarsest<float>();
    else
      factor_coarsest<double>();
    std::size_t rows = 0;
    for (const Level& level : levels) rows = std::max<std::size_t>(rows, level.shape.ny);
    row_partial.assign(rows, 0.0);
    if (robust_coarse_solve()) {
      const std::size_t n1 = levels[1].shape.padded_size();
      for (auto* v : {&k_x, &k_r, &k_z, &k_p, &k_q, &k_b, &k_zero}) *v = MultigridBuffer(n1);
      coarse_rows.assign(levels[1].shape.ny, 0.0);
    }
    if (options.use_as_cg_preconditioner) {
      // cg_p is a copy of z, cg_x and cg_r trade places with level 0's x and r (see solve()).
      for (auto* v : {&cg_p, &cg_x, &cg_r}) *v = frame_buffer(levels[0].shape);
      if (robust_coarse_solve()) cg_q = MultigridBuffer(levels[0].shape.padded_size());
    }
  }

  // Allocates `coarse` (= fine.shape.coarser()) in Real, builds its interpolation and Galerkin
  // operator from `fine` (the texel level if texels) and returns the orphan count.
  template <class Real>
  int build_coarse_level(Level& fine, Level& coarse, bool texels) {
    using Buffer = std::conditional_t<std::is_same_v<Real, float>, FloatMultigridBuffer, MultigridBuffer>;
    const auto v = arrays_of<Real>(coarse);
    const std::size_t size = coarse.shape.padded_size();
    for (Buffer* a : {v.x, v.b, v.r}) *a = Buffer(size);
    // The setup kernels write every coarse node of the operator and interpolation arrays.
    for (Buffer* a : v.operator_and_interpolation) *a = frame_zeroed<Buffer>(coarse.shape);
    Buffer* const* w = v.operator_and_interpolation;
    const kernels::Stencil9ArraysOf<Real> a{w[0]->data(), w[1]->data(), w[2]->data(), w[3]->data(), w[4]->data()};
    const kernels::InterpolationArraysOf<Real> p{w[5]->data(),  w[6]->data(),  w[7]->data(),  w[8]->data(),
                                                 w[9]->data(), w[10]->data(), w[11]->data(), w[12]->data()};
    const Execution ex = fine.execution;
    if (texels)
      kernels::coarsen_texels(fine.shape, bits.data(), p, a, ex);
    else
      kernels::coarsen_stencil9(fine.shape, arrays<Real>(fine).a, p, a, ex);
    coarse.active.assign(size, 0);
    return count_orphans_and_mark_active<Real>(fine, coarse, ex);
  }

  // Active fine nodes (not coarse points) whose interpolation row is zero: parts of the
  // domain (channels narrower than the coarse spacing) the coarse level cannot represent.
  // The same pass over the coarse rows sets coarse.active (c > 0); counts are per row.
  template <class Real>
  int count_orphans_and_mark_active(const Level& fine, Level& coarse, Execution execution) {
    const CycleArrays<Real> arrays_c = arrays<Real>(coarse);
    const kernels::InterpolationViewOf<Real> p = arrays_c.p;
    const Real* coarse_c = arrays_c.a.c;
    row_orphans.assign(coarse.shape.ny, 0);
    // Fine nodes outside the fine grid are ghosts (inactive), so no bounds checks; weights
    // are compared with 0 one by one (|a| + |b| == 0 iff both are), branch-free.
    kernels::forall(
        coarse.shape.ny,
        [&](std::int64_t J64) {
          const int J = static_cast<int>(J64);
          // Local copies: the byte stores to coarse_active may alias what they point to.
          const kernels::InterpolationViewOf<Real> w = p;
          const Real* diagonal = coarse_c;
          const std::uint8_t* active = fine.active.data();
          std::uint8_t* coarse_active = coarse.active.data();
          const std::int64_t fs = fine.shape.stride();
          int orphans = 0;
          for (int I = 0; I < coarse.shape.nx; ++I) {
            const std::int64_t c = coarse.shape.at(I, J), f = fine.shape.at(2 * I, 2 * J);
            coarse_active[c] = diagonal[c] > 0 ? 1 : 0;
            orphans += active[f + 1] & (w.xw[c] == 0) & (w.xe[c] == 0);
            orphans += active[f + fs] & (w.ys[c] == 0) & (w.yn[c] == 0);
            orphans += active[f + fs + 1] & (w.sw[c] == 0) & (w.se[c] == 0) & (w.nw[c] == 0) & (w.ne[c] == 0);
          }
          row_orphans[J] = orphans;
        },
        execution);
    int orphans = 0;
    for (int count : row_orphans) orphans += count;
    return orphans;
  }

  // Sparse Cholesky (CHOLMOD) of the coarsest operator restricted to its nodes with
  // unknowns (SPD: every column of P holds a unit entry at its own fine node).
  template <class Real>
  void factor_coarsest() {
    Level& level = levels.back();
    const kernels::Stencil9ViewOf<Real> a = arrays<Real>(level).a;
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
    // The lower triangle (row >= column) straight from the stencil into the dense and band
    // factors' storage: with a sparse matrix from triplets in between (and fresh band pages),
    // spiral T = 256's coarsest factor took 180 us instead of 110 (2 threads, idle machine).
    const std::int64_t s = g.stride();
    auto for_each_lower_entry = [&](auto&& add) {
      for (int k = 0; k < n; ++k) {
        const std::int64_t t = coarsest_nodes[k];
        auto couple = [&](std::int64_t later, double value) {
          if (index[later] >= 0 && value != 0.0) add(index[later], k, value);
        };
        if (texels) {
          const std::uint8_t m = bits[t];
          add(k, k, kernels::laplace_degree(m));
          if (m & kernels::couples_east_unknown) couple(t + 1, -1.0);
          if (m & kernels::couples_north_unknown) couple(t + s, -1.0);
          continue;
        }
        add(k, k, static_cast<double>(a.c[t]));
        couple(t + 1, a.e[t]);
        couple(t + s - 1, a.nw[t]);
        couple(t + s, a.n[t]);
        couple(t + s + 1, a.ne[t]);
      }
    };
    double band = 0;
    for_each_lower_entry([&](int row, int column, double) { band = std::max<double>(band, row - column); });
    // A dense factor for small coarsest levels: CHOLMOD's analysis alone costs more than
    // factoring a few hundred unknowns densely (measured ~0.2 ms vs ~0.02 ms for 64).
    coarsest_kind = n <= dense_coarsest_max                       ? CoarsestFactor::dense
                    : n * band * band <= banded_coarsest_max_work ? CoarsestFactor::banded
                                                                  : CoarsestFactor::cholmod;
    bool ok = true;
    if (n > 0 && coarsest_kind == CoarsestFactor::dense) {
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);  // LLT reads the lower triangle
      for_each_lower_entry([&](int row, int column, double value) { m(row, column) = value; });
      coarsest_dense.compute(m);
      ok = coarsest_dense.info() == Eigen::Success;
    } else if (n > 0 && coarsest_kind == CoarsestFactor::banded) {
      coarsest_banded.reset(n, static_cast<int>(band));
      for_each_lower_entry([&](int row, int column, double value) { coarsest_banded.set_lower(row, column, value); });
      ok = coarsest_banded.factorize();
    } else if (n > 0) {
      // Renumbered in nested-dissection order, which CHOLMOD keeps (no AMD analysis); the
      // new numbers put some couplings above the diagonal, so each is stored below it.
      coarsest_nodes = detail::grid_nested_dissection_order(g, level.active.data());
      for (int k = 0; k < n; ++k) index[coarsest_nodes[k]] = k;
      std::vector<Eigen::Triplet<double>> entries;  // the lower triangle, which CHOLMOD reads (Eigen::Lower)
      for_each_lower_entry([&](int row, int column, double value) {
        entries.emplace_back(std::max(row, column), std::min(row, column), value);
      });
      Eigen::SparseMatrix<double> m(n, n);
      m.setFromTriplets(entries.begin(), entries.end());
      // Simplicial in a given order: neither BLAS nor METIS, so no lock (cholmod_lock.h).
      cholmod_common& common = coarsest_factor.cholmod();
      common.nmethods = 1;
      common.method[0].ordering = CHOLMOD_NATURAL;
      coarsest_factor.compute(m);
      ok = coarsest_factor.info() == Eigen::Success;
    }
    if (!ok)
      throw std::runtime_error("Laplace multigrid: the coarsest operator (" + std::to_string(n) +
                               " nodes) is not positive definite; this is a bug, please report the tile");
  }

  // Level-0 sweeps and residual (coarse levels: coarse_cycle).
  void smooth0(bool forward, int sweeps, double* last_row_dot = nullptr) {
    Level& level = levels[0];
    for (int sweep = 0; sweep < sweeps; ++sweep)
      kernels::smooth_texels_sweep(level.shape, bits.data(), level.b.data(), level.x.data(), forward, level.execution,
                                   sweep + 1 == sweeps ? last_row_dot : nullptr);
  }

  void residual0(double* row_norm2) {
    Level& level = levels[0];
    kernels::residual_texels(level.shape, bits.data(), level.b.data(), level.x.data(), level.r.data(), row_norm2,
                             level.execution);
  }

  template <class Real>
  void solve_coarsest() {
    const CycleArrays<Real> level = arrays<Real>(levels.back());
    const int n = static_cast<int>(coarsest_nodes.size());
    if (n == 0) return;
    Eigen::VectorXd rhs(n);
    for (int k = 0; k < n; ++k) rhs[k] = level.b[coarsest_nodes[k]];
    Eigen::VectorXd solution;
    if (coarsest_kind == CoarsestFactor::dense) {
      solution = coarsest_dense.solve(rhs);
    } else if (coarsest_kind == CoarsestFactor::banded) {
      coarsest_banded.solve(rhs, solution);
    } else {
      solution = coarsest_factor.solve(rhs);
    }
    for (int k = 0; k < n; ++k) level.x[coarsest_nodes[k]] = static_cast<Real>(solution[k]);
  }

  // One cycle on level l for A_l x_l = b_l, improving x_l in place (x_l = 0 on entry if
  // zero_guess; then it need not be initialised).
  //
  // Level 0 exploits red-black structure (exact-arithmetic identities, so the cycle is the
  // same linear operator and stays symmetric for CG): after the forward sweep the black
  // residual vanishes, so only red residuals are computed and restricted; the backward sweep
  // starts black, and black updates ignore old black values, so only red nodes receive the
  // coarse correction. This halves residual, restriction and prolongation traffic.
  // row_dot (level 0 with post-smoothing only): per-row sums of b * x of the result.
  // first_sweep_done (level 0, zero_guess): x already holds the first forward sweep from zero
  // (done by the fused CG update).
  void cycle(std::size_t l, MultigridCycle type, bool zero_guess, double* row_dot = nullptr,
             bool first_sweep_done = false) {
    Level& level = levels[l];
    if (l > 0 || l + 1 == levels.size()) {
      coarse_cycle<double>(l, type, zero_guess);
      return;
    }
    Level& coarse = levels[l + 1];
    const int pre = options.pre_smoothing, post = options.post_smoothing;
    {
      int sweeps = pre;
      if (zero_guess && sweeps > 0) {
        if (!first_sweep_done)
          kernels::smooth_texels_sweep_from_zero(level.shape, bits.data(), level.b.data(), level.x.data(),
                                                 level.execution);
        --sweeps;
      } else if (zero_guess) {
        std::fill(level.x.begin(), level.x.end(), 0.0);
      }
      smooth0(true, sweeps);
      // float_cycle: the same steps with level 1 and below in float (pre, post > 0 there).
      const bool fused = static_cast<long>(level.shape.nx) * level.shape.ny >= fused_restriction_min_nodes;
      if (pre > 0 && fused) {
        if (float_cycle)
          kernels::restrict_red_residual_texels(level.shape, coarse.shape, arrays<float>(coarse).p, bits.data(),
                                                level.b.data(), level.x.data(), coarse.bf.data(), level.execution);
        else
          kernels::restrict_red_residual_texels(level.shape, coarse.shape, coarse.interpolation(), bits.data(),
                                                level.b.data(), level.x.data(), coarse.b.data(), level.execution);
      } else if (pre > 0) {
        kernels::residual_texels_color(level.shape, bits.data(), level.b.data(), level.x.data(), level.r.data(), 0,
                                       level.execution);
        if (float_cycle)
          kernels::restrict_red_residual(level.shape, coarse.shape, arrays<float>(coarse).p, level.r.data(),
                                         coarse.bf.data(), coarse.execution);
        else
          kernels::restrict_red_residual(level.shape, coarse.shape, coarse.interpolation(), level.r.data(),
                                         coarse.b.data(), coarse.execution);
      } else {
        residual0(nullptr);
        kernels::restrict_residual(level.shape, coarse.shape, coarse.interpolation(), level.r.data(),
                                   coarse.b.data(), coarse.execution);
      }
    }
    if (robust_coarse_solve())
      solve_level1_by_cg();
    else if (float_cycle)
      coarse_cycle<float>(1, MultigridCycle::v, true);
    else
      cycle(1, type, true);
    if (type == MultigridCycle::f) cycle(1, MultigridCycle::v, false);
    if (post > 0 && float_cycle)
      kernels::prolong_correction_red(level.shape, coarse.shape, arrays<float>(coarse).p, coarse.xf.data(),
                                      level.active.data(), level.x.data(), level.execution);
    else if (post > 0)
      kernels::prolong_correction_red(level.shape, coarse.shape, coarse.interpolation(), coarse.x.data(),
                                      level.active.data(), level.x.data(), level.execution);
    else
      kernels::prolong_correction(level.shape, coarse.shape, coarse.interpolation(), coarse.x.data(),
                                  level.active.data(), level.x.data(), level.execution);
    smooth0(false, post, row_dot);
  }

  // The cycle on a coarse level l >= 1 (or on level 0 when it is the coarsest), in double or
  // in float (float_cycle: V-cycles from zero only).
  template <class Real>
  void coarse_cycle(std::size_t l, MultigridCycle type, bool zero_guess) {
    Level& level = levels[l];
    const CycleArrays<Real> v = arrays<Real>(level);
    if (zero_guess) std::fill(v.x, v.x + v.size, Real(0));
    if (l + 1 == levels.size()) {
      solve_coarsest<Real>();  // exact: overwrites every unknown
      return;
    }
    Level& coarse = levels[l + 1];
    const CycleArrays<Real> vc = arrays<Real>(coarse);
    for (int sweep = 0; sweep < options.pre_smoothing; ++sweep)
      kernels::smooth_stencil9_sweep(level.shape, v.a, v.b, v.x, true, level.execution);
    kernels::residual_stencil9(level.shape, v.a, v.b, v.x, v.r, nullptr, level.execution);
    kernels::restrict_residual(level.shape, coarse.shape, vc.p, v.r, vc.b, coarse.execution);
    coarse_cycle<Real>(l + 1, type, true);
    if (type == MultigridCycle::f) coarse_cycle<Real>(l + 1, MultigridCycle::v, false);
    kernels::prolong_correction(level.shape, coarse.shape, vc.p, vc.x, level.active.data(), v.x, level.execution);
    for (int sweep = 0; sweep < options.post_smoothing; ++sweep)
      kernels::smooth_stencil9_sweep(level.shape, v.a, v.b, v.x, false, level.execution);
  }

  double level0_residual_norm() {
    residual0(row_partial.data());
    row_partial.resize(levels[0].shape.ny);
    const double norm = std::sqrt(sum_in_order(row_partial));
    return norm;
  }

  // Deterministic dot product over the level-0 layout (rows summed in order).
  // Deterministic dot product on level l: per-row sums into `rows`, then summed in order.
  double dot_on(std::size_t l, const MultigridBuffer& a, const MultigridBuffer& b, std::vector<double>& rows) {
    const GridShape g = levels[l].shape;
    rows.resize(g.ny);
    kernels::forall(
        g.ny,
        [&](std::int64_t j) {
          const std::int64_t row = g.at(0, static_cast<int>(j));
          double sum = 0;
          for (int i = 0; i < g.nx; ++i) sum += a[row + i] * b[row + i];
          rows[j] = sum;
        },
        levels[l].execution);
    return sum_in_order(rows);
  }

  // Level 1 solved to options.coarse_solve_tolerance by CG preconditioned with the level-1
  // V-cycle, from x = 0 (the coarse solve of the robust cycle).
  void solve_level1_by_cg() {
    Level& level = levels[1];
    const GridShape g = level.shape;
    const Execution ex = level.execution;
    k_b.swap(level.b);  // the right-hand side; level.b is the preconditioner's input from here
    std::copy(k_b.begin(), k_b.end(), k_r.begin());
    std::fill(k_x.begin(), k_x.end(), 0.0);
    const double b2 = dot_on(1, k_r, k_r, coarse_rows), target = options.coarse_solve_tolerance * options.coarse_solve_tolerance * b2;
    double rz = 0, r2 = b2;
    for (int it = 0; it < coarse_solve_max_iterations && r2 > target; ++it) {
      level.b.swap(k_r);
      cycle(1, MultigridCycle::v, true);
      level.b.swap(k_r);
      k_z.swap(level.x);
      const double rz_new = dot_on(1, k_r, k_z, coarse_rows);
      const double beta = it == 0 ? 0.0 : rz_new / rz;
      rz = rz_new;
      kernels::forall(
          g.ny,
          [&](std::int64_t j) {
            const std::int64_t row = g.at(0, static_cast<int>(j));
            for (int i = 0; i < g.nx; ++i) k_p[row + i] = k_z[row + i] + beta * k_p[row + i];
          },
          ex);
      // k_q = 0 - A p (the residual kernel with b = 0).
      kernels::residual_stencil9(g, level.stencil(), k_zero.data(), k_p.data(), k_q.data(), nullptr, ex);
      const double pq = -dot_on(1, k_p, k_q, coarse_rows);
      if (!(pq > 0)) break;
      const double alpha = rz / pq;
      kernels::forall(
          g.ny,
          [&](std::int64_t j) {
            const std::int64_t row = g.at(0, static_cast<int>(j));
            double norm2 = 0;
            for (int i = 0; i < g.nx; ++i) {
              k_x[row + i] += alpha * k_p[row + i];
              k_r[row + i] += alpha * k_q[row + i];
              norm2 += k_r[row + i] * k_r[row + i];
            }
            coarse_rows[j] = norm2;
          },
          ex);
      r2 = 0;
      for (int j = 0; j < g.ny; ++j) r2 += coarse_rows[j];
    }
    k_x.swap(level.x);
    k_b.swap(level.b);
  }

  double dot(const MultigridBuffer& a, const MultigridBuffer& b) { return dot_on(0, a, b, row_partial); }
};

LaplaceMultigrid::LaplaceMultigrid(const kernels::TexelTile& tile, LaplaceMultigridOptions options,
                                   CoarseLevels coarse_levels)
    : hierarchy_(std::make_unique<Hierarchy>()) {
  const auto start = Clock::now();
  validate_laplace_tile(tile);
  if (!(options.tolerance > 0) || options.max_cycles < 1 || options.pre_smoothing < 0 || options.post_smoothing < 0 ||
      options.pre_smoothing + options.post_smoothing < 1 || options.coarsest_nodes < 1 ||
      !(options.coarse_solve_tolerance >= 0 && options.coarse_solve_tolerance < 1))
    throw std::invalid_argument(
        "Laplace multigrid: invalid options (need tolerance > 0, max_cycles >= 1, pre/post smoothing >= 0 with at "
        "least one sweep, coarsest_nodes >= 1, 0 <= coarse_solve_tolerance < 1)");
  if (options.use_as_cg_preconditioner &&
      (options.cycle != MultigridCycle::v || options.pre_smoothing != options.post_smoothing))
    throw std::invalid_argument(
        "Laplace multigrid: a CG preconditioner must be symmetric: use V-cycles with pre_smoothing == post_smoothing "
        "(got " + std::to_string(options.pre_smoothing) + " and " + std::to_string(options.post_smoothing) + ")");
  hierarchy_->options = options;
  hierarchy_->build_fine(tile);
  hierarchy_->setup_ms = ms_since(start);
  if (coarse_levels == CoarseLevels::at_construction) hierarchy_->ensure_coarse_levels();
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
  // The same pass forms the row sums of b^2 (the order of dot()) and sets r = b, which is
  // the initial residual when the initial guess is zero (bench, first solves): two passes
  // over level 0 fewer (of ~50 per solve at 6 iterations), bitwise the same results.
  h.row_partial.resize(g.ny);
  std::vector<std::uint8_t> row_has_guess(g.ny, 0);
  kernels::forall(
      g.ny,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        double b2 = 0;
        // The initial guess of unknown t from tile value k (x = 0 already): with a warm start,
        // the texel's value where it is finite and not 0.
        const auto take_guess = [&](std::int64_t t, int k) {
          const double guess = tile.values[k];
          if (o.warm_start && std::isfinite(guess) && guess != 0.0) fine.x[t] = guess, row_has_guess[j] = 1;
        };
        for (int i = 0; i < g.nx; ++i) {
          const std::int64_t t = g.at(i, j);
          // Four unknowns coupled to four unknowns each: b = r = 0 (b2 += 0 changes nothing),
          // x = 0 or the guess (as below). Callgrind, open T = 1024: this pass 41 -> 15
          // instructions a texel without a guess to read.
          if ((i & 3) == 0 && i + 4 <= g.nx && kernels::four_interior_texels(&h.bits[t])) {
            for (int l = 0; l < 4; ++l) fine.b[t + l] = fine.r[t + l] = fine.x[t + l] = 0.0;
            if (o.warm_start)
              for (int l = 0; l < 4; ++l) take_guess(t + l, tile.index(i + l, j));
            i += 3;
            continue;
          }
          fine.b[t] = 0.0;
          fine.r[t] = 0.0;
          fine.x[t] = 0.0;
          if (!(h.bits[t] & kernels::is_unknown)) continue;
          const int k = tile.index(i, j);
          // Coupled Dirichlet neighbours (the unknown itself is active), in the order west,
          // east, south, north, written out on the flags (kernels::texels_coupled_east/north).
          // An unknown coupled to four unknowns (most texels) has none: its flags are not read
          // (callgrind, open T = 256: this pass ~75 -> ~30 instructions a texel).
          const std::uint8_t* f = tile.flags.data();
          constexpr std::uint8_t dirichlet = kernels::dirichlet, inactive = kernels::inactive;
          constexpr std::uint8_t four_unknown_neighbours = kernels::couples_west_unknown |
                                                           kernels::couples_east_unknown |
                                                           kernels::couples_south_unknown |
                                                           kernels::couples_north_unknown;
          double b = 0;
          if ((h.bits[t] & four_unknown_neighbours) != four_unknown_neighbours) {
            if (i > 0 && (f[k - 1] & (kernels::wall_east | inactive | dirichlet)) == dirichlet) b += tile.values[k - 1];
            if (i + 1 < g.nx && !(f[k] & kernels::wall_east) && (f[k + 1] & (inactive | dirichlet)) == dirichlet)
              b += tile.values[k + 1];
            if (j > 0 && (f[k - g.nx] & (kernels::wall_north | inactive | dirichlet)) == dirichlet)
              b += tile.values[k - g.nx];
            if (j + 1 < g.ny && !(f[k] & kernels::wall_north) && (f[k + g.nx] & (inactive | dirichlet)) == dirichlet)
              b += tile.values[k + g.nx];
          }
          fine.b[t] = b;
          fine.r[t] = b;
          b2 += b * b;
          take_guess(t, k);
        }
        h.row_partial[j] = b2;
      },
      fine.execution);

  LaplaceSolveStats stats;
  const double b_norm = std::sqrt(sum_in_order(h.row_partial));
  const bool zero_guess = std::find(row_has_guess.begin(), row_has_guess.end(), 1) == row_has_guess.end();
  auto record = [&](double relative) {
    if (history) history->push_back({ms_since(start), relative});
  };
  if (b_norm > 0) {
    double relative = zero_guess ? 1.0 : h.level0_residual_norm() / b_norm;  // r = b for x = 0
    record(relative);
    if (relative > o.tolerance) h.ensure_coarse_levels();
    if (!o.use_as_cg_preconditioner) {
      while (relative > o.tolerance && stats.iterations < o.max_cycles) {
        h.cycle(0, o.cycle, false);
        ++stats.iterations;
        relative = h.level0_residual_norm() / b_norm;
        record(relative);
      }
    } else if (relative > o.tolerance) {
      // Preconditioned CG: z = V-cycle(r) from a zero initial guess. Vectors are swapped in
      // and out of level 0 (no copies): fine.b holds r while the cycle runs (and cg_r the rhs).
      h.cg_x.swap(fine.x);
      h.cg_r.swap(fine.r);
      MultigridBuffer& cg_q = h.robust_coarse_solve() ? h.cg_q : fine.r;  // see Hierarchy::cg_q
      // z = M r and r . z; the dot product comes out of the last smoothing sweep when there is one.
      // The first forward sweep from zero can be fused into the CG update of x and r.
      const bool fused_first_sweep = o.pre_smoothing > 0 && h.levels.size() > 1;
      auto precondition = [&](bool first_sweep_done) {
        fine.b.swap(h.cg_r);
        const bool fused_dot = o.post_smoothing > 0 && h.levels.size() > 1;
        h.cycle(0, MultigridCycle::v, true, fused_dot ? h.row_partial.data() : nullptr, first_sweep_done);
        fine.b.swap(h.cg_r);
        if (!fused_dot) return h.dot(h.cg_r, fine.x);  // z = fine.x
        h.row_partial.resize(g.ny);
        return sum_in_order(h.row_partial);
      };
      double rz = precondition(false);
      std::copy(fine.x.begin(), fine.x.end(), h.cg_p.begin());
      kernels::apply_texels(g, h.bits.data(), h.cg_p.data(), cg_q.data(), h.row_partial.data(), fine.execution);
      while (relative > o.tolerance && stats.iterations < o.max_cycles) {
        h.row_partial.resize(g.ny);
        const double pq = sum_in_order(h.row_partial);  // p . A p
        if (!(pq > 0)) break;  // the search direction vanished: converged to round-off
        const double alpha = rz / pq;
        double* x = h.cg_x.data();
        double* r = h.cg_r.data();
        const double* pp = h.cg_p.data();
        const double* q = cg_q.data();
        if (fused_first_sweep) {
          kernels::cg_update_and_smooth_texels_from_zero(g, h.bits.data(), alpha, pp, q, x, r, fine.x.data(),
                                                         h.row_partial.data(), fine.execution);
        } else {
          kernels::forall(
              g.ny,
              [&](std::int64_t j) {
                const std::int64_t row = g.at(0, static_cast<int>(j));
                double norm2 = 0;
                for (int i = 0; i < g.nx; ++i) {
                  x[row + i] += alpha * pp[row + i];
                  r[row + i] -= alpha * q[row + i];
                  norm2 += r[row + i] * r[row + i];
                }
                h.row_partial[j] = norm2;
              },
              fine.execution);
        }
        relative = std::sqrt(sum_in_order(h.row_partial)) / b_norm;
        ++stats.iterations;
        record(relative);
        if (relative <= o.tolerance) break;
        const double rz_new = precondition(fused_first_sweep);
        double beta = rz_new / rz;
        // The robust cycle's inner CG makes the preconditioner depend on r: flexible CG
        // (Polak-Ribiere: beta = z_new . (r_new - r_old) / (z_old . r_old), r_new - r_old = -alpha q).
        if (h.robust_coarse_solve()) beta = -alpha * h.dot(fine.x, cg_q) / rz;
        rz = rz_new;
        kernels::update_direction_and_apply_texels(g, h.bits.data(), fine.x.data(), beta, h.cg_p.data(),
                                                   cg_q.data(), h.row_partial.data(), fine.execution);
      }
      h.cg_x.swap(fine.x);
      relative = h.level0_residual_norm() / b_norm;  // the true residual, not the recursive one
    }
    stats.relative_residual = relative;
    if (!(relative <= o.tolerance))
      throw std::runtime_error("Laplace multigrid: relative residual " + detail::short_number(relative) + " after " +
                               std::to_string(stats.iterations) + " cycles, tolerance " +
                               detail::short_number(o.tolerance) + " not reached; raise max_cycles or use the cholmod solver");
  } else {
    record(0.0);
    std::fill(fine.x.begin(), fine.x.end(), 0.0);
  }

  // Write back: unknowns get the solution, other free texels (no Dirichlet data) 0.
  kernels::forall(
      g.ny,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        const std::uint8_t* flags = tile.flags.data() + tile.index(0, j);
        double* values = tile.values.data() + tile.index(0, j);
        const std::uint8_t* bits = h.bits.data() + g.at(0, j);
        const double* x = fine.x.data() + g.at(0, j);
        for (int i = 0; i < g.nx; ++i) {
          if ((i & 3) == 0 && i + 4 <= g.nx && kernels::four_interior_texels(bits + i)) {  // four unknowns
            std::memcpy(values + i, x + i, 4 * sizeof(double));
            i += 3;
            continue;
          }
          if (flags[i] & (kernels::dirichlet | kernels::inactive)) continue;
          values[i] = (bits[i] & kernels::is_unknown) ? x[i] : 0.0;
        }
      },
      fine.execution);
  stats.ms = ms_since(start);
  return stats;
}

bool LaplaceMultigrid::is_unknown(int t) const {
  const Hierarchy& h = *hierarchy_;
  if (t < 0 || t >= h.width * h.height)
    throw std::out_of_range("LaplaceMultigrid::is_unknown: texel " + std::to_string(t) + " outside the " +
                            std::to_string(h.width) + "x" + std::to_string(h.height) + " tile");
  return h.bits[h.levels[0].shape.at(t % h.width, t / h.width)] & kernels::is_unknown;
}

void LaplaceMultigrid::precondition(const std::vector<double>& r, std::vector<double>& z) {
  Hierarchy& h = *hierarchy_;
  const std::size_t texels = static_cast<std::size_t>(h.width) * h.height;
  if (r.size() != texels)
    throw std::invalid_argument("LaplaceMultigrid::precondition: " + std::to_string(r.size()) + " values for a " +
                                std::to_string(h.width) + "x" + std::to_string(h.height) + " tile");
  h.ensure_coarse_levels();
  if (!h.options.use_as_cg_preconditioner || h.robust_coarse_solve())
    throw std::logic_error("LaplaceMultigrid::precondition needs use_as_cg_preconditioner and the plain cycle "
                           "(coarse_solve_tolerance = 0): only then is M a fixed symmetric operator");
  auto& fine = h.levels[0];
  const GridShape g = fine.shape;
  // Same layout as solve(): b at the unknowns, 0 elsewhere (ghosts included, written by the
  // frame-zeroed buffer); the cycle leaves z in fine.x.
  kernels::forall(
      g.ny,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        for (int i = 0; i < g.nx; ++i) {
          const std::int64_t t = g.at(i, j);
          fine.b[t] = (h.bits[t] & kernels::is_unknown) ? r[static_cast<std::size_t>(j) * h.width + i] : 0.0;
          fine.x[t] = 0.0;
        }
      },
      fine.execution);
  h.cycle(0, MultigridCycle::v, true);
  z.resize(texels);
  kernels::forall(
      g.ny,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        for (int i = 0; i < g.nx; ++i) {
          const std::int64_t t = g.at(i, j);
          z[static_cast<std::size_t>(j) * h.width + i] = (h.bits[t] & kernels::is_unknown) ? fine.x[t] : 0.0;
        }
      },
      fine.execution);
}

LaplaceSolveStats solve_laplace_multigrid(kernels::TexelTile& tile, const LaplaceMultigridOptions& options,
                                          std::vector<LaplaceConvergencePoint>* history) {
  const auto start = Clock::now();
  LaplaceMultigrid multigrid(tile, options, LaplaceMultigrid::CoarseLevels::on_demand);
  LaplaceSolveStats stats = multigrid.solve(tile, history);
  stats.ms = ms_since(start);
  return stats;
}

}  // namespace dgtex

// The corotated step solver that reuses an old Cholesky factor as a PCG preconditioner
// (FactorReusingSolver): it meets its stated relative-residual bound, matches a fresh
// factorisation per step, refactorises when the preconditioner goes stale (sooner for
// large dense systems), and gives bitwise the same result for any thread count.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "dgtex/factor_reusing_solver.h"
#include "dgtex/shell_simulation.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

// A compressed closed cylinder (as the buckling scene, coarser and loaded harder so that
// the corotation changes the matrix noticeably from step to step).
struct CompressedCylinder {
  Mesh mesh = make_cylinder(0.5, 2.0, 0, 360, 10, 6, ElementType::quad8);
  std::unique_ptr<ShellModel> model;
  std::vector<char> fixed;
  std::vector<double> load;
  DynamicsOptions options;
  CompressedCylinder() {
    auto bottom = [](const double* x) { return x[1] < 1e-9; };
    auto top = [](const double* x) { return x[1] > 2 - 1e-9; };
    model = make_model(mesh, Material{}, 1.0, [&](const double* x) { return bottom(x) || top(x); });
    fix_nodes(mesh, bottom, true, true, true, fixed);
    fix_nodes(mesh, top, true, false, true, fixed);
    load.assign(model->num_dofs(), 0.0);
    const double g[3] = {0, -400, 0};
    model->add_gravity(g, load);
    options.time_step = 2e-3;
    options.corotational = true;
    options.mass_damping = 1.0;
  }
};

// The cylinder's rest stiffness K and free-DOF system, and a factor for the solver to fill.
struct CylinderSystem {
  CompressedCylinder c;
  std::vector<double> K;
  FreeDofSystem system;
  SparseCholesky cholesky;
  CylinderSystem() : system(c.model->pattern(), c.fixed) { c.model->assemble_stiffness(nullptr, K, nullptr); }
};

// A cylinder of `around` x `high` quad8 elements clamped at the bottom, and its free-DOF
// system (at the sizes used here, small enough to be factored densely).
struct BottomHeldCylinder {
  static bool bottom(const double* x) { return x[1] < 1e-9; }
  static std::vector<char> bottom_fixed(const Mesh& mesh) {
    std::vector<char> fixed;
    fix_nodes(mesh, bottom, true, true, true, fixed);
    return fixed;
  }
  Mesh mesh;
  std::unique_ptr<ShellModel> model;
  std::vector<char> fixed;
  FreeDofSystem system;
  BottomHeldCylinder(int around, int high)
      : mesh(make_cylinder(0.5, 2.0, 0, 360, around, high, ElementType::quad8)),
        model(make_model(mesh, Material{}, 1.0, bottom)),
        fixed(bottom_fixed(mesh)),
        system(model->pattern(), fixed) {}
  bool factored_densely() const {
    return SparseCholesky::factors_densely(system.size(), static_cast<std::int64_t>(system.row_index().size()));
  }
};

double norm_free(const std::vector<double>& v, const std::vector<char>& fixed) {
  double s = 0;
  for (size_t d = 0; d < v.size(); ++d)
    if (!fixed[d]) s += v[d] * v[d];
  return std::sqrt(s);
}

TEST(FactorReuse, EveryStepMeetsTheResidualBoundAndMatchesAFreshFactorisation) {
  CompressedCylinder c;
  ShellSimulation reused(*c.model, c.fixed, c.load), fresh(*c.model, c.fixed, c.load);
  const double tolerance = FactorReuseOptions{}.relative_tolerance;
  DynamicsOptions direct = c.options;
  direct.reuse_factorization = false;
  const int steps = 16;
  const int n = c.model->num_dofs();
  double worst_residual = 0;
  for (int s = 0; s < steps; ++s) {
    // The step's system, assembled independently: A v+ = b.
    std::vector<double> current(c.mesh.positions), K, corrective, Mv(n), Kv(n), Ku(n);
    for (int d = 0; d < n; ++d) current[d] += reused.displacement()[d];
    c.model->assemble_stiffness(current.data(), K, &corrective);
    const double dt = c.options.time_step, mass_scale = 1 + dt * c.options.mass_damping;
    block_multiply(c.model->pattern(), c.model->mass_blocks().data(), reused.velocity().data(), Mv.data());
    block_multiply(c.model->pattern(), K.data(), reused.displacement().data(), Ku.data());
    std::vector<double> b(n);
    for (int d = 0; d < n; ++d) b[d] = c.fixed[d] ? 0.0 : Mv[d] + dt * (c.load[d] + corrective[d] - Ku[d]);
    reused.step(c.options);
    fresh.step(direct);
    const std::vector<double>& v = reused.velocity();
    block_multiply(c.model->pattern(), c.model->mass_blocks().data(), v.data(), Mv.data());
    block_multiply(c.model->pattern(), K.data(), v.data(), Kv.data());
    std::vector<double> r(n);
    for (int d = 0; d < n; ++d) r[d] = b[d] - (mass_scale * Mv[d] + dt * dt * Kv[d]);
    worst_residual = std::max(worst_residual, norm_free(r, c.fixed) / norm_free(b, c.fixed));
  }
  const FactorReuseStatistics& stats = reused.solver_statistics();
  std::printf("%d steps: %ld factorisations, %ld PCG iterations, worst true relative residual %.2e\n", steps,
              stats.factorizations, stats.iterations, worst_residual);
  // The PCG recurrence residual is what the solver bounds; the true one may drift from it
  // by round-off accumulated over the few iterations: allow 2x.
  EXPECT_LE(worst_residual, 2 * tolerance);
  EXPECT_LT(stats.factorizations, steps / 2);  // the factor really is reused
  EXPECT_GE(stats.iterations, steps);
  // Displacements after 16 steps agree with the factorise-every-step path to a few times
  // the per-step tolerance (the errors of the steps add up, scaled by the conditioning).
  double diff = 0, scale = 0;
  for (int d = 0; d < n; ++d) {
    diff = std::max(diff, std::abs(reused.displacement()[d] - fresh.displacement()[d]));
    scale = std::max(scale, std::abs(fresh.displacement()[d]));
  }
  std::printf("max |u_reused - u_fresh| / max |u_fresh| = %.2e\n", diff / scale);
  EXPECT_GT(scale, 1e-3);  // the cylinder did deform
  EXPECT_LE(diff, 1e-6 * scale);
}

TEST(FactorReuse, ResultIsBitwiseIndependentOfThreadCountAcrossRefactorisations) {
  CompressedCylinder c;
  FactorReuseOptions often;
  often.refactor_after_iterations = 1;  // refactorise every few steps
  std::vector<double> reference;
  long reference_factorizations = 0;
  for (int threads : {1, 2, 4}) {
    const test::ThreadCountGuard set_threads(threads);
    ShellSimulation sim(*c.model, c.fixed, c.load);
    sim.set_solver_options(often);
    for (int s = 0; s < 10; ++s) sim.step(c.options);
    if (reference.empty()) {
      reference = sim.displacement();
      reference_factorizations = sim.solver_statistics().factorizations;
      EXPECT_GT(reference_factorizations, 2);
    }
    EXPECT_EQ(sim.displacement(), reference) << threads << " threads";
    EXPECT_EQ(sim.solver_statistics().factorizations, reference_factorizations) << threads << " threads";
  }
}

TEST(FactorReuse, DenseFactorisationsInTurnGiveTheSameBitsAtAnyThreadCount) {
  // Pending dense factorisations run before the assembly, not beside it (step()); the
  // steps must still meet the bound, refactorise, and not depend on the thread count.
  const BottomHeldCylinder c(8, 4);
  ASSERT_TRUE(c.factored_densely());
  std::vector<double> load(c.model->num_dofs(), 0.0);
  const double g[3] = {4000, 0, 0};  // sideways: the cylinder swings and its K rotates
  c.model->add_gravity(g, load);
  DynamicsOptions options;
  options.time_step = 1e-2;
  options.corotational = true;
  FactorReuseOptions often;
  often.refactor_after_iterations = 1;
  std::vector<double> reference;
  for (int threads : {1, 2, 4}) {
    const test::ThreadCountGuard set_threads(threads);
    ShellSimulation sim(*c.model, c.fixed, load);
    sim.set_solver_options(often);
    for (int s = 0; s < 10; ++s) {
      sim.step(options);
      EXPECT_LE(sim.solver_statistics().last_relative_residual, often.relative_tolerance);
    }
    EXPECT_GT(sim.solver_statistics().factorizations, 2) << threads << " threads";
    std::printf("%d threads: %ld factorisations, %ld PCG iterations\n", threads,
                sim.solver_statistics().factorizations, sim.solver_statistics().iterations);
    if (reference.empty()) reference = sim.displacement();
    EXPECT_EQ(sim.displacement(), reference) << threads << " threads";
  }
}

TEST(FactorReuse, StalePreconditionerIsReplacedAndTheBoundStillHolds) {
  CylinderSystem cylinder;
  CompressedCylinder& c = cylinder.c;
  const std::vector<double>& K = cylinder.K;
  SparseCholesky& cholesky = cylinder.cholesky;
  const std::vector<double>& M = c.model->mass_blocks();
  const int n = c.model->num_dofs();
  FactorReuseOptions options;
  options.max_iterations = 3;
  FactorReusingSolver solver(c.model->pattern(), cylinder.system, M, options);
  auto relative_residual = [&](const ScaledBlockSum& A, const std::vector<double>& b, const std::vector<double>& x) {
    std::vector<double> Mx(n), Kx(n), r(n);
    block_multiply(c.model->pattern(), M.data(), x.data(), Mx.data());
    block_multiply(c.model->pattern(), K.data(), x.data(), Kx.data());
    for (int d = 0; d < n; ++d) r[d] = b[d] - (A.mass_scale * Mx[d] + A.stiffness_scale * Kx[d]);
    return norm_free(r, c.fixed) / norm_free(b, c.fixed);
  };
  std::vector<double> x(n, 0.0);
  // First solve factorises; a slightly changed matrix reuses the factor; a matrix with 4x
  // the stiffness cannot be solved in 3 iterations with the old factor: it is refactorised.
  for (double scale : {4e-6, 4.04e-6, 1.6e-5}) {
    const ScaledBlockSum A{1.0, &K, scale};
    std::fill(x.begin(), x.end(), 0.0);
    solver.solve(A, c.load, x, cholesky);
    EXPECT_LE(relative_residual(A, c.load, x), 2 * options.relative_tolerance) << "scale " << scale;
    for (int d = 0; d < n; ++d)
      if (c.fixed[d]) {
        EXPECT_EQ(x[d], 0.0);
      }
  }
  EXPECT_EQ(solver.statistics().solves, 3);
  EXPECT_EQ(solver.statistics().factorizations, 2);
  EXPECT_EQ(solver.statistics().stale_factor_failures, 1);  // the third solve's old factor
}

TEST(FactorReuse, ElementLocalPreconditionerIsSparserAndGivesTheSameSteps) {
  // The default preconditioner factorises only the element-local couplings; it must meet
  // the same bound, agree with the whole-pattern preconditioner to the solver tolerance,
  // and have a much sparser factor (the DG edge couplings are what fill L).
  CompressedCylinder c;
  ShellSimulation element_local(*c.model, c.fixed, c.load), full(*c.model, c.fixed, c.load);
  FactorReuseOptions full_options;
  full_options.preconditioner_pattern = PreconditionerPattern::full;
  full.set_solver_options(full_options);
  for (int s = 0; s < 16; ++s) {
    element_local.step(c.options);
    full.step(c.options);
    EXPECT_LE(element_local.solver_statistics().last_relative_residual, FactorReuseOptions{}.relative_tolerance);
  }
  double diff = 0, scale = 0;
  for (size_t d = 0; d < full.displacement().size(); ++d) {
    diff = std::max(diff, std::abs(element_local.displacement()[d] - full.displacement()[d]));
    scale = std::max(scale, std::abs(full.displacement()[d]));
  }
  const FactorReuseStatistics& e = element_local.solver_statistics();
  std::printf("element-local: nnz(L) %ld, %ld factorisations, %ld iterations; full: nnz(L) %ld, %ld, %ld; "
              "max |du| / max |u| = %.2e\n",
              static_cast<long>(element_local.factor_nonzeros()), e.factorizations, e.iterations,
              static_cast<long>(full.factor_nonzeros()), full.solver_statistics().factorizations,
              full.solver_statistics().iterations, diff / scale);
  EXPECT_EQ(e.element_local_fallbacks, 0);
  EXPECT_GT(scale, 1e-3);
  EXPECT_LE(diff, 1e-6 * scale);  // as the factorise-every-step comparison above
  EXPECT_LT(2 * element_local.factor_nonzeros(), full.factor_nonzeros());
}

TEST(FactorReuse, OverlappedFactorisationMeetsTheBoundAndAgreesWithTheSynchronousOne) {
  // Overlapped (the default): a stale solve gathers its own matrix and the step after
  // factorises it beside its assembly, so PCG starts from a factor one step old. It must
  // meet the same bound, agree with factorising each stale step's successor synchronously
  // to the solver tolerance, and actually have run factorisations beside the assembly.
  CompressedCylinder c;
  ShellSimulation overlapped(*c.model, c.fixed, c.load), synchronous(*c.model, c.fixed, c.load);
  FactorReuseOptions options;
  options.refactor_after_iterations = 4;  // several refactorisations in 16 steps
  overlapped.set_solver_options(options);
  options.overlap_factorization = false;
  synchronous.set_solver_options(options);
  for (int s = 0; s < 16; ++s) {
    overlapped.step(c.options);
    synchronous.step(c.options);
    EXPECT_LE(overlapped.solver_statistics().last_relative_residual, options.relative_tolerance);
  }
  double diff = 0, scale = 0;
  for (size_t d = 0; d < overlapped.displacement().size(); ++d) {
    diff = std::max(diff, std::abs(overlapped.displacement()[d] - synchronous.displacement()[d]));
    scale = std::max(scale, std::abs(synchronous.displacement()[d]));
  }
  const FactorReuseStatistics& o = overlapped.solver_statistics();
  std::printf("overlapped: %ld factorisations, %ld iterations; synchronous: %ld, %ld; max |du| / max |u| = %.2e\n",
              o.factorizations, o.iterations, synchronous.solver_statistics().factorizations,
              synchronous.solver_statistics().iterations, diff / scale);
  EXPECT_GT(o.factorizations, 2);  // the first, synchronous one and overlapped ones
  EXPECT_EQ(o.element_local_fallbacks, 0);
  EXPECT_GT(scale, 1e-3);
  EXPECT_LE(diff, 1e-6 * scale);
}

TEST(FactorReuse, WholePatternFactorisationIsAlsoLeftForBesideTheAssembly) {
  // With the whole pattern (chosen, or after a fallback, as in the fracture scene) a stale
  // solve, too, leaves the factorisation of its own matrix pending instead of factorising
  // the next one synchronously; factorize_pending() then refreshes the caller's factor.
  CylinderSystem cylinder;
  const CompressedCylinder& c = cylinder.c;
  FactorReuseOptions options;
  options.preconditioner_pattern = PreconditionerPattern::full;
  options.refactor_after_iterations = 2;
  FactorReusingSolver solver(c.model->pattern(), cylinder.system, c.model->mass_blocks(), options);
  ASSERT_FALSE(solver.element_local());
  std::vector<double> x(c.model->num_dofs(), 0.0);
  solver.solve(ScaledBlockSum{1.0, &cylinder.K, 4e-6}, c.load, x, cylinder.cholesky);  // factorises A_1
  EXPECT_FALSE(solver.factorization_pending());
  const ScaledBlockSum stiffer{1.0, &cylinder.K, 1e-4};  // far from A_1: the old factor is stale
  std::fill(x.begin(), x.end(), 0.0);
  solver.solve(stiffer, c.load, x, cylinder.cholesky);
  const int stale_iterations = solver.statistics().last_iterations;
  EXPECT_GT(stale_iterations, options.refactor_after_iterations);
  EXPECT_LE(solver.statistics().last_relative_residual, options.relative_tolerance);
  EXPECT_EQ(solver.statistics().factorizations, 1);
  ASSERT_TRUE(solver.factorization_pending());
  EXPECT_FALSE(solver.dense_factorization_pending());  // CHOLMOD's: left for beside the assembly
  solver.factorize_pending();
  EXPECT_FALSE(solver.factorization_pending());
  EXPECT_EQ(solver.statistics().factorizations, 2);
  // The refreshed factor is that of `stiffer` itself (in float): a few iterations at most.
  std::fill(x.begin(), x.end(), 0.0);
  solver.solve(stiffer, c.load, x, cylinder.cholesky);
  std::printf("stale factor: %d iterations; after the pending factorisation: %d\n", stale_iterations,
              solver.statistics().last_iterations);
  EXPECT_LE(solver.statistics().last_iterations, 3);
  EXPECT_LE(solver.statistics().last_relative_residual, options.relative_tolerance);
  EXPECT_EQ(solver.statistics().factorizations, 2);
}

TEST(FactorReuse, ASystemFactoredDenselyUsesTheWholePattern) {
  // A small cylinder (4 x 2 elements, 96 DOFs): its DG edge couplings make the
  // element-local pattern differ, but SparseCholesky factors the whole pattern densely, so
  // an element-local factor would be no smaller, only a weaker preconditioner. The
  // compressed cylinder above (10 x 6 elements, factored sparse) keeps the element-local
  // default.
  const BottomHeldCylinder c(4, 2);
  ASSERT_TRUE(c.factored_densely());
  const std::vector<char> kept = element_local_blocks(c.model->mass_blocks());
  ASSERT_NE(std::count(kept.begin(), kept.end(), 0), 0) << "the element-local pattern must differ";
  const FactorReusingSolver small(c.model->pattern(), c.system, c.model->mass_blocks());
  EXPECT_FALSE(small.element_local());

  CylinderSystem cylinder;
  ASSERT_FALSE(SparseCholesky::factors_densely(cylinder.system.size(),
                                               static_cast<std::int64_t>(cylinder.system.row_index().size())));
  const FactorReusingSolver large(cylinder.c.model->pattern(), cylinder.system, cylinder.c.model->mass_blocks());
  EXPECT_TRUE(large.element_local());
}

TEST(FactorReuse, LargeDenseSystemsRefactoriseSooner) {
  // A cylinder of 8 x 4 elements held at the bottom: 288 free DOFs, factored densely with a
  // float copy of the factor. A stale solve of more than large_dense_refactor_after_iterations
  // (3) leaves its factorisation pending, though it stays under refactor_after_iterations.
  const BottomHeldCylinder c(8, 4);
  ASSERT_GE(c.system.size(), SparseCholesky::dense_single_precision_min_unknowns);
  ASSERT_TRUE(c.factored_densely());
  std::vector<double> K, load(c.model->num_dofs(), 0.0);
  c.model->assemble_stiffness(nullptr, K, nullptr);
  const double g[3] = {0, -400, 0};
  c.model->add_gravity(g, load);
  // A_1 factorised; then A_2 = M + 2e-6 K, which the factor of A_1 = M + 1e-6 K solves in
  // about 6 iterations.
  for (int threshold : {FactorReuseOptions{}.large_dense_refactor_after_iterations, 12}) {
    FactorReuseOptions options;
    options.large_dense_refactor_after_iterations = threshold;
    SparseCholesky cholesky;
    FactorReusingSolver solver(c.model->pattern(), c.system, c.model->mass_blocks(), options);
    std::vector<double> x(c.model->num_dofs(), 0.0);
    solver.solve(ScaledBlockSum{1.0, &K, 1e-6}, load, x, cholesky);
    std::fill(x.begin(), x.end(), 0.0);
    solver.solve(ScaledBlockSum{1.0, &K, 2e-6}, load, x, cholesky);
    const int iterations = solver.statistics().last_iterations;
    ASSERT_GT(iterations, 3);
    ASSERT_LE(iterations, options.refactor_after_iterations);
    EXPECT_LE(solver.statistics().last_relative_residual, options.relative_tolerance);
    EXPECT_EQ(solver.factorization_pending(), iterations > threshold) << "threshold " << threshold;
    // A dense factor's: ShellSimulation::step runs it in turn, before the assembly.
    EXPECT_EQ(solver.dense_factorization_pending(), solver.factorization_pending()) << "threshold " << threshold;
  }
}

TEST(FactorReuse, FallsBackToTheWholePatternWhenElementLocalIsTooWeak) {
  // With one iteration allowed and an exact (double) preconditioner only a factor of A
  // itself converges: the element-local factor fails twice (stale, then fresh) and the
  // solver must switch to the whole pattern for good, still meeting the bound.
  CylinderSystem cylinder;
  const CompressedCylinder& c = cylinder.c;
  FactorReuseOptions options;
  options.max_iterations = 1;
  options.single_precision_preconditioner = false;
  FactorReusingSolver solver(c.model->pattern(), cylinder.system, c.model->mass_blocks(), options);
  ASSERT_TRUE(solver.element_local());
  const ScaledBlockSum A{1.0, &cylinder.K, 4e-6};
  for (int s = 0; s < 2; ++s) {
    std::vector<double> x(c.model->num_dofs(), 0.0);
    solver.solve(A, c.load, x, cylinder.cholesky);
    EXPECT_LE(solver.statistics().last_relative_residual, options.relative_tolerance);
  }
  EXPECT_FALSE(solver.element_local());
  EXPECT_EQ(solver.statistics().element_local_fallbacks, 1);
  EXPECT_EQ(solver.statistics().factorizations, 2);  // element-local once, then A once (reused by solve 2)
}

// Vectors of another size were read and written out of bounds: refused, naming which.
TEST(FactorReuse, VectorsOfAnotherSizeAreRefused) {
  CylinderSystem cylinder;
  const CompressedCylinder& c = cylinder.c;
  FactorReusingSolver solver(c.model->pattern(), cylinder.system, c.model->mass_blocks());
  const ScaledBlockSum A{1.0, &cylinder.K, 4e-6};
  const std::size_t dofs = c.model->num_dofs();
  std::vector<double> x(dofs, 0.0), short_b(c.load.begin(), c.load.end() - 1);
  EXPECT_THROW(solver.solve(A, short_b, x, cylinder.cholesky), std::invalid_argument);
  std::vector<double> long_x(dofs + 3, 0.0);
  try {
    solver.solve(A, c.load, long_x, cylinder.cholesky);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "FactorReusingSolver::solve: x has " + std::to_string(dofs + 3) +
                                         " entries; expected #dofs = " + std::to_string(dofs));
  }
  const std::vector<double> short_kx(dofs - 3, 0.0);
  EXPECT_THROW(solver.solve(A, c.load, x, cylinder.cholesky, &short_kx), std::invalid_argument);
  EXPECT_EQ(solver.statistics().solves, 0);
  solver.solve(A, c.load, x, cylinder.cholesky);  // the right sizes still solve
  EXPECT_LE(solver.statistics().last_relative_residual, solver.options().relative_tolerance);
}

TEST(FactorReuse, ElementLocalDroppedRadiusIsTheDefinitionsOnTheDenseMatrix) {
  // The reference: A formed densely, an entry dropped where its two nodes share no element
  // (from the mesh, not from the mass blocks), the radius summed entry by entry.
  CylinderSystem cylinder;
  const CompressedCylinder& c = cylinder.c;
  const BlockAssembly& pattern = c.model->pattern();
  const int nodes = pattern.num_nodes(), n = 3 * nodes;
  std::vector<char> shared(static_cast<size_t>(nodes) * nodes, 0);
  const int npe = c.mesh.nodes_per_element();
  for (int e = 0; e < c.mesh.num_elements(); ++e)
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b)
        shared[static_cast<size_t>(c.mesh.element_nodes(e)[a]) * nodes + c.mesh.element_nodes(e)[b]] = 1;
  std::vector<char> free(n);
  for (int d = 0; d < n; ++d) free[d] = !c.fixed[d];
  const std::vector<char> kept = element_local_blocks(c.model->mass_blocks());
  for (double stiffness_scale : {1e-7, 4e-6, 1e-4}) {
    const ScaledBlockSum A{1.3, &cylinder.K, stiffness_scale};
    std::vector<double> dense(static_cast<size_t>(n) * n, 0.0), dropped(dense.size(), 0.0);
    for (int r = 0; r < nodes; ++r)
      for (std::int64_t k = pattern.row_start()[r]; k < pattern.row_start()[r + 1]; ++k) {
        const int col = pattern.column()[k];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const double a = A.mass_scale * c.model->mass_blocks()[9 * k + 3 * i + j] +
                             A.stiffness_scale * cylinder.K[9 * k + 3 * i + j];
            dense[static_cast<size_t>(3 * r + i) * n + 3 * col + j] = a;
            if (!shared[static_cast<size_t>(r) * nodes + col]) dropped[static_cast<size_t>(3 * r + i) * n + 3 * col + j] = a;
          }
      }
    double expected = 0;
    for (int i = 0; i < n; ++i) {
      if (!free[i]) continue;
      double sum = 0;
      for (int j = 0; j < n; ++j)
        if (free[j] && dropped[static_cast<size_t>(i) * n + j] != 0)
          sum += std::abs(dropped[static_cast<size_t>(i) * n + j]) /
                 std::sqrt(dense[static_cast<size_t>(i) * n + i] * dense[static_cast<size_t>(j) * n + j]);
      expected = std::max(expected, sum);
    }
    ASSERT_GT(expected, 0) << "the cylinder's DG edges couple nodes of no common element";
    for (int threads : {1, 2, 3}) {
      const test::ThreadCountGuard set_threads(threads);
      EXPECT_NEAR(element_local_dropped_radius(pattern, kept, free, c.model->mass_blocks(), A), expected,
                  1e-12 * expected)
          << "stiffness scale " << stiffness_scale << ", " << threads << " threads";
    }
  }
  // A free DOF without a positive diagonal: A is not positive definite, nothing to weigh.
  std::vector<double> negative = cylinder.K;
  for (double& v : negative) v = -v;
  const ScaledBlockSum indefinite{1.0, &negative, 1.0};
  EXPECT_EQ(element_local_dropped_radius(pattern, kept, free, c.model->mass_blocks(), indefinite),
            std::numeric_limits<double>::infinity());
}

TEST(FactorReuse, ElementLocalIsRuledOutWhereTheDroppedCouplingsOutweighTheMass) {
  // The fracture scene's plate without its cuts (tri6, clamped at x = 0 and 1). At a time step
  // of 3e-5 s the step matrix is mostly mass and the element-local factor is kept; at the
  // scene's 1e-3 s dt^2 K dominates, the couplings the element-local pattern drops reach
  // a radius of ~1 (its matrix is not positive definite there), so the first factorisation
  // is of the whole pattern: no element-local factor, no fallback.
  const Mesh mesh = make_rectangle(1.0, 1.0, 16, 17, ElementType::tri6, TriangleSplit::square);
  auto clamped = [](const double* x) { return x[0] < 1e-9 || x[0] > 1 - 1e-9; };
  const auto model = make_model(mesh, Material{1e7, 0.3, 0.01, 500}, 1.0, clamped);
  std::vector<char> fixed;
  fix_nodes(mesh, clamped, true, true, true, fixed);
  const FreeDofSystem system(model->pattern(), fixed);
  std::vector<double> K, load(model->num_dofs(), 0.0);
  model->assemble_stiffness(nullptr, K, nullptr);
  const double g[3] = {0, 0, -9.81};
  model->add_gravity(g, load);
  for (double dt : {3e-5, 1e-3}) {
    SparseCholesky cholesky;
    FactorReusingSolver solver(model->pattern(), system, model->mass_blocks());
    ASSERT_TRUE(solver.element_local());
    EXPECT_TRUE(std::isnan(solver.element_local_dropped_radius()));
    std::vector<double> x(model->num_dofs(), 0.0);
    solver.solve(ScaledBlockSum{1 + 2 * dt, &K, dt * dt}, load, x, cholesky);
    EXPECT_LE(solver.statistics().last_relative_residual, FactorReuseOptions{}.relative_tolerance);
    const double radius = solver.element_local_dropped_radius();
    const bool small = dt < 1e-4;
    std::printf("time step %g s: dropped radius %.3f\n", dt, radius);
    EXPECT_EQ(radius <= FactorReuseOptions{}.element_local_max_dropped_radius, small);
    EXPECT_EQ(solver.element_local(), small);
    EXPECT_EQ(solver.element_local_factor_nonzeros() > 0, small);
    EXPECT_EQ(cholesky.analyzed(), !small);
    EXPECT_EQ(solver.statistics().element_local_fallbacks, 0);
    EXPECT_EQ(solver.statistics().factorizations, 1);
    // Judged once: options asking for the element-local pattern again do not bring it back.
    solver.set_options(FactorReuseOptions{});
    EXPECT_EQ(solver.element_local(), small);
  }
  // What the rule saves: tried anyway at 1e-3 s, the element-local matrix is not positive
  // definite and the solver falls back after an analysis and factorisation of it.
  FactorReuseOptions always;
  always.element_local_max_dropped_radius = std::numeric_limits<double>::infinity();
  SparseCholesky cholesky;
  FactorReusingSolver tried(model->pattern(), system, model->mass_blocks(), always);
  std::vector<double> x(model->num_dofs(), 0.0);
  tried.solve(ScaledBlockSum{1 + 2e-3, &K, 1e-6}, load, x, cholesky);
  EXPECT_LE(tried.statistics().last_relative_residual, always.relative_tolerance);
  EXPECT_EQ(tried.statistics().element_local_fallbacks, 1);
}

TEST(DeterministicDot, IsIndependentOfThreadCount) {
  std::vector<double> x(100003), y(x.size());
  for (size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.1 * i), y[i] = std::cos(0.37 * i) * 1e3;
  const double one = test::with_threads(1, [&] { return deterministic_dot(x, y); });
  for (int threads : {2, 3, 4}) {
    const test::ThreadCountGuard set_threads(threads);
    EXPECT_EQ(deterministic_dot(x, y), one) << threads << " threads";
  }
  double naive = 0;
  for (size_t i = 0; i < x.size(); ++i) naive += x[i] * y[i];
  EXPECT_NEAR(one, naive, 1e-9 * std::abs(naive) + 1e-9);
}

}  // namespace

// A cut that leaves a sliver a few texels wide (thesis Table 5.1 cuts are texel-detailed,
// so such fragments happen): the enriched functions of the nodes on the far side of the
// sliver have almost no support, and the mass matrix becomes nearly singular. The remedy
// (ShellModelOptions::min_enrichment_mass_ratio) drops those enriched DOFs; these tests show
// the conditioning with and without it, also for two functions that nearly coincide at a
// node (cut pieces that run close to each other), and the fracture scene that such a pair
// made unstable.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "dgtex/basis_projection.h"
#include "dgtex/free_dof_system.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/shell_simulation.h"
#include "enrichment_test_support.h"
#include "shell_test_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

// Smallest and largest eigenvalue of the Jacobi-scaled mass matrix D^-1/2 M D^-1/2
// (scale-free; its largest is O(1)).
// Of the mass matrix the solvers see: over the unknowns of the model's FreeDofSystem (no
// fixed DOFs; the exactly tied ones eliminated, ShellModel::dependent_nodes).
std::pair<double, double> scaled_mass_spectrum(const ShellModel& model) {
  const FreeDofSystem system(model.pattern(), std::vector<char>(model.num_dofs(), 0), nullptr, &model.dependent_nodes());
  std::vector<double> values;
  system.gather(model.mass_blocks().data(), 1.0, nullptr, 0.0, values);
  const int n = system.size();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int k = system.column_start()[j]; k < system.column_start()[j + 1]; ++k)
      M(system.row_index()[k], j) = M(j, system.row_index()[k]) = values[k];
  const Eigen::VectorXd s = M.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = s.asDiagonal() * M * s.asDiagonal();
  const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
  return {eig(0), eig(n - 1)};
}

double sliver_cut(const double* x) { return x[0] - 0.5 / 64; }

// 1 texel from the left edge of a 2 x 1 plate of 0.5-wide elements at T = 64. step: the
// cut's +-1; else one texel of the last element, far from the sliver, reads 0.999, so
// that the function is no step function (its ties are then column ties, not exact ones).
std::unique_ptr<ShellModel> sliver_model(const Mesh& mesh, double min_mass_ratio, bool step = true) {
  EnrichmentFunction f = straight_cut_enrichment(mesh, 64, sliver_cut);
  if (!step) f.elements.back().tile.values.back() = 0.999;
  return enriched_model(mesh, {std::move(f)}, min_mass_ratio);
}

TEST(EnrichmentFragments, DroppingTinySupportsKeepsTheMassMatrixWellConditioned) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto kept = sliver_model(mesh, 0.0);
  const auto pruned = sliver_model(mesh, 1e-3);
  const auto [kept_min, kept_max] = scaled_mass_spectrum(*kept);
  const auto [pruned_min, pruned_max] = scaled_mass_spectrum(*pruned);
  std::printf("sliver of 1 texel: all %d enriched nodes kept: scaled mass eigenvalues [%.3e, %.3e]; "
              "%d pruned (dropped or tied): [%.3e, %.3e], condition %.3e\n",
              kept->num_enriched_nodes(), kept_min, kept_max, pruned->num_pruned_enriched_nodes(), pruned_min,
              pruned_max, pruned_max / pruned_min);
  EXPECT_GT(pruned->num_pruned_enriched_nodes(), 0);
  EXPECT_GT(pruned->num_enriched_nodes(), 0);  // the rest of the cut still separates
  // Keeping every enriched DOF leaves the mass matrix singular to round-off (its smallest
  // eigenvalue is at the level of rounding errors, even negative); dropping the
  // near-dependent ones leaves it well conditioned.
  EXPECT_LT(kept_min, 1e-12 * kept_max);
  EXPECT_GT(pruned_min, 0.0);
  EXPECT_LT(pruned_max / pruned_min, 1e4);
}

// An enrichment function of every node of the mesh with the texel values h(x) (no walls).
EnrichmentFunction smooth_enrichment(const Mesh& mesh, int t, const LevelFunction& h) {
  EnrichmentFunction f;
  for (int n = 0; n < mesh.num_nodes(); ++n) f.enriched_nodes.push_back(n);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    kernels::TexelTile tile = kernels::make_element_tile(mesh.type, t);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        double c[2], x[3];
        kernels::texel_centre(mesh.type, t, i, j, c);
        surface_point(mesh, e, c[0], c[1], x);
        tile.values[tile.index(i, j)] = h(x);
      }
    f.elements.push_back({e, std::move(tile)});
  }
  return f;
}

// The first function sin(8x) (and a second one, if given) on every node.
std::unique_ptr<ShellModel> smooth_function_model(const Mesh& mesh, const LevelFunction* second, double min_mass_ratio) {
  std::vector<EnrichmentFunction> functions = {
      smooth_enrichment(mesh, 32, [](const double* x) { return std::sin(8 * x[0]); })};
  if (second) functions.push_back(smooth_enrichment(mesh, 32, *second));
  return enriched_model(mesh, std::move(functions), min_mass_ratio);
}

// A near copy of the first function with a step of 0.02 along x = 0.3 that the first one
// does not have: dropped at every node, but its quadrature resolves the step.
double stepped_copy(const double* x) { return std::sin(8 * x[0]) + (x[0] > 0.3 ? 0.02 : 0.0); }

}  // namespace

// Each function alone adds much to N^a (the old test looked at that only), but the second
// is the first plus 1 % of another smooth field: together they are nearly dependent, and
// the mass matrix nearly singular. The second one's nodes go; a second function that is
// independent (the first one turned by 90 degrees) keeps them all.
TEST(EnrichmentFragments, ANearCopyOfAnEarlierFunctionAtANodeIsDropped) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const LevelFunction near_copy = [](const double* x) { return std::sin(8 * x[0]) + 0.01 * std::cos(5 * x[1]); };
  const LevelFunction independent = [](const double* x) { return std::sin(8 * x[1]); };
  const auto all = smooth_function_model(mesh, &near_copy, 0.0);
  const auto pruned = smooth_function_model(mesh, &near_copy, 1e-3);
  const auto first_only = smooth_function_model(mesh, nullptr, 1e-3);
  const auto other = smooth_function_model(mesh, &independent, 1e-3);
  const auto [all_min, all_max] = scaled_mass_spectrum(*all);
  const auto [pruned_min, pruned_max] = scaled_mass_spectrum(*pruned);
  const auto [first_min, first_max] = scaled_mass_spectrum(*first_only);
  std::printf("near copy: all %d enriched nodes kept: scaled mass eigenvalues [%.3e, %.3e]; %d dropped: [%.3e, %.3e] "
              "(the first function alone: [%.3e, %.3e]); independent second function: %d dropped\n",
              all->num_enriched_nodes(), all_min, all_max, pruned->num_pruned_enriched_nodes(), pruned_min, pruned_max,
              first_min, first_max, other->num_pruned_enriched_nodes());
  EXPECT_LT(all_min, 1e-8 * all_max);
  // The near copy lost every node: what is left is the model of the first function alone.
  ASSERT_EQ(pruned->enrichments().size(), 1u);
  EXPECT_EQ(pruned->num_pruned_enriched_nodes(), mesh.num_nodes());
  EXPECT_EQ(first_only->num_pruned_enriched_nodes(), 0);
  EXPECT_EQ(pruned->num_enriched_nodes(), mesh.num_nodes());
  EXPECT_NEAR(pruned_min, first_min, 1e-12 * first_max);
  EXPECT_NEAR(pruned_max, first_max, 1e-12 * first_max);
  EXPECT_GT(pruned_min, 1e5 * all_min);
  EXPECT_EQ(other->num_pruned_enriched_nodes(), 0);
  EXPECT_EQ(other->num_enriched_nodes(), 2 * mesh.num_nodes());
}

// The model rebuilt after the pruning reuses each element's mass and load weights, taking
// the entries of the remaining functions; it equals a model built from the kept functions
// alone, bitwise. The second function nearly copies the first in the left element only, so
// only the nodes of that element go (near copies are dropped, not tied).
TEST(EnrichmentFragments, PrunedModelEqualsTheModelOfItsKeptFunctionsBitwise) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const LevelFunction copy_on_the_left = [](const double* x) {
    return x[0] < 0.5 ? std::sin(8 * x[0]) + 0.01 * std::cos(5 * x[1]) : std::sin(8 * x[1]);
  };
  const auto pruned = smooth_function_model(mesh, &copy_on_the_left, 1e-3);
  ASSERT_GT(pruned->num_pruned_enriched_nodes(), 0);
  ASSERT_EQ(pruned->num_tied_enriched_nodes(), 0);
  ASSERT_EQ(pruned->enrichments().size(), 2u);  // the second function keeps the right element's nodes
  const auto direct = enriched_model(mesh, pruned->enrichments(), 1e-3);
  ASSERT_EQ(direct->num_pruned_enriched_nodes(), 0);
  expect_models_equal_bitwise(*pruned, *direct);
}

// Where the pruning drops a whole function (here stepped_copy), the basis built again
// without it keeps the quadrature integrated with it: the one of all functions, which
// resolves the step, and the kept function's mass and load weights are those integrals'
// entries, bitwise, instead of a second integration on the kept textures' own quadrature
// (spiral6's step 167 took ~6 ms more than its neighbours for it).
TEST(EnrichmentFragments, ABasisThatLosesAWholeFunctionKeepsTheQuadratureOfAllFunctions) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const LevelFunction stepped = stepped_copy;
  const auto all = smooth_function_model(mesh, &stepped, 0.0);
  const auto pruned = smooth_function_model(mesh, &stepped, 1e-3);
  const auto first_only = smooth_function_model(mesh, nullptr, 1e-3);
  std::printf("quadrature points: both functions %lld, pruned to the first %lld, the first alone %lld\n",
              static_cast<long long>(all->num_enriched_element_quadrature_points()),
              static_cast<long long>(pruned->num_enriched_element_quadrature_points()),
              static_cast<long long>(first_only->num_enriched_element_quadrature_points()));
  ASSERT_EQ(pruned->enrichments().size(), 1u);
  ASSERT_EQ(pruned->num_dofs(), first_only->num_dofs());
  // The step needs points of its own: the quadrature of both functions has more.
  ASSERT_GT(all->num_enriched_element_quadrature_points(), first_only->num_enriched_element_quadrature_points());
  EXPECT_EQ(pruned->num_enriched_element_quadrature_points(), all->num_enriched_element_quadrature_points());
  // Mass: every block of the pruned model is the block of the same two nodes in the model of
  // both functions (the first function's virtual nodes are numbered alike in both), bitwise.
  const BlockAssembly &p = pruned->pattern(), &q = all->pattern();
  for (int r = 0; r < p.num_nodes(); ++r)
    for (std::int64_t k = p.row_start()[r]; k < p.row_start()[r + 1]; ++k) {
      const int c = p.column()[k];
      const int* at = std::find(q.column().data() + q.row_start()[r], q.column().data() + q.row_start()[r + 1], c);
      ASSERT_NE(at, q.column().data() + q.row_start()[r + 1]) << "block (" << r << ", " << c << ")";
      const std::int64_t l = at - q.column().data();
      for (int i = 0; i < 9; ++i)
        ASSERT_EQ(pruned->mass_blocks()[9 * k + i], all->mass_blocks()[9 * l + i]) << "block (" << r << ", " << c << ")";
    }
  // Gravity loads (the mass weights) likewise.
  const double g[3] = {0.1, -0.2, -9.81};
  std::vector<double> fp(pruned->num_dofs(), 0.0), fa(all->num_dofs(), 0.0);
  pruned->add_gravity(g, fp);
  all->add_gravity(g, fa);
  for (int d = 0; d < pruned->num_dofs(); ++d) ASSERT_EQ(fp[d], fa[d]) << "dof " << d;
  // It is still the first function's model, up to the finer quadrature.
  const auto [pruned_min, pruned_max] = scaled_mass_spectrum(*pruned);
  const auto [first_min, first_max] = scaled_mass_spectrum(*first_only);
  EXPECT_NEAR(pruned_min, first_min, 1e-6 * first_max);
  EXPECT_NEAR(pruned_max, first_max, 1e-6 * first_max);
}

// That quadrature stays with the pruned basis: a later call on the model that gives the kept
// function alone builds the kept function's own quadrature, and one that gives both again
// prunes as before; each result equals a fresh model's given the same functions, bitwise.
TEST(EnrichmentFragments, ALaterBasisOfAModelThatLostAWholeFunctionEqualsAFreshOneBitwise) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const LevelFunction stepped = stepped_copy;
  const auto model = smooth_function_model(mesh, &stepped, 1e-3);
  ASSERT_EQ(model->enrichments().size(), 1u);
  const auto first_only = smooth_function_model(mesh, nullptr, 1e-3);
  model->set_enrichments(first_only->enrichments());
  expect_models_equal_bitwise(*model, *first_only);
  const auto pruned = smooth_function_model(mesh, &stepped, 1e-3);
  std::vector<EnrichmentFunction> both = first_only->enrichments();
  both.push_back(smooth_enrichment(mesh, 32, stepped));
  model->set_enrichments(std::move(both));
  ASSERT_EQ(model->enrichments().size(), 1u);
  expect_models_equal_bitwise(*model, *pruned);
  EXPECT_GT(model->num_enriched_element_quadrature_points(), first_only->num_enriched_element_quadrature_points());
}

// examples/scenes/fracture.json: where two of its cuts' functions nearly coincide around
// three nodes, their pairs of enriched DOFs made a mode with almost no mass that the
// corotated step drove unstable: from step ~140 those DOFs oscillated at up to 90 m/s
// (the sheet moves at ~2.5 m/s), and the solver's one-step-old factor failed every step
// (43 PCG iterations and a factorisation a step, against 3-16 before).
TEST(EnrichmentFragments, FractureSceneStaysStableWithNearCopiesDropped) {
  Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/fracture.json");
  scene.render.reset();
  SceneRun run(scene);
  const int standard_dofs = 3 * run.mesh().num_nodes();
  double max_standard = 0, max_enriched = 0;
  int max_iterations = 0;
  for (int step = 1; step <= 160; ++step) {
    run.step();
    const std::vector<double>& v = run.simulation().velocity();
    for (int d = 0; d < static_cast<int>(v.size()); ++d) {
      double& largest = d < standard_dofs ? max_standard : max_enriched;
      largest = std::max(largest, std::fabs(v[d]));
    }
    max_iterations = std::max(max_iterations, run.simulation().solver_statistics().last_iterations);
  }
  std::printf("fracture, 160 steps: max |v| standard %.3g m/s, enriched %.3g m/s; most PCG iterations in a step %d; "
              "%d enriched nodes dropped\n",
              max_standard, max_enriched, max_iterations, run.model().num_pruned_enriched_nodes());
  EXPECT_LT(max_enriched, 2 * max_standard);
  // Fewer than max_iterations: the reused factor never failed.
  EXPECT_LT(max_iterations, FactorReuseOptions{}.max_iterations);
  EXPECT_EQ(run.solver_statistics().stale_factor_failures, 0);
}

// A straight cut 3 texels left of the middle nodes of a 2 x 1 plate (quad8, T = 64): a node
// at x = 0 holds a strip of the right piece where its N^a almost vanishes, so its enriched
// function has almost no mass (below 1e-3 of its N^a's). Dropped, the strip moved with
// that node's standard DOFs: either piece's translation was off by 2.3e-2 there (session
// 74); tied to a kept node's DOFs, the translations were exact but the piece followed the
// plate's motion at that node (sessions 74-76). Independent of the functions on its
// support, it is kept (session 77): either piece's translation is in the basis exactly,
// and the mass matrix is as well conditioned as with the node dropped (scaled condition
// 4.3e5, set by the kept nodes' own small masses).
TEST(EnrichmentFragments, ANodeHoldingASmallCornerOfAPieceIsKeptSoThePieceTranslates) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const int T = 64;
  const double texel = 0.5 / T, cut = 0.5 - 3 * texel;
  const LevelFunction f = [cut](const double* x) { return x[0] - cut; };
  const auto model = enriched_model(mesh, {straight_cut_enrichment(mesh, T, f)}, 1e-3);
  EXPECT_EQ(model->num_pruned_enriched_nodes(), 0);
  EXPECT_EQ(model->num_tied_enriched_nodes(), 0);
  const auto [min_eigenvalue, max_eigenvalue] = scaled_mass_spectrum(*model);
  EXPECT_GT(min_eigenvalue, 0.0);
  EXPECT_LT(max_eigenvalue / min_eigenvalue, 1e6);  // measured 4.27e5
  double worst = 0;
  for (const double side : {1.0, -1.0}) {
    const std::vector<double> u = piece_field(*model, f, side, [](const double*, double* v) { v[0] = v[1] = 0, v[2] = 1; });
    // Texel centres of element 0 (x in [0, 0.5]) not next to the cut, where the texture is +-1.
    for (int j = 0; j < T; ++j)
      for (int i = 0; i < T; ++i) {
        const double x = (i + 0.5) * texel;
        if (std::abs(x - cut) < texel) continue;
        const double xi[2] = {2 * (i + 0.5) / T - 1, 2 * (j + 0.5) / T - 1};
        double value[3];
        model->interpolate(u, 0, xi, value);
        const double expected = (x > cut) == (side > 0) ? 1.0 : 0.0;
        worst = std::max(worst, std::abs(value[2] - expected));
      }
  }
  std::printf("%d enriched nodes kept, none tied; scaled mass condition %.3g; translations of either piece off by %.1e\n",
              model->num_enriched_nodes(), max_eigenvalue / min_eigenvalue, worst);
  EXPECT_LT(worst, 1e-12);
}

// The sliver's functions at the nodes beyond it depend on each other on the sliver, and two
// are tied (their mass is small). Of a step function the ties are exact (the nodes keep
// their DOFs, dependent on their partners'): an infinitesimal rigid motion r(x) of either
// piece (standard DOFs r(x^a) on the piece's nodes, enriched DOFs side r(x^a) / 2 at every
// node) is what the ties give, translations and rotations alike. With one partner per tie
// (its field copied, the first form of the exact tie) the sliver's rotations were off by
// 1/8 of their largest entry.
TEST(EnrichmentFragments, TheTiesOfAStepFunctionKeepEveryRigidMotionOfEitherPiece) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto model = sliver_model(mesh, 1e-3);
  ASSERT_EQ(model->dependent_nodes().size(), 2u);
  EXPECT_EQ(model->num_tied_enriched_nodes(), 2);
  EXPECT_EQ(model->num_pruned_enriched_nodes(), 2);  // tied ones included: no unknowns of their own
  const FreeDofSystem system(model->pattern(), std::vector<char>(model->num_dofs(), 0), nullptr, &model->dependent_nodes());
  EXPECT_EQ(system.size(), model->num_dofs() - 6);
  double worst = 0, worst_projected = 0;
  for (const double side : {1.0, -1.0})
    for (int axis = 0; axis < 3; ++axis)
      for (const bool rotation : {false, true}) {
        const std::vector<double> motion = piece_field(*model, sliver_cut, side, [&](const double* x, double* v) {
          const double w[3] = {axis == 0 ? 1.0 : 0.0, axis == 1 ? 1.0 : 0.0, axis == 2 ? 1.0 : 0.0};
          if (!rotation) {
            v[0] = w[0], v[1] = w[1], v[2] = w[2];
            return;
          }
          v[0] = w[1] * x[2] - w[2] * x[1], v[1] = w[2] * x[0] - w[0] * x[2], v[2] = w[0] * x[1] - w[1] * x[0];
        });
        std::vector<double> tied = motion;
        system.distribute(tied);  // the dependent DOFs from their sources
        worst = std::max(worst, max_difference(tied, motion) / max_abs(motion));
        // So the mass projection onto the basis (over the DOFs that are not tied) gives it back.
        const ProjectedState projected = project_onto_basis(*model, motion, motion, *model, std::vector<char>(model->num_dofs(), 0));
        worst_projected = std::max(worst_projected, max_difference(projected.displacement, motion) / max_abs(motion));
        worst_projected = std::max(worst_projected, max_difference(projected.velocity, motion) / max_abs(motion));
      }
  std::printf("rigid motions of either piece: their tied DOFs off by %.1e, projected onto the basis by %.1e\n", worst,
              worst_projected);
  EXPECT_LT(worst, 1e-14);            // measured 0
  EXPECT_LT(worst_projected, 1e-10);  // measured 2.9e-12
}

// The step of a model with exact ties, against the system written out densely: the DOFs
// that are neither held nor tied solve (T^T A T) v = T^T b with A = M + dt^2 K, b = dt f (a
// force on every DOF, the tied ones' included), and the tied DOFs follow, v = T v_free. T
// is built here from dependent_nodes() alone. Linear with a factor of its own, and corotated
// (at rest K is the linear one) by PCG with the reused factor.
TEST(EnrichmentFragments, AStepOfAModelWithExactTiesSolvesForTheDofsThatAreNotTied) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto model = sliver_model(mesh, 1e-3);
  ASSERT_FALSE(model->dependent_nodes().empty());
  const int n = model->num_dofs();
  std::vector<char> fixed;
  fix_nodes(mesh, [](const double* x) { return x[0] > 1 - 1e-9; }, true, true, true, fixed);
  fixed.resize(n, 0);
  const std::vector<double> force = random_values(n, 5);
  std::vector<double> K;
  model->assemble_stiffness(nullptr, K, nullptr);
  const double dt = 1e-3;
  const Eigen::MatrixXd A =
      dense_from_blocks(model->pattern(), model->mass_blocks()) + dt * dt * dense_from_blocks(model->pattern(), K);
  const Eigen::MatrixXd T = dense_elimination_matrix(fixed, model->dependent_nodes());
  const Eigen::VectorXd b = dt * Eigen::Map<const Eigen::VectorXd>(force.data(), n);
  const Eigen::VectorXd expected = T * (T.transpose() * A * T).ldlt().solve(T.transpose() * b);
  for (const bool corotational : {false, true}) {
    ShellSimulation simulation(*model, fixed, force);
    DynamicsOptions options;
    options.time_step = dt;
    options.corotational = corotational;
    simulation.step(options);
    const Eigen::Map<const Eigen::VectorXd> v(simulation.velocity().data(), n);
    const double off = (v - expected).cwiseAbs().maxCoeff() / expected.cwiseAbs().maxCoeff();
    std::printf("%s: velocity off the dense solve by %.1e of its largest entry\n",
                corotational ? "corotated, PCG with the reused factor" : "linear", off);
    EXPECT_LT(off, corotational ? 1e-7 : 1e-10);
  }
  // Later corotated steps iterate with the factor of an earlier matrix (PCG's products over
  // all DOFs, collected): the same steps as a fresh factor of each step's own T^T A T.
  std::vector<std::vector<double>> displacements;
  for (const bool reuse : {true, false}) {
    ShellSimulation simulation(*model, fixed, force);
    DynamicsOptions options;
    options.time_step = 0.02;
    options.corotational = true;
    options.reuse_factorization = reuse;
    for (int step = 0; step < 10; ++step) simulation.step(options);
    if (reuse) {
      EXPECT_GT(simulation.solver_statistics().iterations, 10);
    }
    displacements.push_back(simulation.displacement());
  }
  const double off = max_difference(displacements[0], displacements[1]) / max_abs(displacements[1]);
  std::printf("10 corotated steps: reusing the factor off a factor a step by %.1e\n", off);
  EXPECT_LT(off, 1e-6);
}

// Of a function that is no step the ties are column ties: a tied column adds to its
// partner's moments point by point (moments_of_fields' own path for an element whose global
// nodes repeat), the same bits as the reference sums.
TEST(EnrichmentFragments, TiedColumnsAddToTheirPartnersMomentsAsTheReferenceSums) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto model = sliver_model(mesh, 1e-3, false);
  ASSERT_GT(model->num_tied_enriched_nodes(), 0);
  ASSERT_TRUE(model->dependent_nodes().empty());
  std::vector<double> field(model->num_dofs());
  for (std::size_t k = 0; k < field.size(); ++k) field[k] = std::sin(0.7 * static_cast<double>(k) + 0.3);
  const std::vector<double> moments = model->moments_of_fields(*model, {&field})[0];
  const std::vector<double> reference =
      model->mass_weighted_moments([&](int e, const double xi[2], double out[3]) { model->interpolate(field, e, xi, out); });
  EXPECT_EQ(moments, reference);
}

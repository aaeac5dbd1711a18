// A basis change evaluates the new basis at every quadrature point of the enriched elements
// twice: for the new mass matrix and for the projection's moments. A model told to keep
// those values (ShellModel::keep_basis_values, as SceneRun does for its next model) reads
// them in moments_of_fields instead. The kept values must give the moments bitwise, also
// where set_enrichments prunes nodes and rebuilds from a subset of the functions (their
// columns of the first build's values), and nothing must stay kept after release.
// The projection of the basis after that one reads them too, as the source's values at the
// points both bases share: again bitwise the moments of an evaluated source.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include <omp.h>

#include "enrichment_test_support.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

// The old model's state projected onto `functions`: moments from a copy that keeps its
// basis values against a copy that evaluates them, bitwise; every enriched element of the
// keeping copy read kept values. Returns the keeping copy (released).
std::unique_ptr<ShellModel> expect_kept_moments_bitwise(const ShellModel& old_model,
                                                        const std::vector<EnrichmentFunction>& functions) {
  auto evaluating = std::make_unique<ShellModel>(old_model);
  auto keeping = std::make_unique<ShellModel>(old_model);
  evaluating->set_enrichments(functions);
  keeping->keep_basis_values();
  keeping->set_enrichments(functions);
  EXPECT_GT(keeping->num_enriched_elements(), 0);
  int kept_elements = 0;
  for (int e = 0; e < keeping->mesh().num_elements(); ++e) {
    EXPECT_FALSE(evaluating->has_kept_basis_values(e)) << "element " << e;
    kept_elements += keeping->has_kept_basis_values(e);
  }
  EXPECT_EQ(kept_elements, keeping->num_enriched_elements());
  const std::vector<double> u = random_values(old_model.num_dofs(), 1), v = random_values(old_model.num_dofs(), 2);
  const auto evaluated = evaluating->moments_of_fields(old_model, {&u, &v});
  const auto kept = keeping->moments_of_fields(old_model, {&u, &v});
  EXPECT_TRUE(bitwise_equal(evaluated[0], kept[0]));
  EXPECT_TRUE(bitwise_equal(evaluated[1], kept[1]));
  keeping->release_basis_values();
  for (int e = 0; e < keeping->mesh().num_elements(); ++e) EXPECT_FALSE(keeping->has_kept_basis_values(e));
  return keeping;
}

}  // namespace

TEST(KeptBasisValues, ProjectionMomentsEqualTheEvaluatedOnesBitwise) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto old_model =
      enriched_model(mesh, {straight_cut_enrichment(mesh, 32, [](const double* x) { return x[0] - 0.25; })}, 0.0);
  const std::vector<EnrichmentFunction> next = {
      straight_cut_enrichment(mesh, 32, [](const double* x) { return x[0] + 0.4 * x[1] - 0.55; }, false)};
  const auto keeping = expect_kept_moments_bitwise(*old_model, next);
  EXPECT_EQ(keeping->num_pruned_enriched_nodes(), 0);
}

TEST(KeptBasisValues, APrunedBasisTakesItsColumnsOfTheFirstBuildsValues) {
  // A cut one texel from the left edge leaves nodes with almost no enriched mass: the
  // first build evaluates every element, the pruned rebuild reuses all their integrals.
  // (The old model's cut crosses both elements, so that neither reuses the old model's
  // integrals, which have no kept values: the nodes tied on the element edge bring the
  // right element into the pruned basis.)
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto old_model = enriched_model(
      mesh, {straight_cut_enrichment(mesh, 64, [](const double* x) { return x[0] + 0.4 * x[1] - 0.55; }, false)}, 1e-3);
  const std::vector<EnrichmentFunction> sliver = {
      straight_cut_enrichment(mesh, 64, [](const double* x) { return x[0] - 0.5 / 64; })};
  const auto keeping = expect_kept_moments_bitwise(*old_model, sliver);
  EXPECT_GT(keeping->num_pruned_enriched_nodes(), 0);
  EXPECT_GT(keeping->num_tied_enriched_nodes(), 0);
}

TEST(KeptBasisValues, ABasisWithoutEnrichedElementsKeepsNone) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto model = enriched_model(mesh, {}, 0.0);
  model->keep_basis_values();
  model->set_enrichments({straight_cut_enrichment(mesh, 32, [](const double* x) { return x[0] - 0.25; })});
  int kept_elements = 0;
  for (int e = 0; e < mesh.num_elements(); ++e) kept_elements += model->has_kept_basis_values(e);
  EXPECT_EQ(kept_elements, model->num_enriched_elements());
  // The cut removed: nothing is integrated, and the values of the old basis must not stay.
  model->set_enrichments({});
  for (int e = 0; e < mesh.num_elements(); ++e) EXPECT_FALSE(model->has_kept_basis_values(e));
}

namespace {

// Moments onto `next` from `source` as kept (its values read at shared points) against a copy
// of `source` without kept values (evaluated everywhere): bitwise equal. Returns the points
// read from the source's values.
std::int64_t expect_source_values_give_the_moments_bitwise(const ShellModel& source, const ShellModel& next) {
  ShellModel evaluated_source(source);
  evaluated_source.release_basis_values();
  const std::vector<double> u = random_values(source.num_dofs(), 3), v = random_values(source.num_dofs(), 4);
  std::int64_t read = -1, read_without = -1;
  const auto from_kept = next.moments_of_fields(source, {&u, &v}, &read);
  const auto from_evaluated = next.moments_of_fields(evaluated_source, {&u, &v}, &read_without);
  EXPECT_TRUE(bitwise_equal(from_kept[0], from_evaluated[0]));
  EXPECT_TRUE(bitwise_equal(from_kept[1], from_evaluated[1]));
  EXPECT_EQ(read_without, 0);
  return read;
}

}  // namespace

TEST(KeptBasisValues, TheNextProjectionReadsTheSourcesValuesAtSharedPointsBitwise) {
  // A second cut in the right element: the left element's points stay where they were, the
  // right one's cells split along the new cut.
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto left = [](const double* x) { return x[0] - 0.25; };
  const auto right = [](const double* x) { return x[0] + 0.3 * x[1] - 0.8; };
  auto source = enriched_model(mesh, {}, 0.0);
  source->keep_basis_values();
  source->set_enrichments({straight_cut_enrichment(mesh, 32, left)});
  ShellModel next(*source);
  next.keep_basis_values();
  next.set_enrichments({straight_cut_enrichment(mesh, 32, left), straight_cut_enrichment(mesh, 32, right, false)});
  const std::int64_t read = expect_source_values_give_the_moments_bitwise(*source, next);
  EXPECT_GT(read, 0);
  EXPECT_LT(read, next.num_enriched_element_quadrature_points());
  // The sums are split among the threads by basis function: the same bits for any count.
  const std::vector<double> u = random_values(source->num_dofs(), 5);
  const auto one = test::with_threads(1, [&] { return next.moments_of_fields(*source, {&u}); });
  for (int threads : {2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    EXPECT_TRUE(bitwise_equal(next.moments_of_fields(*source, {&u})[0], one[0])) << threads << " threads";
  }
}

TEST(KeptBasisValues, APrunedSourceGivesItsKeptColumnsToTheNextProjection) {
  // The source is a pruned rebuild (its values are columns of its first build's); the next
  // basis adds a cut in the right element.
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto sliver = [](const double* x) { return x[0] - 0.5 / 64; };
  auto source = enriched_model(mesh, {}, 1e-3);
  source->keep_basis_values();
  source->set_enrichments({straight_cut_enrichment(mesh, 64, sliver)});
  ASSERT_GT(source->num_pruned_enriched_nodes(), 0);
  ShellModel next(*source);
  next.keep_basis_values();
  next.set_enrichments({straight_cut_enrichment(mesh, 64, sliver),
                        straight_cut_enrichment(mesh, 64, [](const double* x) { return x[0] + 0.3 * x[1] - 0.8; }, false)});
  EXPECT_GT(expect_source_values_give_the_moments_bitwise(*source, next), 0);
}

TEST(KeptBasisValues, ASourceWithoutEnrichedElementsIsEvaluated) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  auto source = enriched_model(mesh, {}, 0.0);
  source->keep_basis_values();
  source->set_enrichments({});
  ShellModel next(*source);
  next.set_enrichments({straight_cut_enrichment(mesh, 32, [](const double* x) { return x[0] - 0.25; })});
  EXPECT_EQ(expect_source_values_give_the_moments_bitwise(*source, next), 0);
}

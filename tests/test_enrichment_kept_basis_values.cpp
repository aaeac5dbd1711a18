// A basis change evaluates the new basis at every quadrature point of the enriched elements
// twice: for the new mass matrix and for the projection's moments. A model told to keep
// those values (ShellModel::keep_basis_values, as SceneRun does for its next model) reads
// them in moments_of_fields instead. The kept values must give the moments bitwise, also
// where set_enrichments prunes nodes and rebuilds from a subset of the functions (their
// columns of the first build's values), and nothing must stay kept after release.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "enrichment_test_support.h"
#include "shell_test_support.h"

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
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto old_model =
      enriched_model(mesh, {straight_cut_enrichment(mesh, 64, [](const double* x) { return x[0] - 0.25; })}, 1e-3);
  const std::vector<EnrichmentFunction> sliver = {
      straight_cut_enrichment(mesh, 64, [](const double* x) { return x[0] - 0.5 / 64; })};
  const auto keeping = expect_kept_moments_bitwise(*old_model, sliver);
  EXPECT_GT(keeping->num_pruned_enriched_nodes(), 0);
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

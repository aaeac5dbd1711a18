// A copy of an enriched model (SceneRun copies its model at every basis change, then gives
// the copy new functions) shares the enrichment functions instead of copying their textures,
// and stands on its own: it assembles the same stiffness after the original is gone (ASan
// would see a texture read from freed memory), and new functions on the copy leave the
// original's as they were.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "enrichment_test_support.h"
#include "shell_test_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

TEST(EnrichedModelCopy, SharesTheTexturesAndOutlivesTheOriginal) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  auto original =
      enriched_model(mesh, {straight_cut_enrichment(mesh, 32, [](const double* x) { return x[0] - 0.25; })}, 0.0);
  ASSERT_GT(original->num_enriched_elements(), 0);
  std::vector<double> current = original->rest_state();
  for (std::size_t d = 0; d < current.size(); ++d) current[d] += 1e-3 * static_cast<double>(d % 7);
  std::vector<double> expected;
  original->assemble_stiffness(current.data(), expected, nullptr);

  auto copy = std::make_unique<ShellModel>(*original);
  ASSERT_EQ(copy->enrichments().size(), original->enrichments().size());
  EXPECT_EQ(copy->enrichments()[0].elements[0].tile.values.data(),
            original->enrichments()[0].elements[0].tile.values.data());  // shared, not copied
  const std::vector<double> original_values = original->enrichments()[0].elements[0].tile.values;
  original.reset();
  std::vector<double> blocks;
  copy->assemble_stiffness(current.data(), blocks, nullptr);
  EXPECT_TRUE(bitwise_equal(blocks, expected));

  // New functions on a copy of the copy: the copy keeps its own.
  ShellModel next(*copy);
  const auto slanted = [](const double* x) { return x[0] + 0.3 * x[1] - 0.6; };
  next.set_enrichments({straight_cut_enrichment(mesh, 32, slanted, /*aligned=*/false)});
  EXPECT_NE(next.enrichments()[0].elements[0].tile.values, original_values);
  EXPECT_EQ(copy->enrichments()[0].elements[0].tile.values, original_values);
  copy->assemble_stiffness(current.data(), blocks, nullptr);
  EXPECT_TRUE(bitwise_equal(blocks, expected));
}

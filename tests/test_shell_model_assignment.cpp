// A ShellModel assigned another assembles what the other does. The assembly keeps data
// built for the model's rest geometry and basis between calls (the plain elements' and
// edges' rest rows, the rotation clusters' rest sums); an assigned model starts those over
// as a copy does. Until session 72 it kept its own, checked by size only, so a model of
// another plate with as many elements assembled its old plate's stiffness.
#include <gtest/gtest.h>

#include <vector>

#include "dgtex/mesh_generators.h"
#include "dgtex/scene_run.h"
#include "dgtex/shell_model.h"
#include "dgtex/topology.h"
#include "scene_in_code_support.h"

namespace {

using namespace dgtex;

// A 4 x 4 quad8 plate `width` long: the same element and edge counts for every width.
ShellModel plate(double width) {
  const Mesh mesh = make_rectangle(width, 1.0, 4, 4, ElementType::quad8);
  const std::vector<kernels::ShellSection> sections(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  ShellModelOptions options;
  options.penalty = 1.0;
  return ShellModel(mesh, build_topology(mesh), sections, {}, options);
}

// The corotated stiffness at the rest state (which builds the cached rest data).
std::vector<double> corotated_stiffness(const ShellModel& model) {
  std::vector<double> blocks, corrective;
  model.assemble_stiffness(model.rest_state().data(), blocks, &corrective);
  return blocks;
}

TEST(ShellModelAssignment, APlainModelAssignedAnotherAssemblesTheOthersStiffness) {
  const ShellModel wide = plate(3.0);
  const std::vector<double> expected = corotated_stiffness(wide);
  ASSERT_NE(corotated_stiffness(plate(1.0)), expected);

  ShellModel copied_into = plate(1.0);
  corotated_stiffness(copied_into);
  copied_into = wide;
  EXPECT_EQ(corotated_stiffness(copied_into), expected);

  ShellModel moved_into = plate(1.0);
  corotated_stiffness(moved_into);
  moved_into = plate(3.0);
  EXPECT_EQ(corotated_stiffness(moved_into), expected);
}

// The rotation clusters' rest sums, built at the first corotated assembly, likewise: two
// strips cut at different places in the same element.
TEST(ShellModelAssignment, AClusteredEnrichedModelAssignedAnotherAssemblesTheOthersStiffness) {
  Scene scene = test::strip_built_in_code();
  scene.enrichment.rotation_cluster_texels = 4;
  Scene other_scene = scene;
  other_scene.cuts[0].points = {{0.275, 0, 0}, {0.275, 0.06, 0}};
  const SceneRun run(scene), other_run(other_scene);
  const ShellModel other = other_run.model();
  ASSERT_GT(other.num_enriched_dofs(), 0);
  const std::vector<double> expected = corotated_stiffness(other);
  ASSERT_GT(other.num_rotation_clusters(), 0);

  ShellModel assigned = run.model();
  ASSERT_NE(corotated_stiffness(assigned), expected);
  assigned = other;
  EXPECT_EQ(corotated_stiffness(assigned), expected);
  EXPECT_EQ(assigned.num_rotation_clusters(), other.num_rotation_clusters());
}

}  // namespace

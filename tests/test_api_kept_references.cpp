// Where a public class keeps a reference to an argument (README, "Public API", ownership),
// a temporary argument is a compile error instead of a dangling reference; SceneRun keeps
// a copy of its Scene instead, so a temporary scene is fine.
#include <gtest/gtest.h>

#include <type_traits>
#include <vector>

#include "dgtex/cut_manager.h"
#include "dgtex/deformed_shell.h"
#include "dgtex/factor_reusing_solver.h"
#include "dgtex/scene_run.h"
#include "dgtex/shell_simulation.h"

namespace {

using namespace dgtex;

TEST(KeptReferences, ATemporaryIsRefusedWhereAReferenceIsKept) {
  static_assert(std::is_constructible_v<DeformedShell, const ShellState&>);
  static_assert(!std::is_constructible_v<DeformedShell, ShellState>, "DeformedShell(run.state()) would dangle");

  using Fixed = std::vector<char>;
  using Force = std::vector<double>;
  static_assert(std::is_constructible_v<ShellSimulation, const ShellModel&, Fixed, Force>);
  static_assert(!std::is_constructible_v<ShellSimulation, ShellModel, Fixed, Force>);

  using Cuts = std::vector<Cut>;
  static_assert(std::is_constructible_v<CutManager, const Mesh&, const Topology&, const Cuts&, const EnrichmentOptions&>);
  static_assert(!std::is_constructible_v<CutManager, Mesh, const Topology&, const Cuts&, const EnrichmentOptions&>);
  // The topology is read by the constructor only (build_topology(mesh) as an argument is fine).
  static_assert(std::is_constructible_v<CutManager, const Mesh&, Topology, const Cuts&, const EnrichmentOptions&>);

  using Mass = std::vector<double>;
  static_assert(std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, const FreeDofSystem&, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, BlockAssembly, const FreeDofSystem&, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, FreeDofSystem, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, const FreeDofSystem&, Mass>);
  SUCCEED() << "checked at compile time";
}

// A clamped strip under gravity with a cut from its lower edge, built in code.
Scene cut_strip() {
  Scene scene;
  scene.source_name = "cut strip";
  scene.mesh.source = MeshSource::rectangle;
  scene.mesh.size = {0.4, 0.1};
  scene.mesh.divisions = {4, 1};
  scene.material = {5e8, 0.3, 0.01, 1000};
  BoundaryCondition clamp;
  clamp.select.normal = {1, 0, 0};
  clamp.fixed = {true, true, true};
  clamp.clamp = true;
  scene.boundary.push_back(clamp);
  Load gravity;
  gravity.acceleration = {0, 0, -9.81};
  scene.loads.push_back(gravity);
  scene.analysis.type = Analysis::Type::dynamic;
  scene.analysis.time_step = 0.005;
  scene.analysis.steps = 3;
  scene.analysis.corotational = true;
  Cut cut;
  cut.points = {{0.225, 0, 0}, {0.225, 0.06, 0}};
  scene.cuts.push_back(cut);
  scene.enrichment.texture_resolution = 32;
  return scene;
}

// The steps read the scene (its step count, its loads at a basis change): a kept reference
// to the temporary would be read after its scope, which the sanitizer build reports.
TEST(KeptReferences, SceneRunKeepsACopyOfTheScene) {
  SceneRun from_temporary(cut_strip());
  const Scene scene = cut_strip();
  SceneRun from_named(scene);
  for (int i = 0; i < scene.analysis.steps; ++i) from_temporary.step(), from_named.step();
  EXPECT_EQ(from_temporary.steps_taken(), scene.analysis.steps);
  EXPECT_EQ(from_temporary.displacement(), from_named.displacement());
}

}  // namespace

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
#include "dgtex/surface_point.h"
#include "scene_in_code_support.h"

namespace {

using namespace dgtex;

TEST(KeptReferences, ATemporaryIsRefusedWhereAReferenceIsKept) {
  static_assert(std::is_constructible_v<DeformedShell, const ShellState&>);
  static_assert(!std::is_constructible_v<DeformedShell, ShellState>, "DeformedShell(run.state()) would dangle");
  // A const temporary (a getter returning `const ShellState`) bound to `const T&` until
  // session 71: each kept reference also refuses `const T&&`.
  static_assert(!std::is_constructible_v<DeformedShell, const ShellState>);

  using Fixed = std::vector<char>;
  using Force = std::vector<double>;
  static_assert(std::is_constructible_v<ShellSimulation, const ShellModel&, Fixed, Force>);
  static_assert(!std::is_constructible_v<ShellSimulation, ShellModel, Fixed, Force>);
  static_assert(!std::is_constructible_v<ShellSimulation, const ShellModel, Fixed, Force>);

  using Cuts = std::vector<Cut>;
  static_assert(std::is_constructible_v<CutManager, const Mesh&, const Topology&, const Cuts&, const EnrichmentOptions&>);
  static_assert(!std::is_constructible_v<CutManager, Mesh, const Topology&, const Cuts&, const EnrichmentOptions&>);
  static_assert(!std::is_constructible_v<CutManager, const Mesh, const Topology&, const Cuts&, const EnrichmentOptions&>);
  // The topology is read by the constructor only (build_topology(mesh) as an argument is fine).
  static_assert(std::is_constructible_v<CutManager, const Mesh&, Topology, const Cuts&, const EnrichmentOptions&>);

  static_assert(std::is_constructible_v<SurfacePointSearch, const Mesh&>);
  static_assert(!std::is_constructible_v<SurfacePointSearch, Mesh>, "SurfacePointSearch(make_rectangle(...)) would dangle");
  static_assert(!std::is_constructible_v<SurfacePointSearch, const Mesh>);

  using Mass = std::vector<double>;
  static_assert(std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, const FreeDofSystem&, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, BlockAssembly, const FreeDofSystem&, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, FreeDofSystem, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, const FreeDofSystem&, Mass>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, const BlockAssembly, const FreeDofSystem&, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, const FreeDofSystem, const Mass&>);
  static_assert(!std::is_constructible_v<FactorReusingSolver, const BlockAssembly&, const FreeDofSystem&, const Mass>);
  SUCCEED() << "checked at compile time";
}

// The steps read the scene (its step count, its loads at a basis change): a kept reference
// to the temporary would be read after its scope, which the sanitizer build reports.
TEST(KeptReferences, SceneRunKeepsACopyOfTheScene) {
  SceneRun from_temporary(test::strip_built_in_code());
  const Scene scene = test::strip_built_in_code();
  SceneRun from_named(scene);
  for (int i = 0; i < scene.analysis.steps; ++i) from_temporary.step(), from_named.step();
  EXPECT_EQ(from_temporary.steps_taken(), scene.analysis.steps);
  EXPECT_EQ(from_temporary.displacement(), from_named.displacement());
}

}  // namespace

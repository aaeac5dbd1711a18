// A Scene built in code (the C++ API, not a scene file) is checked as a file is:
// validate_scene, and SceneRun and the scene builders, which call it, refuse a bad value
// with the SceneError a scene file holding it would give, its JSON path naming the field.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "dgtex/scene.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/scene_run.h"
#include "example_scene_files_support.h"
#include "scene_in_code_support.h"

namespace {

using namespace dgtex;
using test::strip_built_in_code;

struct BadValue {
  const char* what;
  std::function<void(Scene&)> set;
  const char* json_path;
  const char* message_part;  // the value as the message shows it, or the problem
};

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInfinity = std::numeric_limits<double>::infinity();

std::vector<BadValue> bad_values() {
  return {
      {"E = 0", [](Scene& s) { s.material.youngs_modulus = 0; }, "material.youngs_modulus", "must be positive, got 0"},
      {"E = NaN", [](Scene& s) { s.material.youngs_modulus = kNaN; }, "material.youngs_modulus", "got NaN"},
      {"nu = 0.5", [](Scene& s) { s.material.poisson_ratio = 0.5; }, "material.poisson_ratio", "got 0.5"},
      {"h = 0", [](Scene& s) { s.material.thickness = 0; }, "material.thickness", "must be positive"},
      {"no density, dynamic", [](Scene& s) { s.material.density = 0; }, "material.density", "dynamic analysis"},
      {"dt = 0", [](Scene& s) { s.analysis.time_step = 0; }, "analysis.time_step", "must be positive"},
      {"dt < 0", [](Scene& s) { s.analysis.time_step = -0.005; }, "analysis.time_step", "got -0.005"},
      {"no steps", [](Scene& s) { s.analysis.steps = 0; }, "analysis.steps", "got 0"},
      {"negative damping", [](Scene& s) { s.analysis.damping.mass = -1; }, "analysis.damping.mass", "got -1"},
      {"penalty 0", [](Scene& s) { s.penalty = 0; }, "penalty", "must be positive"},
      {"no divisions", [](Scene& s) { s.mesh.divisions = {0, 1}; }, "mesh.divisions[0]", "got 0"},
      {"zero width", [](Scene& s) { s.mesh.size[1] = 0; }, "mesh.size[1]", "must be positive"},
      {"zero normal", [](Scene& s) { s.boundary[0].select.normal = {0, 0, 0}; }, "boundary[0].select.plane.normal",
       "zero normal"},
      {"nothing held", [](Scene& s) { s.boundary[0].fixed = {false, false, false}, s.boundary[0].clamp = false; },
       "boundary[0].fix", "holds nothing"},
      {"infinite gravity", [](Scene& s) { s.loads[0].acceleration[2] = -kInfinity; }, "loads[0].acceleration[2]",
       "got -Infinity"},
      {"cut of one point", [](Scene& s) { s.cuts[0].points.resize(1); }, "cuts[0].points", "at least 2 points"},
      {"NaN cut point", [](Scene& s) { s.cuts[0].points[1][1] = kNaN; }, "cuts[0].points[1][1]", "got NaN"},
      {"negative start time", [](Scene& s) { s.cuts[0].start_time = -1; }, "cuts[0].start_time", "must not be negative"},
      {"cut speed 0", [](Scene& s) { s.cuts[0].has_schedule = true, s.cuts[0].speed = 0.0; }, "cuts[0].speed",
       "must be positive"},
      {"T = 33", [](Scene& s) { s.enrichment.texture_resolution = 33; }, "enrichment.texture_resolution",
       "not a power of two"},
      {"T = 0", [](Scene& s) { s.enrichment.texture_resolution = 0; }, "enrichment.texture_resolution", "got 0"},
      {"quadrature tolerance 0", [](Scene& s) { s.enrichment.quadrature_tolerance = 0; },
       "enrichment.quadrature_tolerance", "must be positive"},
      {"negative cluster", [](Scene& s) { s.enrichment.rotation_cluster_texels = -1; },
       "enrichment.rotation_cluster_texels", "got -1"},
      {"render width 0", [](Scene& s) { s.render = RenderOptions{}, s.render->width = 0; }, "render.width", "got 0"},
      {"report path", [](Scene& s) { s.output.report = "../report.json"; }, "output.report", "not a plain file name"},
      // Enum values outside their types (a cast in code) were written as a valid neighbour:
      // a Load::Type of 9 as no load, an Analysis::Type of 4 as static (session 71).
      {"load type 9", [](Scene& s) { s.loads[0].type = static_cast<Load::Type>(9); }, "loads[0].type",
       "<not a Load::Type: 9>"},
      {"analysis type 4", [](Scene& s) { s.analysis.type = static_cast<Analysis::Type>(4); }, "analysis.type",
       "<not a Analysis::Type: 4>"},
      {"element type 7", [](Scene& s) { s.mesh.element = static_cast<ElementType>(7); }, "mesh.element",
       "<not a ElementType: 7>"},
      {"select kind 5", [](Scene& s) { s.boundary[0].select.kind = static_cast<BoundarySelect::Kind>(5); },
       "boundary[0].select.plane", "<not a BoundarySelect::Kind: 5>"},
      {"cut kind 3", [](Scene& s) { s.cuts[0].kind = static_cast<Cut::Kind>(3); }, "cuts[0].points",
       "<not a Cut::Kind: 3>"},
      {"solver 7", [](Scene& s) { s.enrichment.solver = static_cast<EnrichmentOptions::Solver>(7); },
       "enrichment.solver", "<not a EnrichmentOptions::Solver: 7>"},
      {"shading 9", [](Scene& s) { s.render = RenderOptions{}, s.render->shading = static_cast<RenderOptions::Shading>(9); },
       "render.shading", "<not a RenderOptions::Shading: 9>"},
      {"probe name with a NUL", [](Scene& s) { s.probes = {Probe{std::string("tip\0x", 5), {1, 0.1, 0}}}; },
       "probes[0].name", "a string with a NUL character"},
  };
}

TEST(SceneValidation, ASceneBuiltInCodeRunsWhenValid) {
  const Scene scene = strip_built_in_code();
  EXPECT_NO_THROW(validate_scene(scene));
  SceneRun run(scene);
  run.step();
  EXPECT_EQ(run.steps_taken(), 1);
  EXPECT_GT(run.model().num_enriched_dofs(), 0);
}

TEST(SceneValidation, SceneRunRefusesABadValueNamingItsField) {
  for (const BadValue& bad : bad_values()) {
    SCOPED_TRACE(bad.what);
    Scene scene = strip_built_in_code();
    bad.set(scene);
    try {
      SceneRun run(scene);
      ADD_FAILURE() << "accepted";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.json_path(), bad.json_path) << e.what();
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("strip (built in code): " + std::string(bad.json_path) + ": ", 0), 0u) << message;
      EXPECT_NE(message.find(bad.message_part), std::string::npos) << message;
    }
  }
}

// The builders check too, so the benchmarks and programs that build a model without
// SceneRun get the same errors.
// A start time set in code without has_schedule still delays the cut, so it is checked as
// a schedule: a static scene cannot have one.
TEST(SceneValidation, AStartTimeSetInCodeCountsAsASchedule) {
  Scene scene = strip_built_in_code(false);
  scene.cuts[0].start_time = 0.5;
  try {
    validate_scene(scene);
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "cuts[0].start_time") << e.what();
    EXPECT_NE(std::string(e.what()).find("needs a dynamic analysis"), std::string::npos) << e.what();
  }
}

TEST(SceneValidation, TheSceneBuildersRefuseABadValue) {
  const Scene good = strip_built_in_code();
  const Mesh mesh = build_scene_mesh(good);
  Scene bad = good;
  bad.material.poisson_ratio = -1;
  EXPECT_THROW(build_scene_mesh(bad), SceneError);
  EXPECT_THROW(build_scene_model(bad, mesh), SceneError);
  Scene triangles = good;
  triangles.mesh.element = ElementType::tri6;
  try {
    build_scene_model(good, build_scene_mesh(triangles));
    ADD_FAILURE() << "a tri6 mesh was taken for the quad8 scene";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "mesh.element") << e.what();
    EXPECT_NE(std::string(e.what()).find("the mesh given has other elements, got tri6"), std::string::npos) << e.what();
  }
  const SceneModel model = build_scene_model(good, mesh);
  // The held DOFs and loads of a scene check it too: a zero plane normal held nothing, a
  // NaN load reached the simulation named as external_force[i] (session 71).
  Scene unheld = good;
  unheld.boundary[0].select.normal = {0, 0, 0};
  EXPECT_THROW(scene_fixed_dofs(unheld, *model.model), SceneError);
  Scene unloaded = good;
  unloaded.loads[0].acceleration[2] = kNaN;
  EXPECT_THROW(scene_external_force(unloaded, *model.model), SceneError);
  EXPECT_EQ(scene_fixed_dofs(good, *model.model), model.fixed);
  EXPECT_EQ(scene_external_force(good, *model.model), model.external_force);
}

TEST(SceneValidation, ASceneWithoutASourceNameIsCalledScene) {
  Scene scene = strip_built_in_code();
  scene.source_name.clear();
  scene.material.thickness = -0.01;
  try {
    validate_scene(scene);
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("scene: material.thickness: ", 0), 0u) << e.what();
  }
}

// What the parser made of a scene file passes again: every example scene as loaded.
TEST(SceneValidation, EveryExampleSceneAsLoadedPasses) {
  const std::vector<std::string> files = test::example_scene_files();
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    EXPECT_NO_THROW(validate_scene(load_scene(file)));
  }
  EXPECT_GE(files.size(), 11u);
}

// A camera looking straight down with the default up passes again once loaded (the
// renderer turns that up; validate_scene re-reads the scene through its JSON, which until
// session 72 always wrote the up and so refused it as given along the view).
TEST(SceneValidation, ACameraLookingStraightDownWithTheDefaultUpPasses) {
  Scene scene = strip_built_in_code();
  scene.render = RenderOptions{};
  scene.render->camera_position = Vec3{0.5, 0.5, 2};
  scene.render->camera_target = Vec3{0.5, 0.5, 0};
  EXPECT_NO_THROW(validate_scene(scene));
  // An up along the view that is not the default is still refused.
  scene.render->camera_up = Vec3{0, 0, -1};
  try {
    validate_scene(scene);
    ADD_FAILURE() << "an up along the view was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("render.camera.up: up is parallel to the viewing direction"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace

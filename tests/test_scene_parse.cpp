// Valid scene files read into the expected Scene values; defaults; canonical round trip.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "dgtex/mesh_generators.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"

namespace {

using namespace dgtex;

std::string scene_path(const std::string& name) { return std::string(DGTEX_SOURCE_DIR) + "/tests/data/scenes/" + name; }

TEST(SceneParse, FullSceneHasEveryValue) {
  const Scene s = load_scene(scene_path("full.json"));
  EXPECT_EQ(s.source_name, scene_path("full.json"));
  EXPECT_EQ(s.mesh.source, MeshSource::rectangle);
  ASSERT_TRUE(s.mesh.element.has_value());
  EXPECT_EQ(*s.mesh.element, ElementType::tri6);
  EXPECT_EQ(s.mesh.size[0], 2.0);
  EXPECT_EQ(s.mesh.size[1], 1.0);
  EXPECT_EQ(s.mesh.divisions[0], 8);
  EXPECT_EQ(s.mesh.divisions[1], 4);

  EXPECT_EQ(s.material.youngs_modulus, 2e6);
  EXPECT_EQ(s.material.poisson_ratio, 0.25);
  EXPECT_EQ(s.material.thickness, 0.02);
  EXPECT_EQ(s.material.density, 500.0);
  EXPECT_EQ(s.penalty, 20.0);

  ASSERT_EQ(s.boundary.size(), 2u);
  const BoundaryCondition& clamped = s.boundary[0];
  EXPECT_EQ(clamped.select.kind, BoundarySelect::Kind::plane);
  // The normal [2, 0, 0] is stored normalised.
  EXPECT_EQ(clamped.select.normal, (Vec3{1, 0, 0}));
  EXPECT_EQ(clamped.select.offset, 0.0);
  EXPECT_EQ(clamped.select.tolerance, 1e-5);
  EXPECT_EQ(clamped.fixed, (std::array<bool, 3>{true, true, true}));
  EXPECT_TRUE(clamped.clamp);
  const BoundaryCondition& roller = s.boundary[1];
  EXPECT_EQ(roller.select.kind, BoundarySelect::Kind::box);
  EXPECT_EQ(roller.select.min, (Vec3{1.9, -1, -1}));
  EXPECT_EQ(roller.select.max, (Vec3{2.1, 2, 1}));
  EXPECT_EQ(roller.select.tolerance, 1e-6);  // default
  EXPECT_EQ(roller.fixed, (std::array<bool, 3>{false, false, true}));
  EXPECT_FALSE(roller.clamp);

  ASSERT_EQ(s.loads.size(), 3u);
  EXPECT_EQ(s.loads[0].type, Load::Type::gravity);
  EXPECT_EQ(s.loads[0].acceleration, (Vec3{0, 0, -9.81}));
  EXPECT_EQ(s.loads[1].type, Load::Type::area_force);
  EXPECT_EQ(s.loads[1].force_per_area, (Vec3{0, 0, -1}));
  EXPECT_EQ(s.loads[2].type, Load::Type::point);
  EXPECT_EQ(s.loads[2].position, (Vec3{1.5, 0.5, 0}));
  EXPECT_EQ(s.loads[2].force, (Vec3{0, 0, -3}));

  EXPECT_TRUE(s.analysis.is_dynamic());
  EXPECT_EQ(s.analysis.time_step, 0.001);
  EXPECT_EQ(s.analysis.steps, 250);
  EXPECT_TRUE(s.analysis.corotational);
  EXPECT_EQ(s.analysis.damping.mass, 0.1);
  EXPECT_EQ(s.analysis.damping.stiffness, 0.002);

  ASSERT_EQ(s.probes.size(), 2u);
  EXPECT_EQ(s.probes[0].name, "tip");
  EXPECT_EQ(s.probes[0].position, (Vec3{2, 0.5, 0}));
  EXPECT_EQ(s.probes[1].name, "center");

  ASSERT_EQ(s.cuts.size(), 2u);
  EXPECT_EQ(s.cuts[0].kind, Cut::Kind::points);
  ASSERT_EQ(s.cuts[0].points.size(), 3u);
  EXPECT_EQ(s.cuts[0].points[2], (Vec3{0.7, 0.9, 0}));
  EXPECT_FALSE(s.cuts[0].has_schedule);
  EXPECT_FALSE(s.cuts[0].speed.has_value());
  EXPECT_EQ(s.cuts[1].kind, Cut::Kind::surface_points);
  ASSERT_EQ(s.cuts[1].surface_points.size(), 2u);
  EXPECT_EQ(s.cuts[1].surface_points[1].element, 5);
  EXPECT_EQ(s.cuts[1].surface_points[1].xi, (std::array<double, 2>{0.5, 0.25}));
  EXPECT_TRUE(s.cuts[1].has_schedule);
  EXPECT_EQ(s.cuts[1].start_time, 0.05);
  ASSERT_TRUE(s.cuts[1].speed.has_value());
  EXPECT_EQ(*s.cuts[1].speed, 2.5);

  EXPECT_EQ(s.enrichment.texture_resolution, 128);
  EXPECT_EQ(s.enrichment.solver, EnrichmentOptions::Solver::cholmod);
  EXPECT_EQ(s.enrichment.new_cut_length.value_or(-1), 0.3);
  EXPECT_EQ(s.enrichment.new_cut_angle_deg.value_or(-1), 45.0);
  EXPECT_EQ(s.enrichment.rotation_cluster_texels, 16);

  ASSERT_TRUE(s.render.has_value());
  const RenderOptions& r = *s.render;
  EXPECT_EQ(r.width, 800);
  EXPECT_EQ(r.height, 600);
  EXPECT_EQ(r.camera_position.value_or(Vec3{}), (Vec3{1, -3, 2}));
  EXPECT_EQ(r.camera_target.value_or(Vec3{}), (Vec3{1, 0.5, 0}));
  EXPECT_EQ(r.camera_up, (Vec3{0, 0, 1}));
  EXPECT_EQ(r.fov_deg, 35.0);
  EXPECT_EQ(r.every_steps, 5);
  EXPECT_EQ(r.shading, RenderOptions::Shading::smooth);
  EXPECT_EQ(r.background, (Vec3{0.1, 0.2, 0.3}));
  EXPECT_EQ(s.output.report, "result.json");
}

TEST(SceneParse, MinimalSceneGetsDocumentedDefaults) {
  const Scene s = load_scene(scene_path("minimal.json"));
  EXPECT_EQ(s.mesh.element.value(), ElementType::quad8);
  EXPECT_EQ(s.mesh.triangles, TriangleSplit::sheared);
  EXPECT_EQ(s.material.density, 0.0);
  EXPECT_EQ(s.penalty, 10.0);
  EXPECT_TRUE(s.boundary.empty());
  EXPECT_TRUE(s.loads.empty());
  EXPECT_FALSE(s.analysis.is_dynamic());
  EXPECT_FALSE(s.analysis.corotational);
  EXPECT_EQ(s.analysis.damping.mass, 0.0);
  EXPECT_EQ(s.analysis.damping.stiffness, 0.0);
  EXPECT_TRUE(s.probes.empty());
  EXPECT_TRUE(s.cuts.empty());
  EXPECT_EQ(s.enrichment.texture_resolution, 256);
  EXPECT_EQ(s.enrichment.solver, EnrichmentOptions::Solver::multigrid);
  EXPECT_FALSE(s.enrichment.new_cut_length.has_value());
  EXPECT_FALSE(s.enrichment.new_cut_angle_deg.has_value());
  EXPECT_EQ(s.enrichment.rotation_cluster_texels, 0);  // per point
  EXPECT_FALSE(s.render.has_value());
  EXPECT_EQ(s.output.report, "report.json");
}

TEST(SceneParse, RenderBlockDefaults) {
  const Scene s = parse_scene(R"({"mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [1, 1]},
    "material": {"youngs_modulus": 1, "poisson_ratio": 0, "thickness": 1}, "render": {}})",
                              "render.json");
  ASSERT_TRUE(s.render.has_value());
  EXPECT_EQ(s.render->width, 640);
  EXPECT_EQ(s.render->height, 480);
  EXPECT_FALSE(s.render->camera_position.has_value());
  EXPECT_FALSE(s.render->camera_target.has_value());
  EXPECT_EQ(s.render->camera_up, (Vec3{0, 0, 1}));
  EXPECT_EQ(s.render->fov_deg, 40.0);
  EXPECT_EQ(s.render->every_steps, 10);
  EXPECT_EQ(s.render->shading, RenderOptions::Shading::flat);
  EXPECT_EQ(s.render->background, (Vec3{1, 1, 1}));
}

TEST(SceneParse, DesignDocumentExampleIsValid) {
  const Scene s = load_scene(scene_path("design_example.json"));
  EXPECT_EQ(s.boundary.size(), 1u);
  EXPECT_EQ(s.loads.size(), 3u);
  EXPECT_EQ(s.probes.size(), 1u);
  EXPECT_EQ(s.material.density, 1000.0);
}

TEST(SceneParse, GeneratorsReadTheirParameters) {
  const std::string material = R"("material": {"youngs_modulus": 1, "poisson_ratio": 0.3, "thickness": 0.1})";
  const Scene cylinder = parse_scene(R"({"mesh": {"generator": "cylinder", "radius": 2, "length": 3,
      "angle_deg": [-90, 270], "divisions": [12, 5], "element": "tri6"}, )" + material + "}", "c.json");
  EXPECT_EQ(cylinder.mesh.source, MeshSource::cylinder);
  EXPECT_EQ(cylinder.mesh.radius, 2.0);
  EXPECT_EQ(cylinder.mesh.length, 3.0);
  EXPECT_EQ(cylinder.mesh.angle_deg, (std::array<double, 2>{-90, 270}));
  EXPECT_TRUE(cylinder.mesh.closed_cylinder());
  EXPECT_EQ(cylinder.mesh.divisions, (std::array<int, 2>{12, 5}));

  const Scene open = parse_scene(R"({"mesh": {"generator": "cylinder", "radius": 2, "length": 3,
      "angle_deg": [0, 90], "divisions": [1, 1]}, )" + material + "}", "c.json");
  EXPECT_FALSE(open.mesh.closed_cylinder());

  const Scene dome = parse_scene(R"({"mesh": {"generator": "hemisphere", "radius": 1.5, "hole_deg": 10,
      "divisions": [4, 16]}, )" + material + "}", "h.json");
  EXPECT_EQ(dome.mesh.source, MeshSource::hemisphere);
  EXPECT_EQ(dome.mesh.radius, 1.5);
  EXPECT_EQ(dome.mesh.hole_deg, 10.0);
  EXPECT_EQ(dome.mesh.divisions, (std::array<int, 2>{4, 16}));
}

// "triangles" picks the tri6 split; it survives the canonical round trip (and so
// validate_scene), and the scene's mesh is the generator's square split.
TEST(SceneParse, Tri6TrianglesSplitIsReadAndKept) {
  const std::string material = R"("material": {"youngs_modulus": 1, "poisson_ratio": 0.3, "thickness": 0.1})";
  const Scene square = parse_scene(R"({"mesh": {"generator": "rectangle", "size": [2, 1], "divisions": [2, 1],
      "element": "tri6", "triangles": "square"}, )" + material + "}", "t.json");
  EXPECT_EQ(square.mesh.triangles, TriangleSplit::square);
  const Scene echo = parse_scene(scene_to_json_text(square), "echo.json");
  EXPECT_EQ(echo.mesh.triangles, TriangleSplit::square);
  const Mesh expected = make_rectangle(2, 1, 2, 1, ElementType::tri6, TriangleSplit::square);
  EXPECT_EQ(build_scene_mesh(square).elements, expected.elements);
  EXPECT_NE(build_scene_mesh(square).elements, make_rectangle(2, 1, 2, 1, ElementType::tri6).elements);
  const Scene sheared = parse_scene(R"({"mesh": {"generator": "rectangle", "size": [2, 1], "divisions": [2, 1],
      "element": "tri6", "triangles": "sheared"}, )" + material + "}", "t.json");
  EXPECT_EQ(sheared.mesh.triangles, TriangleSplit::sheared);
  EXPECT_EQ(scene_to_json_text(sheared).find("triangles"), std::string::npos);  // the default is not written
}

TEST(SceneParse, MeshFileResolvesAgainstTheSceneFolder) {
  const Scene s = load_scene(scene_path("file_mesh.json"));
  EXPECT_EQ(s.mesh.source, MeshSource::file);
  EXPECT_FALSE(s.mesh.element.has_value());  // from the OBJ's faces
  EXPECT_TRUE(std::filesystem::equivalent(s.mesh.file, scene_path("meshes/two_triangles.obj")));
  // Without an element type, surface points are only checked against [-1, 1]^2 here.
  ASSERT_EQ(s.cuts.size(), 1u);
  EXPECT_EQ(s.cuts[0].surface_points[0].xi, (std::array<double, 2>{0.9, -0.9}));
}

TEST(SceneParse, StaticDensityMayBeZeroWithoutGravity) {
  const Scene s = parse_scene(R"({"mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [1, 1]},
    "material": {"youngs_modulus": 1, "poisson_ratio": -0.99, "thickness": 1, "density": 0},
    "loads": [{"type": "area_force", "force_per_area": [0, 0, 1]}]})",
                              "s.json");
  EXPECT_EQ(s.material.density, 0.0);
  EXPECT_EQ(s.material.poisson_ratio, -0.99);
}

TEST(SceneParse, CanonicalJsonRoundTrips) {
  for (const char* name : {"full.json", "minimal.json", "design_example.json", "file_mesh.json"}) {
    SCOPED_TRACE(name);
    const Scene first = load_scene(scene_path(name));
    const std::string text = scene_to_json_text(first);
    const Scene second = parse_scene(text, "echo.json");
    EXPECT_EQ(scene_to_json_text(second), text);
    EXPECT_EQ(nlohmann::json::parse(text).at("version"), scene_format_version);  // the format it is written in
    EXPECT_EQ(second.material.youngs_modulus, first.material.youngs_modulus);
    EXPECT_EQ(second.boundary.size(), first.boundary.size());
    EXPECT_EQ(second.cuts.size(), first.cuts.size());
    EXPECT_EQ(second.render.has_value(), first.render.has_value());
    EXPECT_EQ(second.mesh.file, first.mesh.file);
  }
}

// Directions are directions at any length: a plane normal or camera up of 1e-170 squared to
// 0 and read as "zero" until session 72. Both are read as unit vectors.
TEST(SceneParse, TinyDirectionsAreReadAsUnitVectors) {
  const Scene s = parse_scene(R"({"mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [1, 1]},
      "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01},
      "boundary": [{"select": {"plane": {"normal": [1e-170, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"]}],
      "render": {"camera": {"position": [0.5, -2, 1], "target": [0.5, 0.5, 0], "up": [0, 0, 1e-200]}}})",
                              "tiny.json");
  EXPECT_EQ(s.boundary[0].select.normal, (Vec3{1, 0, 0}));
  EXPECT_EQ(s.render->camera_up, (Vec3{0, 0, 1}));
}

}  // namespace

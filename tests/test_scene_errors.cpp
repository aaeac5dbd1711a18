// Every class of invalid scene gives one SceneError line that names the JSON path and the
// offending value: "<file>: <path>: <problem>, got <value>; <what is valid>".
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "dgtex/scene_io.h"

namespace {

using dgtex::parse_scene;
using dgtex::SceneError;
using json = nlohmann::json;

const char* kSource = "bad.json";

json valid_scene() {
  return json::parse(R"({
    "mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [4, 4], "element": "quad8"},
    "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01, "density": 1000},
    "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}, "tolerance": 1e-6},
                  "fix": ["x", "y", "z"], "clamp": true}],
    "loads": [{"type": "area_force", "force_per_area": [0, 0, -1]}],
    "analysis": {"type": "static"},
    "probes": [{"name": "center", "position": [0.5, 0.5, 0]}],
    "cuts": [{"points": [[0.2, 0.5, 0], [0.8, 0.5, 0]]}]
  })");
}

json dynamic_scene() {
  json s = valid_scene();
  s["analysis"] = {{"type", "dynamic"}, {"time_step", 0.01}, {"steps", 10}};
  return s;
}

// The message of the SceneError that parsing text throws ("" if none).
std::string error_of_text(const std::string& text) {
  try {
    parse_scene(text, kSource);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// Parses the modified scene and checks the one-line message names path and value.
void expect_error(const json& scene, const std::string& path, const std::string& got, const std::string& problem = "") {
  const std::string message = error_of_text(scene.dump());
  ASSERT_FALSE(message.empty()) << "no error for " << scene.dump();
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(std::string(kSource) + ": " + path + ": ", 0), 0u) << message;
  if (!got.empty()) {
    EXPECT_NE(message.find(", got " + got), std::string::npos) << message;
  }
  if (!problem.empty()) {
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  }
}

json with(json scene, const json::json_pointer& pointer, const json& value) {
  scene[pointer] = value;
  return scene;
}
json without(json scene, const std::string& key) {
  scene.erase(key);
  return scene;
}

TEST(SceneErrors, ValidBaseScenesParse) {
  EXPECT_EQ(error_of_text(valid_scene().dump()), "");
  EXPECT_EQ(error_of_text(dynamic_scene().dump()), "");
}

TEST(SceneErrors, UnknownTopLevelKey) {
  expect_error(with(valid_scene(), "/meshes"_json_pointer, 3), "meshes", "3", "unknown key");
  // The message suggests the closest valid key.
  EXPECT_NE(error_of_text(with(valid_scene(), "/meshes"_json_pointer, 3).dump()).find("did you mean \"mesh\""),
            std::string::npos);
}

// The optional top-level "version" is the scene format's (dgtex::scene_format_version).
// A later format's scene is refused by its version, before its new keys read as unknown.
TEST(SceneErrors, AVersionOtherThanTheFormatsIsRefusedBeforeTheKeys) {
  EXPECT_EQ(error_of_text(with(valid_scene(), "/version"_json_pointer, dgtex::scene_format_version).dump()), "");
  expect_error(with(valid_scene(), "/version"_json_pointer, 2), "version", "2",
               "not a scene format this dgtex reads (a scene for a later dgtex?), got 2; expected 1, or no version key");
  expect_error(with(valid_scene(), "/version"_json_pointer, "1"), "version", "\"1\"", "expected 1");
  expect_error(with(valid_scene(), "/version"_json_pointer, 1.0), "version", "1.0", "expected 1");
  json later = with(valid_scene(), "/version"_json_pointer, 2);
  later["joints"] = json::array();
  expect_error(later, "version", "2", "not a scene format this dgtex reads");
}

TEST(SceneErrors, UnknownNestedKey) {
  json s = valid_scene();
  s["material"]["youngs_modulous"] = 1e6;
  expect_error(s, "material.youngs_modulous", "1000000.0", "did you mean \"youngs_modulus\"");
  json deep = valid_scene();
  deep["boundary"][0]["select"]["plane"]["normall"] = json::array({0, 0, 1});
  expect_error(deep, "boundary[0].select.plane.normall", "[0,0,1]", "unknown key");
  json in_cut = valid_scene();
  in_cut["cuts"][0]["sped"] = 2;
  expect_error(in_cut, "cuts[0].sped", "2", "did you mean \"speed\"");
}

TEST(SceneErrors, WrongType) {
  expect_error(with(valid_scene(), "/material/thickness"_json_pointer, "0.01"), "material.thickness", "\"0.01\"",
               "expected a number");
  expect_error(with(valid_scene(), "/boundary/0/clamp"_json_pointer, 1), "boundary[0].clamp", "1", "true or false");
  expect_error(with(valid_scene(), "/loads"_json_pointer, json::object()), "loads", "{}", "expected an array");
  expect_error(with(valid_scene(), "/probes/0/position"_json_pointer, json::array({1, 2})), "probes[0].position", "[1,2]",
               "3 numbers");
  expect_error(with(valid_scene(), "/mesh/divisions/0"_json_pointer, 4.5), "mesh.divisions[0]", "4.5", "integer");
  expect_error(with(valid_scene(), "/material"_json_pointer, json::array()), "material", "[]", "expected an object");
  const std::string root = error_of_text("[1, 2]");
  EXPECT_EQ(root.rfind("bad.json: (root): the scene must be a JSON object, got [1,2]", 0), 0u) << root;
}

TEST(SceneErrors, PoissonRatioAtTheLimits) {
  expect_error(with(valid_scene(), "/material/poisson_ratio"_json_pointer, 0.5), "material.poisson_ratio", "0.5",
               "-1 < poisson_ratio < 0.5");
  expect_error(with(valid_scene(), "/material/poisson_ratio"_json_pointer, -1), "material.poisson_ratio", "-1");
  expect_error(with(valid_scene(), "/material/poisson_ratio"_json_pointer, -1.0), "material.poisson_ratio", "-1.0");
  EXPECT_EQ(error_of_text(with(valid_scene(), "/material/poisson_ratio"_json_pointer, 0.4999).dump()), "");
  EXPECT_EQ(error_of_text(with(valid_scene(), "/material/poisson_ratio"_json_pointer, -0.9999).dump()), "");
}

TEST(SceneErrors, NonPositiveMaterialValues) {
  expect_error(with(valid_scene(), "/material/thickness"_json_pointer, -0.01), "material.thickness", "-0.01", "> 0");
  expect_error(with(valid_scene(), "/material/thickness"_json_pointer, 0), "material.thickness", "0");
  expect_error(with(valid_scene(), "/material/youngs_modulus"_json_pointer, 0.0), "material.youngs_modulus", "0.0");
  expect_error(with(valid_scene(), "/material/density"_json_pointer, -1), "material.density", "-1");
  expect_error(with(valid_scene(), "/penalty"_json_pointer, 0), "penalty", "0");
  expect_error(with(valid_scene(), "/material/thickness"_json_pointer, 1e31), "material.thickness", "1e+31",
               "number out of range");
}

// Below 1e-30 a stiffness E h^3 / 12 underflows (h = 1e-110: a zero pivot that read as
// "penalty too low?") or the displacement overflows (h = 1e-106: NaN in the mesh output).
TEST(SceneErrors, PositiveValuesBelowTheRangeAreRefused) {
  expect_error(with(valid_scene(), "/material/thickness"_json_pointer, 1e-110), "material.thickness", "1e-110",
               "too small");
  expect_error(with(valid_scene(), "/material/youngs_modulus"_json_pointer, 1e-300), "material.youngs_modulus",
               "1e-300", "from 1e-30 to 1e30");
  expect_error(with(valid_scene(), "/material/density"_json_pointer, 1e-31), "material.density", "1e-31",
               "0, or values from 1e-30");
  expect_error(with(valid_scene(), "/mesh/size/1"_json_pointer, 1e-40), "mesh.size[1]", "1e-40", "too small");
  expect_error(with(valid_scene(), "/penalty"_json_pointer, 5e-324), "penalty", "", "too small");
  EXPECT_EQ(error_of_text(with(valid_scene(), "/material/thickness"_json_pointer, 1e-30).dump()), "");
}

TEST(SceneErrors, ZeroDensityOnlyInStaticRuns) {
  EXPECT_EQ(error_of_text(with(valid_scene(), "/material/density"_json_pointer, 0).dump()), "");
  expect_error(with(dynamic_scene(), "/material/density"_json_pointer, 0), "material.density", "0",
               "dynamic analysis");
  json missing = dynamic_scene();
  missing["material"].erase("density");
  expect_error(missing, "material.density", "", "required in a dynamic analysis");
  // Gravity needs mass even in a static run.
  json gravity = with(valid_scene(), "/material/density"_json_pointer, 0);
  gravity["loads"].push_back({{"type", "gravity"}, {"acceleration", {0, 0, -9.81}}});
  expect_error(gravity, "material.density", "0", "loads[1] is gravity");
}

TEST(SceneErrors, MissingRequiredKeys) {
  expect_error(without(valid_scene(), "mesh"), "mesh", "", "missing required key");
  expect_error(without(valid_scene(), "material"), "material", "", "missing required key");
  json s = valid_scene();
  s["material"].erase("thickness");
  expect_error(s, "material.thickness", "", "missing required key");
  json d = dynamic_scene();
  d["analysis"].erase("steps");
  expect_error(d, "analysis.steps", "", "missing required key");
  const std::string message = error_of_text(without(valid_scene(), "mesh").dump());
  EXPECT_EQ(message.find(", got"), std::string::npos) << message;
}

TEST(SceneErrors, BadEnumerationValues) {
  expect_error(with(valid_scene(), "/mesh/element"_json_pointer, "quad9"), "mesh.element", "\"quad9\"",
               "\"quad8\", \"tri6\"");
  expect_error(with(valid_scene(), "/mesh/generator"_json_pointer, "disc"), "mesh.generator", "\"disc\"");
  expect_error(with(valid_scene(), "/analysis/type"_json_pointer, "quasi-static"), "analysis.type", "\"quasi-static\"");
  expect_error(with(valid_scene(), "/loads/0/type"_json_pointer, "pressure"), "loads[0].type", "\"pressure\"");
  expect_error(with(valid_scene(), "/boundary/0/fix/1"_json_pointer, "w"), "boundary[0].fix[1]", "\"w\"");
  expect_error(with(valid_scene(), "/boundary/0/fix/1"_json_pointer, "x"), "boundary[0].fix[1]", "\"x\"",
               "listed twice");
  expect_error(with(valid_scene(), "/enrichment"_json_pointer, {{"solver", "jacobi"}}), "enrichment.solver", "\"jacobi\"");
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"shading", "phong"}}), "render.shading", "\"phong\"");
}

TEST(SceneErrors, MeshParameters) {
  expect_error(with(valid_scene(), "/mesh/divisions/1"_json_pointer, 0), "mesh.divisions[1]", "0", "1..100000");
  expect_error(with(valid_scene(), "/mesh/size/0"_json_pointer, -1), "mesh.size[0]", "-1");
  const json cylinder = {{"generator", "cylinder"}, {"radius", 1}, {"length", 2}, {"angle_deg", {0, 400}},
                         {"divisions", {8, 2}}};
  expect_error(with(valid_scene(), "/mesh"_json_pointer, cylinder), "mesh.angle_deg", "[0,400]", "at most 360");
  expect_error(with(with(valid_scene(), "/mesh"_json_pointer, cylinder), "/mesh/angle_deg"_json_pointer, {30, 30}),
               "mesh.angle_deg", "[30,30]", "non-empty");
  expect_error(with(with(valid_scene(), "/mesh"_json_pointer, cylinder), "/mesh/size"_json_pointer, {1, 1}), "mesh.size",
               "[1,1]", "unknown key");
  // A closed ring needs 3 divisions, as its generator does (the reader said 2 and let 2 through
  // to the generator's own refusal).
  json ring = cylinder;
  ring["angle_deg"] = {0, 360};
  ring["divisions"] = {2, 1};
  expect_error(with(valid_scene(), "/mesh"_json_pointer, ring), "mesh.divisions[0]", "2",
               "a closed 360-degree ring needs at least 3 divisions");
  const json dome = {{"generator", "hemisphere"}, {"radius", 1}, {"hole_deg", 90}, {"divisions", {2, 8}}};
  expect_error(with(valid_scene(), "/mesh"_json_pointer, dome), "mesh.hole_deg", "90", "0 < hole_deg < 90");
  expect_error(with(with(valid_scene(), "/mesh"_json_pointer, dome), "/mesh/hole_deg"_json_pointer, 0), "mesh.hole_deg",
               "0");
  expect_error(with(valid_scene(), "/mesh"_json_pointer, {{"size", {1, 1}}, {"divisions", {1, 1}}}), "mesh",
               "", "needs \"generator\" or \"file\"");
  expect_error(with(valid_scene(), "/mesh"_json_pointer, {{"file", "nowhere.obj"}}), "mesh.file", "\"nowhere.obj\"",
               "no such file");
  expect_error(with(valid_scene(), "/mesh/file"_json_pointer, "x.obj"), "mesh.file", "\"x.obj\"", "exclude each other");
  // The tri6 split: only on tri6, one of two words.
  expect_error(with(valid_scene(), "/mesh/triangles"_json_pointer, "square"), "mesh.triangles", "\"square\"",
               "only tri6 cells");
  const json tri6 = with(valid_scene(), "/mesh/element"_json_pointer, "tri6");
  expect_error(with(tri6, "/mesh/triangles"_json_pointer, "diagonal"), "mesh.triangles", "\"diagonal\"",
               "\"sheared\", \"square\"");
}

TEST(SceneErrors, BoundarySelections) {
  expect_error(with(valid_scene(), "/boundary/0/select/plane/normal"_json_pointer, {0, 0, 0}),
               "boundary[0].select.plane.normal", "[0,0,0]", "zero normal");
  json box = valid_scene();
  box["boundary"][0]["select"] = {{"box", {{"min", {0, 0, 0}}, {"max", {1, -1, 1}}}}};
  expect_error(box, "boundary[0].select.box.max[1]", "-1", "min <= max");
  json both = valid_scene();
  both["boundary"][0]["select"]["box"] = {{"min", {0, 0, 0}}, {"max", {1, 1, 1}}};
  expect_error(both, "boundary[0].select.box", "", "exclude each other");
  expect_error(with(valid_scene(), "/boundary/0/select/tolerance"_json_pointer, -1e-6), "boundary[0].select.tolerance",
               "-1e-06");
  json nothing = valid_scene();
  nothing["boundary"][0]["fix"] = json::array();
  nothing["boundary"][0]["clamp"] = false;
  expect_error(nothing, "boundary[0].fix", "[]", "holds nothing");
}

TEST(SceneErrors, AnalysisValues) {
  expect_error(with(valid_scene(), "/analysis/time_step"_json_pointer, 0.1), "analysis.time_step", "0.1",
               "only allowed when analysis.type is \"dynamic\"");
  expect_error(with(dynamic_scene(), "/analysis/time_step"_json_pointer, 0), "analysis.time_step", "0");
  expect_error(with(dynamic_scene(), "/analysis/steps"_json_pointer, 0), "analysis.steps", "0");
  expect_error(with(dynamic_scene(), "/analysis/damping"_json_pointer, {{"mass", -0.1}}), "analysis.damping.mass",
               "-0.1");
  expect_error(with(dynamic_scene(), "/analysis/damping"_json_pointer, {{"alpha", 0.1}}), "analysis.damping.alpha",
               "0.1");
}

TEST(SceneErrors, ZeroLengthCuts) {
  expect_error(with(valid_scene(), "/cuts/0/points"_json_pointer, {{0.5, 0.5, 0}, {0.5, 0.5, 0}}), "cuts[0].points",
               "[[0.5,0.5,0],[0.5,0.5,0]]", "zero-length cut");
  expect_error(with(valid_scene(), "/cuts/0/points"_json_pointer, {{0.5, 0.5, 0}}), "cuts[0].points", "[[0.5,0.5,0]]",
               "at least 2 points");
  expect_error(with(valid_scene(), "/cuts/0/points"_json_pointer, {{0.1, 0.5, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 0}}),
               "cuts[0].points[2]", "[0.5,0.5,0]", "zero-length segment");
  const json same = {{"element", 2}, {"xi", {0.1, 0.2}}};
  expect_error(with(valid_scene(), "/cuts/0"_json_pointer, {{"surface_points", {same, same}}}), "cuts[0].surface_points",
               "", "zero-length cut");
}

TEST(SceneErrors, CutScheduleAndSurfacePoints) {
  expect_error(with(dynamic_scene(), "/cuts/0/speed"_json_pointer, 0), "cuts[0].speed", "0", "> 0");
  expect_error(with(dynamic_scene(), "/cuts/0/start_time"_json_pointer, -1), "cuts[0].start_time", "-1");
  expect_error(with(valid_scene(), "/cuts/0/speed"_json_pointer, 1), "cuts[0].speed", "1",
               "progressive cut needs a dynamic analysis");
  EXPECT_EQ(error_of_text(with(dynamic_scene(), "/cuts/0/speed"_json_pointer, 1).dump()), "");
  const json a = {{"element", 2}, {"xi", {0.1, 0.2}}};
  const json outside = {{"element", 2}, {"xi", {0.8, 0.4}}};
  json tri = with(valid_scene(), "/mesh/element"_json_pointer, "tri6");
  expect_error(with(tri, "/cuts/0"_json_pointer, {{"surface_points", {a, outside}}}), "cuts[0].surface_points[1].xi",
               "[0.8,0.4]", "tri6");
  // 4 x 4 quad8 cells: elements 0..15.
  const json far = {{"element", 16}, {"xi", {0.1, 0.2}}};
  expect_error(with(valid_scene(), "/cuts/0"_json_pointer, {{"surface_points", {a, far}}}),
               "cuts[0].surface_points[1].element", "16", "0..15");
  expect_error(with(valid_scene(), "/cuts/0"_json_pointer, {{"surface_points", {a, {{"element", -1}, {"xi", {0, 0}}}}}}),
               "cuts[0].surface_points[1].element", "-1");
}

TEST(SceneErrors, EnrichmentTextureResolution) {
  expect_error(with(valid_scene(), "/enrichment"_json_pointer, {{"texture_resolution", 100}}),
               "enrichment.texture_resolution", "100", "power of two");
  expect_error(with(valid_scene(), "/enrichment"_json_pointer, {{"texture_resolution", 8192}}),
               "enrichment.texture_resolution", "8192", "8..4096");
  expect_error(with(valid_scene(), "/enrichment"_json_pointer, {{"texture_resolution", 4}}),
               "enrichment.texture_resolution", "4");
  expect_error(with(valid_scene(), "/enrichment"_json_pointer, {{"new_cut_length", 0}}), "enrichment.new_cut_length", "0");
  expect_error(with(valid_scene(), "/enrichment"_json_pointer, {{"rotation_cluster_texels", -1}}),
               "enrichment.rotation_cluster_texels", "-1", "0..4096");
  expect_error(with(valid_scene(), "/enrichment"_json_pointer, {{"rotation_cluster_texels", 2.5}}),
               "enrichment.rotation_cluster_texels", "2.5");
  for (int r : {8, 16, 1024, 4096})
    EXPECT_EQ(error_of_text(with(valid_scene(), "/enrichment"_json_pointer, {{"texture_resolution", r}}).dump()), "");
}

TEST(SceneErrors, RenderValues) {
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"width", 0}}), "render.width", "0", "1..8192");
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"height", 8193}}), "render.height", "8193");
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"every_steps", 0}}), "render.every_steps", "0");
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"background", {0, 1.5, 0}}}), "render.background[1]", "1.5",
               "[0, 1]");
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"camera", {{"fov_deg", 180}}}}), "render.camera.fov_deg",
               "180");
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"camera", {{"up", {0, 0, 0}}}}}), "render.camera.up",
               "[0,0,0]");
  const json looking_down = {{"position", {0, 0, 5}}, {"target", {0, 0, 0}}, {"up", {0, 0, 1}}};
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"camera", looking_down}}), "render.camera.up", "[0,0,1]",
               "parallel");
  // The default up of a camera looking straight down is the renderer's to replace (as with
  // a target left to the mesh's centre): not refused.
  const json down_default_up = {{"position", {0, 0, 5}}, {"target", {0, 0, 0}}};
  EXPECT_EQ(error_of_text(with(valid_scene(), "/render"_json_pointer, {{"camera", down_default_up}}).dump()), "");
  const json blind = {{"position", {1, 1, 1}}, {"target", {1, 1, 1}}};
  expect_error(with(valid_scene(), "/render"_json_pointer, {{"camera", blind}}), "render.camera.target", "[1,1,1]");
}

TEST(SceneErrors, ProbesAndOutput) {
  json twice = valid_scene();
  twice["probes"].push_back({{"name", "center"}, {"position", {0, 0, 0}}});
  expect_error(twice, "probes[1].name", "\"center\"", "probes[0] already uses it");
  expect_error(with(valid_scene(), "/probes/0/name"_json_pointer, ""), "probes[0].name", "\"\"", "non-empty");
  expect_error(with(valid_scene(), "/output"_json_pointer, {{"report", "../escape.json"}}), "output.report",
               "\"../escape.json\"", "plain file name");
  // A name no Linux file system takes would fail only when the report is written, after the run.
  expect_error(with(valid_scene(), "/output"_json_pointer, {{"report", std::string(256, 'r') + ".json"}}),
               "output.report", "", "a file name of 261 bytes");
  EXPECT_EQ(error_of_text(with(valid_scene(), "/output"_json_pointer, {{"report", std::string(250, 'r') + ".json"}}).dump()),
            "");
}

TEST(SceneErrors, FilesThatAreFoldersOrDevices) {
  // They exist, so "no such file" would mislead.
  expect_error(with(valid_scene(), "/mesh"_json_pointer, {{"file", "/dev/null"}}), "mesh.file", "\"/dev/null\"",
               "not a regular file (resolved to /dev/null)");
  expect_error(with(valid_scene(), "/mesh"_json_pointer, {{"file", "/"}}), "mesh.file", "\"/\"", "not a regular file");
  expect_error(with(valid_scene(), "/mesh"_json_pointer, {{"file", "/nonexistent/m.obj"}}), "mesh.file", "",
               "no such file (resolved to /nonexistent/m.obj)");
}

TEST(SceneErrors, MalformedJsonReportsLineAndColumn) {
  // The stray comma is on line 3, column 15 (1-based).
  const std::string text = "{\n  \"mesh\": {},\n  \"material\": ,\n}";
  const std::string message = error_of_text(text);
  EXPECT_EQ(message.rfind("bad.json:3:15: invalid JSON: ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_EQ(error_of_text("{\"a\": NaN}").rfind("bad.json:1:", 0), 0u);
  EXPECT_NE(error_of_text("{\"a\": NaN}").find("invalid JSON"), std::string::npos);
  EXPECT_NE(error_of_text("// comment\n{}").find("invalid JSON"), std::string::npos);
  EXPECT_NE(error_of_text("{\"mesh\": {},}").find("invalid JSON"), std::string::npos);
  EXPECT_NE(error_of_text("").find("invalid JSON"), std::string::npos);
  // UTF-16, with or without its byte order mark, read as "1:2: unexpected end of input".
  for (const std::string& utf16 : {std::string("\xff\xfe{\0}\0", 6), std::string("{\0}\0", 4)})
    EXPECT_NE(error_of_text(utf16).find("the file is UTF-16 text (or binary); JSON scene files are UTF-8"),
              std::string::npos)
        << error_of_text(utf16);
  EXPECT_NE(error_of_text("{\"penalty\": 1e400}").find("number overflow"), std::string::npos);
  // nlohmann reports no position for an overflowing number; the literal's first place is it.
  EXPECT_EQ(error_of_text("{\n  \"mesh\": {},\n  \"penalty\": -1e400}").rfind("bad.json:3:14: invalid JSON: number overflow", 0),
            0u)
      << error_of_text("{\n  \"mesh\": {},\n  \"penalty\": -1e400}");
}

TEST(SceneErrors, NestingDeeperThanAnySceneIsRefusedWhileParsing) {
  // 100,000 levels took gigabytes of paths and overflowed the stack printing the value.
  for (const int depth : {33, 100000}) {
    const std::string text =
        "{\"material\": {\"thickness\": " + std::string(depth, '[') + std::string(depth, ']') + "}}";
    const std::string message = error_of_text(text);
    EXPECT_EQ(message.rfind("bad.json: material.thickness[0][0]", 0), 0u) << message.substr(0, 200);
    EXPECT_NE(message.find(": nested too deeply; expected at most 32 levels of objects and arrays"), std::string::npos)
        << message.substr(0, 200);
  }
  // 32 levels are read (and refused for their type, not their depth).
  const std::string deep32 = "{\"material\": {\"thickness\": " + std::string(30, '[') + std::string(30, ']') + "}}";
  EXPECT_EQ(error_of_text(deep32).find("nested too deeply"), std::string::npos) << error_of_text(deep32);
}

// Two creases along one path give two identical functions: the stiffness was singular and
// the run ended with "penalty too low?".
TEST(SceneErrors, ACreaseListedTwiceIsRefused) {
  json twice = valid_scene();
  twice["creases"] = {{{"points", {{0.5, 0, 0}, {0.5, 1, 0}}}}, {{"points", {{0.2, 0, 0}, {0.2, 1, 0}}}},
                      {{"points", {{0.5, 1, 0}, {0.5, 0, 0}}}}};
  expect_error(twice, "creases[2]", "{\"points\":[[0.5,1,0],[0.5,0,0]]}", "the same path as creases[0]");
  json surface = valid_scene();
  const json crease = {{"surface_points", {{{"element", 0}, {"xi", {0, -1}}}, {{"element", 0}, {"xi", {0, 1}}}}}};
  surface["creases"] = {crease, crease};
  expect_error(surface, "creases[1]", "", "the same path as creases[0]");
  json different = valid_scene();
  different["creases"] = {{{"points", {{0.5, 0, 0}, {0.5, 1, 0}}}}, {{"points", {{0.5, 0, 0}, {0.5, 0.9, 0}}}}};
  EXPECT_EQ(error_of_text(different.dump()), "");
}

TEST(SceneErrors, NulCharactersInKeysAndStrings) {
  // A NUL would end the file name at it (output.report "x.json\0y" wrote x.json) or cut the
  // message short.
  const std::string key = error_of_text(std::string("{\"mesh\": {}, \"pen\\u0000alty\": 1}"));
  EXPECT_EQ(key, "bad.json: pen\\u0000alty: a key with a NUL character; expected a key without NUL characters");
  expect_error(with(valid_scene(), "/output"_json_pointer, {{"report", std::string("x.json\0y", 8)}}), "output.report",
               "\"x.json\\u0000y\"", "a string with a NUL character");
}

TEST(SceneErrors, DuplicateKeysAreRejected) {
  const std::string text = R"({"mesh": {}, "material": {"density": 1, "density": 2}})";
  const std::string message = error_of_text(text);
  EXPECT_EQ(message.rfind("bad.json: material.density: duplicate key", 0), 0u) << message;
  const std::string nested = R"({"boundary": [{}, {"select": {"tolerance": 1, "tolerance": 2}}]})";
  EXPECT_EQ(error_of_text(nested).rfind("bad.json: boundary[1].select.tolerance: duplicate key", 0), 0u)
      << error_of_text(nested);
}

TEST(SceneErrors, MessagesAreSingleLineEvenForOddValues) {
  json s = valid_scene();
  s["material"]["note\nwith newline"] = "line1\nline2";
  const std::string message = error_of_text(s.dump());
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find("unknown key"), std::string::npos);
  // Long values are shortened to keep the line readable.
  json long_value = valid_scene();
  long_value["extra"] = std::string(500, 'a');
  EXPECT_LT(error_of_text(long_value.dump()).size(), 400u);
}

TEST(SceneErrors, MissingSceneFile) {
  try {
    dgtex::load_scene("/nonexistent/scene.json");
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/scene.json: cannot read the scene file: no such file");
  }
  // A loop of symbolic links read as "no such file" (fuzzing, session 71): the system's reason.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("dgtex_link_loop_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::create_symlink(dir / "b.json", dir / "a.json");
  std::filesystem::create_symlink(dir / "a.json", dir / "b.json");
  try {
    dgtex::load_scene((dir / "a.json").string());
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read the scene file: Too many levels of symbolic links"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace

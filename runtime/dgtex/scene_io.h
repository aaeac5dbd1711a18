#pragma once
// Reading a scene file (JSON, version 1, format in README.md's "Scene file reference")
// into a validated Scene. Validation is strict so that typos never pass silently:
// unknown keys, duplicate keys, wrong types, missing required keys, non-integers where an
// integer is needed, out-of-range values and inconsistent combinations (zero density in a
// dynamic run, a progressive cut in a static run, ...) all throw SceneError.
//
// Checks that need the mesh (empty boundary selections, statically unconstrained models,
// surface points outside the mesh) live in scene_mesh_checks.h.
// Thread-safe, but not pure: load_scene reads the file, and parse_scene and validate_scene
// check that mesh.file and the material textures' images exist and are regular files
// (validate_scene resolves relative paths against the working folder).
#include <stdexcept>
#include <string>

#include "dgtex/scene.h"

namespace dgtex {

// A problem with a scene file. what() is always exactly one line:
//   <file>: <json.path[0].like.this>: <problem>, got <value>; <what would be valid>
// (", got <value>" is left out when there is no value, e.g. a missing key). JSON syntax
// errors read  <file>:<line>:<column>: invalid JSON: <problem>.
class SceneError : public std::runtime_error {
 public:
  // got: the offending value as JSON text (empty: none); valid: what would be accepted.
  SceneError(const std::string& source_name, const std::string& json_path, const std::string& problem,
             const std::string& got, const std::string& valid);
  // For errors that have no JSON path (unreadable file, syntax errors); message as given.
  SceneError(const std::string& source_name, const std::string& message);

  const std::string& json_path() const { return json_path_; }

 private:
  std::string json_path_;
};

// The scene file format this dgtex reads and writes: a file's optional top-level
// "version" must equal it (a file of a later format is refused naming both versions,
// before its keys are checked); scene_to_json_text writes it.
constexpr int scene_format_version = 1;

// Reads and validates the scene file at path. Relative paths inside it (mesh.file)
// resolve against the scene file's folder.
Scene load_scene(const std::string& path);

// Validates json_text. source_name is used in messages and its parent folder (if any)
// resolves relative paths, so parse_scene(text, "dir/scene.json") behaves like
// load_scene("dir/scene.json").
Scene parse_scene(const std::string& json_text, const std::string& source_name);

// Checks a Scene built in code as parse_scene checks a file, and throws the SceneError that
// the scene's canonical JSON (below) would give: the JSON path names the field
// (material.poisson_ratio, cuts[0].speed, ...) and the message the value; NaN and infinity
// are refused like numbers beyond 1e30. Paths (mesh.file, material_textures[i].image) are
// taken as they stand: a parsed scene's are resolved already, and one built in code gives
// them relative to the working folder. build_scene_mesh, build_scene_model and SceneRun
// call it, so a Scene never reaches the simulation unchecked.
void validate_scene(const Scene& scene);

// The scene as canonical JSON text (every key written, defaults included), which
// parse_scene reads back into an equal Scene. Used to echo the effective scene.
std::string scene_to_json_text(const Scene& scene);

}  // namespace dgtex

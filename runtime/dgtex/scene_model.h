#pragma once
// Builds the simulation inputs a scene describes: the mesh (generator or OBJ), the shell
// model (sections, clamped edges, penalty), fixed DOFs and the external load vector.
#include <memory>
#include <vector>

#include "dgtex/mesh.h"
#include "dgtex/scene.h"
#include "dgtex/shell_model.h"

namespace dgtex {

struct SceneModel {
  std::unique_ptr<ShellModel> model;
  std::vector<char> fixed;             // #dofs
  std::vector<double> external_force;  // #dofs
};

// Throws MeshError (mesh problems) or SceneError (scene/mesh mismatches).
Mesh build_scene_mesh(const Scene& scene);
SceneModel build_scene_model(const Scene& scene, const Mesh& mesh);

}  // namespace dgtex

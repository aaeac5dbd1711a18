#pragma once
// Builds the simulation inputs a scene describes: the mesh (generator or OBJ), the shell
// model (sections, clamped edges, penalty), fixed DOFs and the external load vector.
// Functions that return owning values (SceneModel owns its ShellModel through unique_ptr;
// nothing refers back to the scene). Units: those of the scene (SI: m, kg, s, N).
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

// Both check the scene first (validate_scene). Throw SceneError (a bad scene, or a scene
// that does not fit the mesh) or MeshError (mesh problems).
Mesh build_scene_mesh(const Scene& scene);
SceneModel build_scene_model(const Scene& scene, const Mesh& mesh);

// The scene's held DOFs for a model (#dofs); like the two above, it and
// scene_external_force check the scene first (validate_scene). Supports act on the
// standard DOFs of the selected nodes only: the shifted enrichment vanishes at every node
// (thesis §5.3), so a held node stays put, while its enriched DOFs stay free to move what
// a cut separates from it (a chad cut out of an element whose nodes are all held still
// falls out).
std::vector<char> scene_fixed_dofs(const Scene& scene, const ShellModel& model);
// The scene's loads on a model's basis (#dofs, enriched functions included).
std::vector<double> scene_external_force(const Scene& scene, const ShellModel& model);

}  // namespace dgtex

#pragma once
// Internal: scene_fixed_dofs and scene_external_force without their validate_scene, for
// callers that hold a scene validated already (build_scene_model, SceneRun at each basis
// change, where a JSON round trip of the scene each time would cost the step).
#include <vector>

#include "dgtex/scene.h"
#include "dgtex/shell_model.h"

namespace dgtex::detail {

std::vector<char> fixed_dofs_of_valid_scene(const Scene& scene, const ShellModel& model);
std::vector<double> external_force_of_valid_scene(const Scene& scene, const ShellModel& model);

}  // namespace dgtex::detail

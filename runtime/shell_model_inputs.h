#pragma once
// What ShellModel's constructor checks before it reads its inputs, so that a program
// linking dgtex with a mesh, topology or sections of its own gets an error naming the
// value instead of reading out of bounds or assembling NaN.
#include <vector>

#include "dgtex/kernels/shell_element_kernel.h"
#include "dgtex/mesh.h"
#include "dgtex/shell_model.h"
#include "dgtex/topology.h"

namespace dgtex::detail {

// Throws MeshError for a mesh validate_mesh refuses, and std::invalid_argument
// "<who>: the topology was not built from this mesh: ..." for a topology that is not
// build_topology(mesh)'s (ShellModel, CutManager).
void check_mesh_and_topology(const char* who, const Mesh& mesh, const Topology& topology);

// Throws MeshError for a mesh validate_mesh refuses, and std::invalid_argument for a
// topology not built from this mesh, a section that is not a material (E, h > 0,
// -1 < nu < 0.5, density >= 0, all finite), a clamped edge out of range or listed twice, or options out
// of their ranges (penalty > 0, 1..5 edge points, mass ratio in [0, 1), cluster texels
// >= 0, merge tolerance > 0).
void check_shell_model_inputs(const Mesh& mesh, const Topology& topology,
                              const std::vector<kernels::ShellSection>& sections, const std::vector<int>& clamped_edges,
                              const ShellModelOptions& options);

}  // namespace dgtex::detail

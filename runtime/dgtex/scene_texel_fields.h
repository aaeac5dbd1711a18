#pragma once
// The texel fields a scene's cuts and creases will hold (dgtex/texel_memory_estimate.h),
// from its mesh and traced paths, before any field exists: what SceneRun checks against
// the memory available, and what `dgtex run` reports before a long set-up.
#include "dgtex/cut_manager.h"
#include "dgtex/mesh.h"
#include "dgtex/scene.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"

namespace dgtex {

// cuts: the scene's cut manager (nullptr for a scene without cuts). Throws
// std::invalid_argument for a crease the mesh cannot take (crease_footprint).
TexelFields scene_texel_fields(const Scene& scene, const Mesh& mesh, const Topology& topology, const CutManager* cuts);

// The same, building the mesh and tracing the cuts itself (a scene without cuts and creases
// returns at once). Throws what build_scene_mesh and CutManager's constructor throw.
TexelFields scene_texel_fields(const Scene& scene);

}  // namespace dgtex

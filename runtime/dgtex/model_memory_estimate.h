#pragma once
// Will a scene's shell model fit in memory? Its system matrix and the Cholesky factor of it
// grow with the element count, a little faster than linearly (the factor's fill): a
// rectangle of 400 x 400 quad8 elements outgrew a 23 GB machine and the system killed the
// run minutes in, and a typo such as divisions [100000, 100] (within the scene file's 1e7
// cells) would do so after building a mesh of 10 million elements. The scene's mesh is
// checked against a lower bound of that memory before it is built (a file's from its
// counted faces, before it is parsed), and refused with one line (a SceneError naming
// mesh.divisions or mesh.file, the bound, the memory available and the most elements that
// could fit).
//
// The bound per element, from the peak resident memory of examples/scenes/clamped_plate.json
// at divisions n x n (n = 50, 100, 200; static, and dynamic with two corotated steps), less
// the process's ~42 MB before the scene (2-core machine, session 67):
//  - quad8: 123-148 KB static, 143-181 KB dynamic, growing with n; bound 96 KiB;
//  - tri6 (two triangles a cell): 56-68 KB; bound 40 KiB.
// Cuts, creases and material textures need more (their own checks: texel_memory_estimate.h,
// material_texture.h). Pure functions but available_memory_bytes (texel_memory_estimate.h).
#include <cstdint>
#include <string>

#include "dgtex/mesh.h"
#include "dgtex/scene.h"

namespace dgtex {

inline constexpr std::int64_t kQuad8ModelBytesPerElement = 96 * 1024;
inline constexpr std::int64_t kTri6ModelBytesPerElement = 40 * 1024;

// Lower bound of the peak memory of a model of `elements` elements of `type`, in bytes.
std::int64_t model_memory_lower_bound(ElementType type, std::int64_t elements);

// The element type and count of a scene's mesh before it is built: a generator's from its
// divisions, a file's from its faces as load_obj will read them (count_obj_faces, a line
// scan); elements -1 where there is none (a file whose first face is neither a triangle nor
// a quad, which the reader refuses). For the check and the caution below.
struct SceneMeshSize {
  ElementType type = ElementType::quad8;
  std::int64_t elements = -1;
};
SceneMeshSize scene_mesh_size(const Scene& scene);

// Throws SceneError(scene.source_name, "mesh.divisions" (generators) or "mesh.file", ...)
// when the lower bound for `elements` elements exceeds available_bytes, naming both and the
// most elements whose bound fits. available_bytes < 0: no check.
void check_model_memory(const Scene& scene, ElementType type, std::int64_t elements, std::int64_t available_bytes);

// A caution for a mesh that passes the check but comes near the limit: runs measured
// 1.2-1.9x the bound, and 400 x 400 quad8 elements (a 14.6 GiB bound) outgrew 23 GB. One
// sentence naming the bound, the memory and the remedy, for `dgtex run` to print before its
// set-up, when the bound lies between half the memory available and all of it; else "" (also
// with available_bytes < 0). A mesh file's faces are counted (count_obj_faces) for it.
std::string model_memory_caution(const Scene& scene, std::int64_t available_bytes);

}  // namespace dgtex

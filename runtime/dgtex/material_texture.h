#pragma once
// Material textures (thesis §5.6, Fig. 5.20): Young's modulus and thickness per texel on
// chosen elements, from grayscale/RGB images of the scene ("material_textures").
// Texture layout per element: kernels/material_texture_kernel.h (the image covers the
// element's parameter square, row 0 at xi2 = +1; nearest-texel values).
// Functions that read the scene's images and return value types, or check them (nothing
// kept; thread-safe). Young's modulus in Pa, thickness in m (the scene's consistent units).
#include <cstdint>
#include <string>
#include <vector>

#include "dgtex/element_material_texture.h"
#include "dgtex/mesh.h"
#include "dgtex/scene.h"

namespace dgtex {

// Reads the scene's images and combines them per element: fields without a texture keep
// the scene material's value; gray = (R + G + B) / (3 * 255) for RGB, the value for
// grayscale; value = min + (max - min) * gray. Throws SceneError (scene_io.h) naming the JSON
// path (material_textures[i]...) for an unreadable image, an element out of range, or two
// textures of one element with different image sizes. Sorted by element; empty without
// material textures.
// Also throws SceneError at material_textures when the elements' texel arrays
// (kMaterialBytesPerTexel each) would pass the memory available (available_memory_bytes(),
// texel_memory_estimate.h), before they are allocated.
std::vector<ElementMaterialTexture> scene_material_textures(const Scene& scene, const Mesh& mesh);
// The same against available_bytes (< 0: no memory check).
std::vector<ElementMaterialTexture> scene_material_textures(const Scene& scene, const Mesh& mesh,
                                                            std::int64_t available_bytes);

// Bytes a texel of an element's texture takes (E and h, ElementMaterialTexture).
inline constexpr std::int64_t kMaterialBytesPerTexel = 2 * sizeof(double);

// Bytes a quadrature point of a textured element takes in the model: its (xi1, xi2, weight)
// and its section (material_texture_kernel.h). A whole static run measures the same: a
// 2 x 2 plate with 512 x 512 texels an element, all different (4.2 M points), peaks at
// 292 MB, with uniform textures of that size (36 points) at 63 MB: 56.0 bytes a point. A
// corotated run keeps no more (its rotations are formed point by point, session 42).
inline constexpr std::int64_t kMaterialBytesPerPoint = 56;

// The memory the model's quadrature of these textures takes: kMaterialBytesPerPoint times
// their points (kernels::material_texture_point_count: 9 or 4 per cell of equal texels; one
// cell for a uniform texture, one a texel where neighbouring texels all differ).
std::int64_t material_texture_quadrature_bytes(const std::vector<ElementMaterialTexture>& textures);

// Throws SceneError(source_name, "material_textures", ...) when that memory exceeds
// available_bytes (available_memory_bytes(), texel_memory_estimate.h), naming the elements,
// points, bytes and the remedy; available_bytes < 0: no check. A 2048 x 2048 texture of
// distinct texels on 4 elements needs 3.8 GB: refused on a smaller machine before the model
// allocates it instead of the system killing the run.
void check_material_texture_memory(const std::vector<ElementMaterialTexture>& textures, std::int64_t available_bytes,
                                   const std::string& source_name);

}  // namespace dgtex

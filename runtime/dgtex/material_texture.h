#pragma once
// Material textures (thesis §5.6, Fig. 5.20): Young's modulus and thickness per texel on
// chosen elements, from grayscale/RGB images of the scene ("material_textures").
// Texture layout per element: kernels/material_texture_kernel.h (the image covers the
// element's parameter square, row 0 at xi2 = +1; nearest-texel values).
// Functions that read the scene's images and return value types (nothing kept;
// thread-safe). Young's modulus in Pa, thickness in m (the scene's consistent units).
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
std::vector<ElementMaterialTexture> scene_material_textures(const Scene& scene, const Mesh& mesh);

}  // namespace dgtex

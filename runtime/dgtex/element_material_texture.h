#pragma once
// Per-texel Young's modulus and thickness of one element (thesis §5.6), the input of
// ShellModel::set_material_textures. Layout as in kernels/material_texture_kernel.h:
// W x H texels covering the element's parameter square, row-major, rows top to bottom
// (row 0 at xi2 = +1), nearest-texel values.
// A value type that owns its texel arrays. Units: Young's modulus in Pa, thickness in m
// (consistent units in general).
#include <vector>

namespace dgtex {

struct ElementMaterialTexture {
  int element = 0;
  int width = 0;
  int height = 0;
  std::vector<double> youngs_modulus;  // #W*H, > 0
  std::vector<double> thickness;       // #W*H, > 0
};

}  // namespace dgtex

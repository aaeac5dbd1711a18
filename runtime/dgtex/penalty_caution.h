#pragma once
// Is a scene's interior-penalty factor so large that it stiffens the shell? Above the
// definiteness threshold (0.35-0.40, README "Choosing the penalty") the C1 penalty of the
// DG form locks quadratic elements, the more the coarser the mesh and far more for tri6
// than for quad8. Centre deflection of examples/scenes/clamped_plate.json against the same
// mesh at penalty 1 (dgtex run, session 68):
//  - quad8 8 x 8: 5 % less at 10, 13 % at 100, 26 % at 300, 51 % at 1000; 16 x 16: 0.1 %
//    at 10, 6 % at 1000; 32 x 32: under 0.3 % up to 1000;
//  - tri6 8 x 8: 8 % less at 2, 14 % at 3, 38 % at 10; 16 x 16: 16 % at 10; 32 x 32: 5 % at 10.
// Nothing fails, so `dgtex run` cautions instead of refusing. Pure function.
#include <string>

#include "dgtex/mesh.h"

namespace dgtex {

// Above these factors the 8 x 8 plate deflects more than 5 % (quad8) or 8 % (tri6) less
// than at penalty 1.
inline constexpr double kQuad8PenaltyCautionAbove = 10;
inline constexpr double kTri6PenaltyCautionAbove = 2;

// One sentence for `dgtex run` to print before the steps when `penalty` lies above the
// line of `type`, naming the penalty, the measured stiffening and the remedy; else "".
std::string penalty_caution(double penalty, ElementType type);

}  // namespace dgtex

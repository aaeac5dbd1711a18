#pragma once
// Has a linear (not corotated) solution turned the shell further than linear theory holds?
// A linear shell reads rotation as strain, so its result drifts from the corotated one as
// rotations grow. examples/scenes/demo_cantilever.json under gravity, static linear against
// corotated dynamics damped to rest (`dgtex run`, session 70), tip deflection of the linear
// result over the corotated one at the linear tip slope: 1.0015 at 0.048 rad, 1.006 at 0.095,
// 1.024 at 0.19, 1.088 at 0.38, 1.29 at 0.76. Nothing fails, so `dgtex run` cautions instead
// of refusing.
//
// Not caught: membrane stretching. Where the supports hold a shell in its plane, linear
// theory also drops the stretching that deflections of the order of the thickness cause
// while its slopes stay small (examples/scenes/clamped_plate.json, 1.4 thicknesses: the
// linear centre deflection 1.47x the corotated one at slopes ~0.05). Pure functions.
#include <string>

#include "dgtex/mesh.h"

namespace dgtex {

// Above this the cantilever above is ~2.6 % off. The one-element example scenes
// thickness_texture (0.17) and crease (0.11) lie below it.
inline constexpr double kLinearRotationCautionAbove = 0.2;

// The largest |u_a - u_b| / |x_a - x_b| over two nodes a, b of one element: the rotation
// (in radians, for small ones) plus the strain along a - b, which bounds it.
struct LargestRotation {
  double value = 0;
  int element = -1;  // -1: no element moved
};
// `nodal_displacement`: #nodes x 3, finite (not checked: a NaN pair is skipped, so a
// non-finite result reads as no rotation; runs that diverge end before this is read).
LargestRotation largest_rotation(const Mesh& mesh, const double* nodal_displacement);

// One sentence for `dgtex run` to print after a linear analysis whose largest rotation
// (at `when`, e.g. "at step 40"; "" for statics) lies above the line, naming it, the element,
// the measured drift and the remedy; else "".
std::string linear_rotation_caution(const LargestRotation& largest, const std::string& when);

}  // namespace dgtex

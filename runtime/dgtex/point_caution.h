#pragma once
// Do the point loads and probes lie on the shell? Each acts at (or reads) the surface point
// nearest to where it is given, however far that is: a point load at [100, 100, 100] on a
// unit plate was applied at its corner without a word (session 72). Cut points farther than
// cut_point_tolerance (a quarter of the mean element edge) are refused, since a cut's
// shape depends on them; a load or probe a little off a curved shell is common, so
// `dgtex run` cautions instead, from the same distance on. Pure function.
#include <string>

#include "dgtex/mesh.h"
#include "dgtex/scene.h"

namespace dgtex {

// One sentence for `dgtex run` to print before the steps, naming the first point load or
// probe farther than cut_point_tolerance(mesh) from the surface, its distance, the point it
// acts at and how many more are that far; else "".
std::string far_point_caution(const Scene& scene, const Mesh& mesh);

}  // namespace dgtex

#pragma once
// A run's displacement at the surface point nearest to a position, as a scene's probe reads
// it (`dgtex run`'s report), enrichment included.
#include "dgtex/scene.h"
#include "dgtex/scene_run.h"
#include "dgtex/surface_point.h"

namespace dgtex::test {

inline Vec3 displacement_at(const SceneRun& run, const Vec3& position) {
  const SurfacePoint p = closest_surface_point(run.mesh(), position.data());
  Vec3 u;
  run.model().interpolate(run.displacement(), p.element, p.xi, u.data());
  return u;
}

}  // namespace dgtex::test

#pragma once
// Small builders shared by the cut tests: a cut from rest-configuration points, and
// enrichment options with a texture resolution and the reference (CHOLMOD) solver.
#include <utility>
#include <vector>

#include "dgtex/scene.h"

namespace dgtex::testing_support {

inline Cut points_cut(std::vector<Vec3> points) {
  Cut cut;
  cut.kind = Cut::Kind::points;
  cut.points = std::move(points);
  return cut;
}

inline EnrichmentOptions cholmod_enrichment(int resolution) {
  EnrichmentOptions o;
  o.texture_resolution = resolution;
  o.solver = EnrichmentOptions::Solver::cholmod;
  return o;
}

}  // namespace dgtex::testing_support

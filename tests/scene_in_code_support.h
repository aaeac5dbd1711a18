#pragma once
// A scene built in code, as a program linking dgtex builds one (dgtex/scene.h): a
// 0.4 m x 0.1 m strip of 4 x 1 quad8, clamped along x = 0, under gravity.
#include "dgtex/scene.h"

namespace dgtex::test {

// dynamic: 2 corotated steps of 5 ms (else static); with_cut: a cut from the lower edge
// 60 % across at x = 0.225 m, T = 32.
inline Scene strip_built_in_code(bool dynamic = true, bool with_cut = true) {
  Scene scene;
  scene.source_name = "strip (built in code)";
  scene.mesh.source = MeshSource::rectangle;
  scene.mesh.element = ElementType::quad8;
  scene.mesh.size = {0.4, 0.1};
  scene.mesh.divisions = {4, 1};
  scene.material = {5e8, 0.3, 0.01, 1000};  // E [Pa], nu, h [m], density [kg/m^3]
  BoundaryCondition clamp;
  clamp.select.normal = {1, 0, 0};
  clamp.fixed = {true, true, true};
  clamp.clamp = true;
  scene.boundary.push_back(clamp);
  Load gravity;
  gravity.acceleration = {0, 0, -9.81};
  scene.loads.push_back(gravity);
  if (dynamic) {
    scene.analysis.type = Analysis::Type::dynamic;
    scene.analysis.time_step = 0.005;
    scene.analysis.steps = 2;
    scene.analysis.corotational = true;
  }
  if (with_cut) {
    Cut cut;
    cut.points = {{0.225, 0, 0}, {0.225, 0.06, 0}};
    scene.cuts.push_back(cut);
    scene.enrichment.texture_resolution = 32;
  }
  return scene;
}

// A 1 m x 1 m plate of 2 x 2 elements (h = 1 cm, density 1000), clamped along x = 0, with
// cut textures of T = 16: no loads, no cuts, static.
inline Scene square_plate_built_in_code(ElementType element, double youngs_modulus) {
  Scene scene;
  scene.source_name = "square plate (built in code)";
  scene.mesh.source = MeshSource::rectangle;
  scene.mesh.element = element;
  scene.mesh.size = {1, 1};
  scene.mesh.divisions = {2, 2};
  scene.material = {youngs_modulus, 0.3, 0.01, 1000};
  BoundaryCondition clamp;
  clamp.select.normal = {1, 0, 0};
  clamp.fixed = {true, true, true};
  clamp.clamp = true;
  scene.boundary.push_back(clamp);
  scene.enrichment.texture_resolution = 16;
  return scene;
}

}  // namespace dgtex::test

// A cut plate through dgtex's public C++ API, built against an installed dgtex
// (find_package(dgtex) -> dgtex::dgtex). The scene is assembled in code, the same data a
// scene file would give (dgtex/scene.h, dgtex/scene_io.h):
//   a 0.4 m x 0.1 m plate, 10 mm thick, E = 500 MPa, nu = 0.3, 1000 kg/m^3, 8 x 2 quad8,
//   clamped along x = 0, under gravity, with a straight cut from the lower long edge
//   (y = 0) 60 % across the width at x = 0.225 m; dynamic, corotated, 20 steps of 5 ms.
// Prints the counts and the tip displacement (metres) and exits nonzero when a count is
// not the expected one or a displacement is not finite or points the wrong way.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <vector>

#include "dgtex/scene.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/surface_point.h"
#include "dgtex/version.h"

namespace {

constexpr int kDivisionsX = 8;
constexpr int kDivisionsY = 2;
constexpr int kSteps = 20;

dgtex::Scene cut_plate_scene() {
  dgtex::Scene scene;
  scene.source_name = "cut_plate (built in code)";
  scene.mesh.source = dgtex::MeshSource::rectangle;
  scene.mesh.element = dgtex::ElementType::quad8;
  scene.mesh.size = {0.4, 0.1};
  scene.mesh.divisions = {kDivisionsX, kDivisionsY};
  scene.material = {5e8, 0.3, 0.01, 1000};  // Pa, -, m, kg/m^3
  scene.penalty = 1;

  dgtex::BoundaryCondition clamp;
  clamp.select.kind = dgtex::BoundarySelect::Kind::plane;
  clamp.select.normal = {1, 0, 0};
  clamp.select.offset = 0;
  clamp.fixed = {true, true, true};
  clamp.clamp = true;
  scene.boundary.push_back(clamp);

  dgtex::Load gravity;
  gravity.type = dgtex::Load::Type::gravity;
  gravity.acceleration = {0, 0, -9.81};  // m/s^2
  scene.loads.push_back(gravity);

  scene.analysis.type = dgtex::Analysis::Type::dynamic;
  scene.analysis.time_step = 0.005;  // s
  scene.analysis.steps = kSteps;
  scene.analysis.corotational = true;
  scene.analysis.damping.mass = 2.0;  // 1/s

  dgtex::Cut cut;
  cut.kind = dgtex::Cut::Kind::points;
  cut.points = {{0.225, 0.0, 0}, {0.225, 0.06, 0}};
  scene.cuts.push_back(cut);
  scene.enrichment.texture_resolution = 32;
  return scene;
}

bool all_finite(const std::vector<double>& values) {
  for (double v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

int check(bool ok, const char* what) {
  if (!ok) std::fprintf(stderr, "cut_plate: FAILED: %s\n", what);
  return ok ? 0 : 1;
}

}  // namespace

int main() {
  try {
    // SceneRun checks the scene as a scene file is checked (dgtex::validate_scene): a bad
    // value throws dgtex::SceneError naming the field, e.g. "material.poisson_ratio".
    // It keeps a copy of the scene.
    dgtex::SceneRun run(cut_plate_scene());
    while (run.steps_taken() < kSteps) run.step();

    const dgtex::ShellModel& model = run.model();
    const double tip_position[3] = {0.4, 0.05, 0};
    const dgtex::SurfacePoint tip = dgtex::closest_surface_point(run.mesh(), tip_position);
    double tip_u[3];
    model.interpolate(run.displacement(), tip.element, tip.xi, tip_u);

    const int elements = run.mesh().num_elements();
    const int nodes = run.mesh().num_nodes();
    const int enrichments = static_cast<int>(model.enrichments().size());
    std::printf("elements %d, nodes %d, dofs %d (enriched %d), enrichments %d, steps %d, time %.3f s\n", elements,
                nodes, model.num_dofs(), model.num_enriched_dofs(), enrichments, run.steps_taken(), run.time());
    std::printf("tip displacement [m]: %.6e %.6e %.6e\n", tip_u[0], tip_u[1], tip_u[2]);

    // quad8 rectangle: (2 nx + 1)(2 ny + 1) grid points minus the nx ny cell centres.
    const int expected_nodes = (2 * kDivisionsX + 1) * (2 * kDivisionsY + 1) - kDivisionsX * kDivisionsY;
    int failures = 0;
    std::printf("dgtex %s (found at build time: %s)\n", dgtex::version(), DGTEX_FOUND_VERSION);
    failures += check(std::strcmp(dgtex::version(), DGTEX_FOUND_VERSION) == 0,
                      "the library loaded at run time is the version find_package found");
    failures += check(elements == kDivisionsX * kDivisionsY, "element count");
    failures += check(nodes == expected_nodes, "node count");
    failures += check(enrichments >= 1 && model.num_enriched_dofs() > 0, "the cut adds enrichment functions");
    failures += check(model.num_dofs() == 3 * nodes + model.num_enriched_dofs(), "dof count");
    failures += check(run.steps_taken() == kSteps, "steps taken");
    failures += check(static_cast<int>(run.displacement().size()) == model.num_dofs(), "displacement size");
    failures += check(all_finite(run.displacement()), "finite displacements");
    failures += check(std::isfinite(tip_u[0]) && std::isfinite(tip_u[1]) && std::isfinite(tip_u[2]),
                      "finite tip displacement");
    // Gravity pulls the free end down; it cannot fall further than free fall in 0.1 s.
    const double free_fall = 0.5 * 9.81 * run.time() * run.time();
    failures += check(tip_u[2] < 0 && tip_u[2] > -free_fall, "tip moves down, less than free fall");
    if (failures == 0) std::printf("cut_plate: OK\n");
    return failures == 0 ? 0 : 1;
  } catch (const dgtex::SceneError& e) {  // a bad value in the scene; what() names the field
    std::fprintf(stderr, "cut_plate: bad scene at %s: %s\n", e.json_path().c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cut_plate: %s\n", e.what());
    return 2;
  }
}

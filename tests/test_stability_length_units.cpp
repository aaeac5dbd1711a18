// The same scene in any length unit: a cut cantilever measured in nanometres, metres or
// gigametres (lengths x s, gravity / s, time step, damping and the selection's tolerance
// scaled so that the motion is similar) moves alike, u / s the same to round-off, for both
// element types, corotated, with its enrichment (README "Stability where methods fail").
// No tolerance inside the simulation is an absolute length; the one in the scene file,
// select.tolerance, is cautioned when it is a large part of the mesh (selection_caution.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"

namespace {

using namespace dgtex;

// examples/scenes/demo_cantilever.json on a 4 x 2 mesh, 20 steps, cut along its middle
// from x = 0.3 past the free end, every length times `s`.
std::string cut_cantilever(const char* element, double s) {
  const nlohmann::json scene = {
      {"mesh", {{"generator", "rectangle"}, {"size", {1.0 * s, 0.2 * s}}, {"divisions", {4, 2}}, {"element", element}}},
      {"material", {{"youngs_modulus", 5e8}, {"poisson_ratio", 0.3}, {"thickness", 0.01 * s}, {"density", 1000}}},
      {"penalty", 1},
      {"boundary",
       {{{"select", {{"plane", {{"normal", {1, 0, 0}}, {"offset", 0}}}, {"tolerance", 1e-6 * s}}},
         {"fix", {"x", "y", "z"}},
         {"clamp", true}}}},
      {"loads", {{{"type", "gravity"}, {"acceleration", {0, 0, -9.81 / s}}}}},
      {"analysis",
       {{"type", "dynamic"}, {"time_step", 0.005 * s}, {"steps", 20}, {"corotational", true},
        {"damping", {{"mass", 2.0 / s}, {"stiffness", 0.0}}}}},
      {"cuts", {{{"points", {{0.3 * s, 0.1 * s, 0.0}, {1.01 * s, 0.1 * s, 0.0}}}}}},
      {"enrichment", {{"texture_resolution", 32}}}};
  return scene.dump();
}

std::vector<double> final_displacement_over_scale(const char* element, double s) {
  SceneRun run(parse_scene(cut_cantilever(element, s), "cut_cantilever.json"));
  for (int step = 0; step < 20; ++step) run.step();
  std::vector<double> u = run.simulation().displacement();
  EXPECT_GT(u.size(), 3u * run.mesh().num_nodes()) << "no enriched unknowns: the cut is missing";
  for (double& x : u) x /= s;
  return u;
}

TEST(LengthUnits, ACutCantileverMovesAlikeFromNanometresToGigametres) {
  for (const char* element : {"quad8", "tri6"}) {
    const std::vector<double> metres = final_displacement_over_scale(element, 1.0);
    double largest = 0;
    for (double x : metres) largest = std::max(largest, std::abs(x));
    ASSERT_GT(largest, 0.01) << element;  // it moves: the tip sags ~0.2 m in these 20 steps
    for (double s : {1e-9, 1e9}) {
      const std::vector<double> scaled = final_displacement_over_scale(element, s);
      ASSERT_EQ(scaled.size(), metres.size()) << element << " at " << s;  // the same enrichment
      double difference = 0;
      for (size_t i = 0; i < metres.size(); ++i) difference = std::max(difference, std::abs(scaled[i] - metres[i]));
      std::printf("%s at lengths x %g: largest |u / s - u(metres)| / largest |u| = %.2e\n", element, s,
                  difference / largest);
      EXPECT_LT(difference / largest, 1e-9) << element << " at " << s;  // measured 1.2e-13 to 1.0e-12
    }
  }
}

}  // namespace

// A plate cut fully across, clamped on one side, under gravity (ShellSimulation::step,
// linear semi-implicit Euler): the free piece falls exactly like a free body, the clamped
// piece stays (its displacement is tiny next to the free piece's).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/shell_simulation.h"
#include "enrichment_test_support.h"
#include "shell_test_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

TEST(EnrichedDynamics, FreePieceFallsAtGravityClampedPieceStays) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_rectangle(1, 0.5, 4, 2, type);
    // quad8: across at x = 0.578; tri6: parallel to the cell diagonals (both on texel edges).
    const LevelFunction cut = type == ElementType::quad8 ? LevelFunction([](const double* x) { return x[0] - 0.578125; })
                                                         : LevelFunction([](const double* x) { return x[0] - x[1] - 0.578125; });
    testing_support::Material stiff;
    stiff.E = 1e11;
    stiff.h = 0.02;
    auto clamp = [](const double* x) { return x[0] < 1e-9; };
    auto model = make_model(mesh, stiff, 10.0, clamp);
    model->set_enrichments({straight_cut_enrichment(mesh, 16, cut)});
    std::vector<char> fixed;
    fix_nodes(mesh, clamp, true, true, true, fixed);
    fixed.resize(model->num_dofs(), 0);
    const double g = 9.81, gravity[3] = {0, 0, -g};
    std::vector<double> f(model->num_dofs(), 0.0);
    model->add_gravity(gravity, f);
    ShellSimulation sim(*model, fixed, f);
    DynamicsOptions options;
    options.time_step = 1e-3;
    const int steps = 50;
    // Total displacement (standard + enriched functions) at every node, through an element.
    std::vector<int> element_of(mesh.num_nodes(), -1), local_of(mesh.num_nodes(), -1);
    for (int e = 0; e < mesh.num_elements(); ++e)
      for (int a = 0; a < mesh.nodes_per_element(); ++a) element_of[mesh.element_nodes(e)[a]] = e, local_of[mesh.element_nodes(e)[a]] = a;
    auto total = [&](int n, double out[3]) {
      double xi[2];
      kernels::node_parametric_position(type, local_of[n], xi);
      model->interpolate(sim.displacement(), element_of[n], xi, out);
    };
    std::vector<double> previous(mesh.num_nodes(), 0.0), before(mesh.num_nodes(), 0.0);
    double worst_fall = 0, worst_acceleration = 0, clamped_max = 0, free_min = 1e300;
    for (int s = 1; s <= steps; ++s) {
      sim.step(options);
      // Discrete free fall of semi-implicit Euler: v_s = -g s dt, u_s = -g dt^2 s (s + 1) / 2.
      const double expected = -g * options.time_step * options.time_step * s * (s + 1) / 2;
      for (int n = 0; n < mesh.num_nodes(); ++n) {
        double u[3];
        total(n, u);
        if (cut(mesh.node(n)) > 0) {
          worst_fall = std::max({worst_fall, std::abs(u[2] - expected) / std::abs(expected), std::abs(u[0]) / std::abs(expected),
                                 std::abs(u[1]) / std::abs(expected)});
          if (s == steps) free_min = std::min(free_min, std::abs(u[2]));
          if (s >= 2) {
            const double a = (u[2] - 2 * previous[n] + before[n]) / (options.time_step * options.time_step);
            worst_acceleration = std::max(worst_acceleration, std::abs(a + g) / g);
          }
        } else {
          clamped_max = std::max(clamped_max, std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]));
        }
        before[n] = previous[n];
        previous[n] = u[2];
      }
    }
    std::printf("%s: %d enriched DOFs; free piece: fall error %.2e (relative), acceleration error %.2e (relative to g); "
                "after %d steps min free fall %.4e, max clamped-piece displacement %.4e (ratio %.2e)\n",
                type == ElementType::quad8 ? "quad8" : "tri6", model->num_enriched_dofs(), worst_fall,
                worst_acceleration, steps, free_min, clamped_max, clamped_max / free_min);
    EXPECT_LT(worst_fall, 1e-8);
    EXPECT_LT(worst_acceleration, 1e-5);
    // The clamped piece responds like a cantilever under its weight: at most twice (sudden
    // load) its static tip deflection q L^4 / (8 D), L its length (quad8 0.578, tri6 1), with
    // a margin for plate effects; both are small next to the free fall.
    const double length = type == ElementType::quad8 ? 0.578125 : 1.0;
    const double D = stiff.E * std::pow(stiff.h, 3) / (12 * (1 - stiff.nu * stiff.nu));
    const double cantilever = stiff.rho * stiff.h * g * std::pow(length, 4) / (8 * D);
    EXPECT_LT(clamped_max, 2.5 * cantilever);
    EXPECT_LT(clamped_max, 0.05 * free_min);
  }
}

// A clamped plate with a partial cut through its one element (a harmonic enrichment, so the
// clamped edge is an enriched edge) under 1 % of gravity, damped to rest: the corotated
// deflection is the linear one. Its clamp's terms were once turned with the element's frame,
// and spiral1's plate hinged about its clamped edge: 14.9 mm against the linear 0.18 mm here.
TEST(EnrichedDynamics, ACorotatedClampedEnrichedPlateUnderASmallLoadDeflectsAsTheLinearOne) {
  const std::string scene_text = R"({
    "mesh": {"generator": "rectangle", "size": [0.2, 0.2], "divisions": [1, 1], "element": "quad8"},
    "material": {"youngs_modulus": 1e7, "poisson_ratio": 0.3, "thickness": 0.01, "density": 500},
    "penalty": 1,
    "boundary": [{"select": {"plane": {"normal": [0, 1, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -0.0981]}],
    "analysis": {"type": "dynamic", "time_step": 0.002, "steps": 300, "corotational": COROTATIONAL,
                 "damping": {"mass": 40.0}},
    "cuts": [{"points": [[0.05, 0.1, 0], [0.15, 0.12, 0]]}],
    "enrichment": {"texture_resolution": 32}})";
  double corner[2];
  for (int corotational = 0; corotational < 2; ++corotational) {
    std::string text = scene_text;
    text.replace(text.find("COROTATIONAL"), 12, corotational ? "true" : "false");
    SceneRun run(parse_scene(text, "clamped_cut_plate"));
    ASSERT_EQ(run.model().num_enriched_elements(), 1);
    for (int s = 0; s < 300; ++s) run.step();
    const double xi[2] = {1, 1};  // the free corner (0.2, 0.2)
    double u[3];
    run.model().interpolate(run.displacement(), 0, xi, u);
    corner[corotational] = u[2];
  }
  std::printf("free corner deflection: linear %.6e, corotated %.6e\n", corner[0], corner[1]);
  EXPECT_LT(corner[0], -1e-4);
  EXPECT_NEAR(corner[1] / corner[0], 1.0, 1e-4);  // measured 1.5e-6
}

}  // namespace

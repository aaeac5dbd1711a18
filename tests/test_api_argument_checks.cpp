// Wrong sizes and indices from a program linking dgtex throw std::invalid_argument naming
// the function, the argument and what is valid (runtime/api_argument_checks.h), where they
// read and wrote out of bounds; so do ShellModel's parts (a bad mesh: MeshError) and a
// time that is not finite for CutManager::update. Stepping a static scene is a
// std::logic_error; a ShellSimulation step that throws leaves the state as it was.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/cut_manager.h"
#include "dgtex/deformed_shell.h"
#include "dgtex/mesh_error.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/model_error.h"
#include "dgtex/scene.h"
#include "dgtex/scene_model.h"
#include "dgtex/scene_run.h"
#include "dgtex/shell_simulation.h"
#include "dgtex/surface_point.h"
#include "dgtex/topology.h"
#include "exception_message_support.h"
#include "scene_in_code_support.h"
#include "shell_test_support.h"

namespace {

using namespace dgtex;
using test::message_of;
using test::strip_built_in_code;
using testing_support::max_abs;
using testing_support::max_difference;

TEST(ApiArgumentChecks, ShellModelLoadsAndInterpolationCheckSizesAndElements) {
  const Scene scene = strip_built_in_code(true, false);
  const Mesh mesh = build_scene_mesh(scene);
  const SceneModel built = build_scene_model(scene, mesh);
  const ShellModel& model = *built.model;
  const int dofs = model.num_dofs();
  const double xi[2] = {0, 0}, force[3] = {0, 0, 1};
  std::vector<double> f(dofs, 0.0), short_f(3, 0.0);
  double out[3];

  EXPECT_EQ(message_of<std::invalid_argument>([&] { model.interpolate(short_f, 1, xi, out); }),
            "ShellModel::interpolate: u has 3 entries; expected num_dofs() = " + std::to_string(dofs));
  EXPECT_EQ(message_of<std::invalid_argument>([&] { model.interpolate(f, 4, xi, out); }),
            "ShellModel::interpolate: element 4 is out of range; expected 0..3 (mesh().num_elements() = 4)");
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.interpolate(f, -1, xi, out); }), "");
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.add_point_force(7, xi, force, f); }), "");
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.add_point_force(1, xi, force, short_f); }), "");
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.add_gravity(force, short_f); }), "");
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.add_area_force(force, short_f); }), "");

  // Valid calls: a unit point force at the centre of element 1 adds up to 1 over its basis.
  EXPECT_EQ(message_of<std::invalid_argument>([&] { model.add_point_force(1, xi, force, f); }), "");
  double total_z = 0;
  for (int d = 2; d < dofs; d += 3) total_z += f[d];
  EXPECT_NEAR(total_z, 1.0, 1e-12);
  EXPECT_EQ(message_of<std::invalid_argument>([&] { model.interpolate(f, 3, xi, out); }), "");
}

TEST(ApiArgumentChecks, ShellSimulationChecksItsVectorsAndTimeStep) {
  const Scene scene = strip_built_in_code(true, false);
  const Mesh mesh = build_scene_mesh(scene);
  const SceneModel built = build_scene_model(scene, mesh);
  const int dofs = built.model->num_dofs();
  EXPECT_EQ(message_of<std::invalid_argument>([&] { ShellSimulation(*built.model, std::vector<char>(5), built.external_force); }),
            "ShellSimulation: fixed has 5 entries; expected model.num_dofs() = " + std::to_string(dofs));
  EXPECT_NE(message_of<std::invalid_argument>([&] { ShellSimulation(*built.model, built.fixed, {}); }), "");

  ShellSimulation simulation(*built.model, built.fixed, built.external_force);
  EXPECT_NE(message_of<std::invalid_argument>([&] { simulation.set_state(std::vector<double>(dofs), {}); }), "");
  DynamicsOptions options;
  // 1e300: dt^2 K overflowed, and the failed factorisation read "penalty too low?".
  for (double dt : {0.0, -0.005, std::nan(""), 1e300}) {
    options.time_step = dt;
    EXPECT_NE(message_of<std::invalid_argument>([&] { simulation.step(options); }).find("is not a positive time up to 1e30"),
              std::string::npos)
        << dt;
  }
  options.time_step = 0.005;
  simulation.step(options);
  double lowest_z = 0;
  for (int n = 0; n < mesh.num_nodes(); ++n) lowest_z = std::min(lowest_z, simulation.displacement()[3 * n + 2]);
  EXPECT_LT(lowest_z, 0);  // gravity pulls the strip down
}

// A step that throws leaves the simulation's state as it was before it (displacement,
// velocity, time), so a program may retry it, e.g. with a smaller time step. With the
// factor-reusing solver the failure may have replaced its factor, so the steps after it
// agree with a run that never failed to within the solver's tolerance (1e-8), not bitwise;
// factorising every step, they agree bitwise. Made to fail here by a penalty too low for a
// definite stiffness: M + dt^2 K is definite at small steps only.
TEST(ApiArgumentChecks, AShellSimulationStepThatThrowsLeavesTheStateAsItWas) {
  Scene scene = strip_built_in_code(true, false);
  scene.penalty = 0.01;
  const Mesh mesh = build_scene_mesh(scene);
  const SceneModel built = build_scene_model(scene, mesh);
  for (const bool reuse : {true, false}) {
    SCOPED_TRACE(reuse ? "reusing factors" : "a factor every step");
    ShellSimulation failing(*built.model, built.fixed, built.external_force);
    ShellSimulation reference(*built.model, built.fixed, built.external_force);
    DynamicsOptions small;
    small.corotational = true;
    small.reuse_factorization = reuse;
    small.time_step = 1e-4;
    for (int k = 0; k < 3; ++k) failing.step(small), reference.step(small);
    const std::vector<double> u = failing.displacement(), v = failing.velocity();
    const double time = failing.time();
    DynamicsOptions large = small;
    large.time_step = 0.05;
    EXPECT_NE(message_of<std::runtime_error>([&] { failing.step(large); }).find("not positive definite in the deformed state"),
              std::string::npos);
    EXPECT_EQ(failing.displacement(), u);
    EXPECT_EQ(failing.velocity(), v);
    EXPECT_EQ(failing.time(), time);
    for (int k = 0; k < 3; ++k) failing.step(small), reference.step(small);
    const double tolerance = reuse ? 1e-8 : 0.0;
    EXPECT_LE(max_difference(failing.displacement(), reference.displacement()),
              tolerance * max_abs(reference.displacement()));
    EXPECT_LE(max_difference(failing.velocity(), reference.velocity()), tolerance * max_abs(reference.velocity()));
    EXPECT_GT(max_abs(reference.displacement()), 0);
  }
}

// ShellModel built from parts of a program's own: each bad part is named before it is read.
TEST(ApiArgumentChecks, ShellModelChecksItsMeshTopologySectionsAndOptions) {
  const Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::quad8);
  const Topology topology = build_topology(mesh);
  kernels::ShellSection steel{2e11, 0.3, 0.01, 7800};
  const std::vector<kernels::ShellSection> sections(4, steel);
  const auto model_error = [&](Mesh m, const Topology& t, std::vector<kernels::ShellSection> s, std::vector<int> clamped,
                               ShellModelOptions options) {
    return message_of<std::invalid_argument>([&] { ShellModel(std::move(m), t, std::move(s), clamped, options); });
  };
  EXPECT_EQ(model_error(mesh, topology, sections, {0, 7}, {}), "");

  EXPECT_EQ(model_error(mesh, topology, {steel, steel}, {}, {}),
            "ShellModel: sections has 2 entries; expected mesh.num_elements() = 4");
  const auto with_section = [&](const std::function<void(kernels::ShellSection&)>& change) {
    std::vector<kernels::ShellSection> changed = sections;
    change(changed[2]);
    return model_error(mesh, topology, changed, {}, {});
  };
  EXPECT_EQ(with_section([](kernels::ShellSection& s) { s.youngs_modulus = -1; }),
            "ShellModel: sections[2].youngs_modulus is -1; expected a positive finite number");
  EXPECT_NE(with_section([](kernels::ShellSection& s) { s.poisson_ratio = 0.5; }), "");
  EXPECT_NE(with_section([](kernels::ShellSection& s) { s.thickness = 0; }), "");
  EXPECT_NE(with_section([](kernels::ShellSection& s) { s.density = std::nan(""); }), "");
  EXPECT_EQ(model_error(mesh, topology, sections, {8}, {}),
            "ShellModel: clamped_edges[0] 8 is out of range; expected 0..7 (topology.boundary_edges.size() = 8)");
  // Listed twice, its clamp terms were assembled twice (a silently stiffer clamp).
  EXPECT_EQ(model_error(mesh, topology, sections, {0, 3, 0}, {}),
            "ShellModel: clamped_edges[2] 0 is listed twice; list each edge once");

  // A topology of another mesh: more edges, or as many but of other elements.
  EXPECT_NE(model_error(mesh, build_topology(make_rectangle(1, 1, 4, 4, ElementType::quad8)), sections, {}, {})
                .find("the topology was not built from this mesh"),
            std::string::npos);
  Mesh reversed = mesh;  // the same elements, listed in reverse order
  for (int e = 0; e < 4; ++e)
    std::copy(mesh.element_nodes(3 - e), mesh.element_nodes(3 - e) + 8, reversed.elements.begin() + 8 * e);
  EXPECT_NE(model_error(reversed, topology, sections, {}, {}).find("interior_edges[0] (element 0, local edge 1)"),
            std::string::npos);
  EXPECT_EQ(model_error(reversed, build_topology(reversed), sections, {}, {}), "");

  const auto with_options = [&](const std::function<void(ShellModelOptions&)>& change) {
    ShellModelOptions options;
    change(options);
    return model_error(mesh, topology, sections, {}, options);
  };
  EXPECT_EQ(with_options([](ShellModelOptions& o) { o.penalty = 0; }),
            "ShellModel: options.penalty is 0; expected a positive finite number");
  EXPECT_NE(with_options([](ShellModelOptions& o) { o.edge_quadrature_points = 6; }), "");
  EXPECT_NE(with_options([](ShellModelOptions& o) { o.min_enrichment_mass_ratio = 1; }), "");
  EXPECT_NE(with_options([](ShellModelOptions& o) { o.rotation_cluster_texels = -1; }), "");
  EXPECT_NE(with_options([](ShellModelOptions& o) { o.enrichment_quadrature.merge_tolerance = 0; }), "");

  // The mesh itself: what validate_mesh refuses, as a MeshError.
  Mesh not_finite = mesh;
  not_finite.positions[4] = std::nan("");
  EXPECT_THROW(ShellModel(not_finite, topology, sections, {}, {}), MeshError);
  Mesh bad_index = mesh;
  bad_index.elements[3] = 999;
  EXPECT_THROW(ShellModel(bad_index, build_topology(bad_index), sections, {}, {}), MeshError);
}

TEST(ApiArgumentChecks, CutManagerUpdatesToFiniteTimesOnly) {
  const Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::quad8);
  Cut cut;
  cut.points = {{0, 0.5, 0}, {1, 0.5, 0}};
  EnrichmentOptions options;
  options.texture_resolution = 32;
  CutManager cuts(mesh, build_topology(mesh), {cut}, options);
  EXPECT_NE(message_of<std::invalid_argument>([&] { cuts.update(std::nan("")); }).find("is not finite"), std::string::npos);
  EXPECT_TRUE(cuts.update(0.0));
  EXPECT_EQ(cuts.functions().size(), 1u);
}

// What validate_scene refuses of a scene file is refused of cuts and options built in code
// (helper audit, session 71): a NaN or negative speed was taken (the cut never appeared),
// a NaN angle split nowhere, and a resolution of 65536 allocated a 32 GiB tile.
TEST(ApiArgumentChecks, CutManagerRefusesSchedulesAndOptionsAScenesValidationWould) {
  const Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::quad8);
  const Topology topology = build_topology(mesh);
  Cut cut;
  cut.points = {{0, 0.5, 0}, {1, 0.5, 0}};
  cut.has_schedule = true;
  EnrichmentOptions options;
  options.texture_resolution = 32;
  auto refusal = [&](const Cut& c, const EnrichmentOptions& o) {
    return message_of<std::invalid_argument>([&] { CutManager(mesh, topology, {c}, o); });
  };
  for (double speed : {-1.0, 0.0, std::nan(""), double(INFINITY)}) {
    Cut bad = cut;
    bad.speed = speed;
    EXPECT_NE(refusal(bad, options).find("CutManager: cuts[0].speed is "), std::string::npos) << speed;
  }
  Cut late = cut;
  late.start_time = std::nan("");
  EXPECT_EQ(refusal(late, options), "CutManager: cuts[0].start_time is nan; expected a finite number >= 0");
  EnrichmentOptions bad = options;
  bad.new_cut_angle_deg = -5;
  EXPECT_NE(refusal(cut, bad).find("enrichment.new_cut_angle_deg is -5"), std::string::npos);
  bad = options;
  bad.new_cut_length = std::nan("");
  EXPECT_NE(refusal(cut, bad).find("enrichment.new_cut_length is nan"), std::string::npos);
  bad = options;
  bad.texture_resolution = 65536;
  EXPECT_NE(refusal(cut, bad).find("enrichment.texture_resolution is 65536; expected 2..4096"), std::string::npos);
  Cut good = cut;
  good.speed = 2.0;
  EXPECT_EQ(refusal(good, options), "");
}

// Found by reading the public headers (session 68): each read or wrote out of bounds, or
// was taken silently.
TEST(ApiArgumentChecks, ShellSimulationRefusesNonFiniteInputsNegativeDampingAndBadSolverOptions) {
  const Scene scene = strip_built_in_code(true, false);
  const Mesh mesh = build_scene_mesh(scene);
  const SceneModel built = build_scene_model(scene, mesh);
  const int dofs = built.model->num_dofs();
  std::vector<double> force = built.external_force;
  force[17] = std::nan("");
  EXPECT_EQ(message_of<std::invalid_argument>([&] { ShellSimulation(*built.model, built.fixed, force); }),
            "ShellSimulation: external_force[17] is nan; expected a finite number");
  ShellSimulation simulation(*built.model, built.fixed, built.external_force);
  std::vector<double> u(dofs, 0.0);
  u[4] = INFINITY;
  EXPECT_EQ(message_of<std::invalid_argument>([&] { simulation.set_state(u, std::vector<double>(dofs, 0.0)); }),
            "ShellSimulation::set_state: u[4] is inf; expected a finite number");
  DynamicsOptions options;
  options.time_step = 0.005;
  options.mass_damping = -3;  // 1 + dt a <= 0 read as "not positive definite (penalty too low?)"
  EXPECT_EQ(message_of<std::invalid_argument>([&] { simulation.step(options); }),
            "ShellSimulation::step: mass_damping -3; expected a finite number >= 0");
  options.mass_damping = 0;
  FactorReuseOptions solver;
  solver.relative_tolerance = 1;  // took the extrapolated guess as the solution
  EXPECT_EQ(message_of<std::invalid_argument>([&] { simulation.set_solver_options(solver); }),
            "FactorReuseOptions: relative_tolerance 1; expected a number in (0, 1), e.g. 1e-8");
  solver.relative_tolerance = 1e-8;
  solver.max_iterations = 0;
  EXPECT_NE(message_of<std::invalid_argument>([&] { simulation.set_solver_options(solver); }).find("max_iterations 0"),
            std::string::npos);
  solver.max_iterations = 40;
  solver.refactor_after_iterations = 0;  // every solve that iterates refactorises: valid
  EXPECT_EQ(message_of<std::invalid_argument>([&] { simulation.set_solver_options(solver); }), "");
  simulation.step(options);
}

// A simulation keeps the DOFs of the model it was built on: a model changed under it was
// stepped with the old state, constraints and factor (writes past the end of the state).
TEST(ApiArgumentChecks, ASimulationRefusesToGoOnOnceItsModelChanged) {
  const Scene scene = strip_built_in_code(true, false);
  const Mesh mesh = build_scene_mesh(scene);
  SceneModel built = build_scene_model(scene, mesh);
  ShellModel& model = *built.model;
  ShellSimulation simulation(model, built.fixed, built.external_force);
  DynamicsOptions options;
  options.time_step = 0.005;
  simulation.step(options);
  const std::uint64_t revision = model.revision();

  // set_enrichments that throws leaves the model (and so the simulation) as they were: a
  // function enriching a node of two elements with a texture on one of them only.
  int node = -1;
  for (int a = 0; a < mesh.nodes_per_element() && node < 0; ++a)
    for (int e = 1; e < mesh.num_elements(); ++e)
      if (std::count(mesh.element_nodes(e), mesh.element_nodes(e) + mesh.nodes_per_element(), mesh.element_nodes(0)[a]))
        node = mesh.element_nodes(0)[a];
  ASSERT_GE(node, 0);
  EnrichmentFunction half;
  half.enriched_nodes = {node};
  half.elements.push_back({0, kernels::TexelTile(4, 4)});
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.set_enrichments({half}); }).find("but has no texture"),
            std::string::npos);
  EXPECT_EQ(model.revision(), revision);
  EXPECT_EQ(model.num_enriched_nodes(), 0);
  simulation.step(options);

  model.set_material_textures({{1, 1, 1, {2e6}, {0.02}}});
  EXPECT_GT(model.revision(), revision);
  EXPECT_NE(message_of<std::logic_error>([&] { simulation.step(options); })
                .find("ShellSimulation::step: the model's basis or material textures changed after this simulation "
                      "was built"),
            std::string::npos);
  EXPECT_THROW(simulation.kinetic_energy(), std::logic_error);
  ShellSimulation rebuilt(model, built.fixed, built.external_force);
  rebuilt.step(options);
}

TEST(ApiArgumentChecks, IndicesAndParametricPointsOfModelCutsAndSearchAreChecked) {
  const Mesh mesh = make_rectangle(1, 1, 2, 2, ElementType::quad8);
  const Topology topology = build_topology(mesh);
  const std::vector<kernels::ShellSection> sections(4, kernels::ShellSection{1e6, 0.3, 0.01, 1000});
  const ShellModel model(mesh, topology, sections, {}, {});
  const std::vector<double> u(model.num_dofs(), 0.0);
  double out[3];
  const double outside[2] = {1.5, 0}, not_a_number[2] = {std::nan(""), 0}, corner[2] = {1, -1};
  EXPECT_EQ(message_of<std::invalid_argument>([&] { model.interpolate(u, 0, outside, out); }),
            "ShellModel::interpolate: xi (1.5, 0) is outside the reference element; quad8 needs xi1, xi2 in [-1, 1]");
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.interpolate(u, 0, not_a_number, out); }), "");
  EXPECT_EQ(message_of<std::invalid_argument>([&] { model.interpolate(u, 0, corner, out); }), "");
  std::vector<double> f(model.num_dofs(), 0.0);
  const double up[3] = {0, 0, 1};
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.add_point_force(0, outside, up, f); }), "");
  // Virtual nodes start at num_nodes(): 0 read before the arrays.
  EXPECT_NE(message_of<std::invalid_argument>([&] { model.node_shift(0); }).find("virtual node 0 is out of range"),
            std::string::npos);

  // A null field was read (helper audit, session 71).
  EXPECT_EQ(message_of<std::invalid_argument>([&] { model.moments_of_fields(model, {&u, nullptr}); }),
            "moments_of_fields: field 1 is a null pointer");

  // A topology of another (finer) mesh wrote out of bounds in the cut manager's adjacency.
  Cut cut;
  cut.points = {{0, 0.5, 0}, {1, 0.5, 0}};
  EnrichmentOptions options;
  options.texture_resolution = 32;
  const Mesh finer = make_rectangle(1, 1, 4, 4, ElementType::quad8);
  EXPECT_NE(message_of<std::invalid_argument>([&] { CutManager(mesh, build_topology(finer), {cut}, options); })
                .find("CutManager: the topology was not built from this mesh"),
            std::string::npos);

  const SurfacePointSearch search(mesh);
  const double p[3] = {0.2, 0.2, 0.1};
  EXPECT_EQ(message_of<std::invalid_argument>([&] { search.closest_among({0, 99}, p); }),
            "SurfacePointSearch::closest_among: elements[1] 99 is out of range; expected 0..3 (mesh.num_elements() = 4)");
  EXPECT_NE(message_of<std::invalid_argument>([&] { search.closest_among({2, 1}, p); }).find("ascending"),
            std::string::npos);
  EXPECT_EQ(search.closest_among({0, 1}, p).element, 0);
}

// DeformedShell validated its state but not the element and xi of each call, and
// sample_enrichment not the size of its texture (helper audit, session 71): each read out of
// bounds.
TEST(ApiArgumentChecks, DeformedShellChecksItsElementsAndPoints) {
  SceneRun run(strip_built_in_code(true, false));
  const ShellState state = run.state();
  const DeformedShell shell(state);
  const int elements = state.mesh.num_elements();
  double x[3];
  EXPECT_NE(message_of<std::invalid_argument>([&] { shell.enrichments_of(elements); })
                .find("DeformedShell::enrichments_of: element " + std::to_string(elements) + " is out of range"),
            std::string::npos);
  EXPECT_NE(message_of<std::invalid_argument>([&] { shell.position(-1, 0, 0, x); }).find("element -1 is out of range"),
            std::string::npos);
  EXPECT_NE(message_of<std::invalid_argument>([&] { shell.position(0, std::nan(""), 0, x); })
                .find("xi[0] is nan; expected a finite number"),
            std::string::npos);
  EXPECT_EQ(message_of<std::invalid_argument>([&] { shell.position(0, 0, 0, x); }), "");
  ElementEnrichment texture;
  texture.resolution = 64;
  texture.values.assign(16 * 16, 0.5f);
  EXPECT_NE(message_of<std::invalid_argument>([&] { sample_enrichment(state.mesh.type, texture, 0, 0); })
                .find("sample_enrichment: 256 values for resolution 64"),
            std::string::npos);
  texture.resolution = 16;
  EXPECT_EQ(sample_enrichment(state.mesh.type, texture, 0, 0), 0.5f);
  int i, j;
  EXPECT_THROW(enrichment_texel(state.mesh.type, 0, 0, 0, i, j), std::invalid_argument);
}

// A step that threw (here: a penalty below the definiteness threshold) ends the run: a
// retry after a failed basis change went on with the old basis, its cuts already moved on.
TEST(ApiArgumentChecks, AStepAfterAFailedStepIsALogicError) {
  Scene scene = strip_built_in_code(true, false);
  scene.penalty = 0.01;
  SceneRun run(scene);
  EXPECT_NE(message_of<ModelError>([&] { run.step(); }).find("penalty too low?"), std::string::npos);
  EXPECT_NE(message_of<std::logic_error>([&] { run.step(); })
                .find("SceneRun::step: step 1 failed (dynamic system matrix not positive definite"),
            std::string::npos);
  EXPECT_EQ(run.steps_taken(), 0);
}

TEST(ApiArgumentChecks, SteppingAStaticSceneIsALogicError) {
  SceneRun run(strip_built_in_code(false, false));
  EXPECT_THROW(run.step(), std::logic_error);
  EXPECT_EQ(run.steps_taken(), 0);
  run.solve_static();
  SceneRun dynamic(strip_built_in_code(true, false));
  dynamic.step();
  EXPECT_EQ(dynamic.steps_taken(), 1);
}

}  // namespace

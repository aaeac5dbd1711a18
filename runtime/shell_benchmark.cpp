#include "dgtex/shell_benchmark.h"

#include <omp.h>

#include <Eigen/Dense>
#include <chrono>
#include <ctime>
#include <stdexcept>

#include "dgtex/kernels/shape_functions.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/shell_simulation.h"
#include "dgtex/stage_timer.h"
#include "thread_count_guard.h"

namespace dgtex {

namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

// The flop model (a multiply-add counts 2). Exact for the products that dominate:
//  - element K:  2 * (6 nq) * 3 npe * (3 npe + 3) / 2   (upper block triangle of B^T D B)
//  - edge K:     4 * nq_edge * 6 npe * (6 npe + 3) / 2  (P G^T + Q M^T, upper blocks),
//                boundary edges count only the plus half (3 npe instead of 6 npe);
//  - block gather: 9 adds per contribution ~ one per local block.
// Estimated by counting the arithmetic of the point-level code (shell_point.cpp), per basis
// function a of a point: rest geometry 30, membrane rows 25, bending rows 190, rotation of
// both row sets 108, plane stress 35, corrective force 90  ->  ~480 per function and point
// (elements); edges per side and function ~300 plus rotation, corrective and P, Q ~95.
// Corotation adds per element point 60 npe + 200 (deformation gradient) + ~450 (polar,
// 4 Newton steps) and per edge point 120 npe + 300 (edge frames).
double shell_assembly_flops(const ShellModel& model, bool corotated) {
  const kernels::ElementType type = model.mesh().type;
  const double npe = kernels::nodes_per_element(type);
  const double nq = kernels::element_quadrature(type).count;
  const double nqe = model.options().edge_quadrature_points;
  const double elements = model.mesh().num_elements();
  const double interior = model.num_interior_edges(), boundary = model.num_clamped_edges();
  const double element_product = 2 * (6 * nq) * 3 * npe * (3 * npe + 3) / 2;
  const double element_points = nq * (480 * npe + 60 + (corotated ? 60 * npe + 650 : 0));
  const double interior_product = 4 * nqe * 6 * npe * (6 * npe + 3) / 2;
  const double boundary_product = 4 * nqe * 3 * npe * (3 * npe + 3) / 2;
  const double edge_point = 2 * (300 * npe + 60) + 95 * 2 * npe + (corotated ? 120 * npe + 300 : 0);
  const double gather = 9 * (elements * npe * npe + (interior + boundary) * 4 * npe * npe);
  return elements * (element_product + element_points) + interior * (interior_product + nqe * edge_point) +
         boundary * (boundary_product + nqe * edge_point / 2) + gather;
}

double measure_dense_gemm_gflops(int n, int repeat) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(n, n), b = Eigen::MatrixXd::Random(n, n), c(n, n);
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const Clock::time_point start = Clock::now();
    c.noalias() = a * b;
    best = std::min(best, ms_since(start));
  }
  if (!(c.norm() > 0)) throw std::runtime_error("dense GEMM reference produced zero");  // keeps c alive
  return 2.0 * n * n * n / (best * 1e-3) / 1e9;
}

Scene load_shell_benchmark_scene(const std::string& scene_path) {
  Scene scene = load_scene(scene_path);
  if (!scene.analysis.is_dynamic())
    throw std::invalid_argument("scene '" + scene_path + "' is a static analysis; the shell benchmark needs \"analysis\": {\"type\": \"dynamic\", ...}");
  if (!scene.cuts.empty())
    throw std::invalid_argument("scene '" + scene_path + "' has cuts, which the shell benchmark does not time; remove \"cuts\"");
  return scene;
}

ShellBenchRun run_shell_benchmark(const std::string& scene_path, int steps, int threads, bool reuse_factorization,
                                  const FactorReuseOptions& solver, const std::function<void(int, int)>& progress) {
  const Scene scene = load_shell_benchmark_scene(scene_path);
  if (steps < 1) throw std::invalid_argument("steps = " + std::to_string(steps) + ", need >= 1");
  const Mesh mesh = build_scene_mesh(scene);
  SceneModel setup = build_scene_model(scene, mesh);
  const ShellModel& model = *setup.model;
  const detail::ThreadCountGuard set_threads(threads);
  ShellSimulation sim(model, setup.fixed, setup.external_force);
  sim.set_solver_options(solver);
  DynamicsOptions options;
  options.time_step = scene.analysis.time_step;
  options.corotational = scene.analysis.corotational;
  options.mass_damping = scene.analysis.damping.mass;
  options.stiffness_damping = scene.analysis.damping.stiffness;
  options.reuse_factorization = reuse_factorization;

  ShellBenchRun run;
  run.threads = threads;
  run.steps = steps;
  run.reuse_factorization = reuse_factorization;
  for (int s = 0; s < steps; ++s) {
    const double before_assembly = sim.timings().count("assembly") ? sim.timings().at("assembly").total_ms : 0;
    const double before_solve = sim.timings().count("solve") ? sim.timings().at("solve").total_ms : 0;
    const double cpu_before = process_cpu_ms();
    sim.step(options);
    run.step_cpu.add(process_cpu_ms() - cpu_before);
    const double assembly = (sim.timings().count("assembly") ? sim.timings().at("assembly").total_ms : 0) - before_assembly;
    const double solve = sim.timings().at("solve").total_ms - before_solve;
    run.assembly.add(assembly);
    run.solve.add(solve);
    run.step.add(assembly + solve);
    run.assembly_ms.push_back(assembly);
    run.solve_ms.push_back(solve);
    if (progress) progress(s + 1, steps);
  }
  run.elements = mesh.num_elements();
  run.nodes = mesh.num_nodes();
  run.free_dofs = sim.system().size();
  run.quadrature_points = model.num_quadrature_points();
  run.factor_nonzeros = sim.factor_nonzeros();
  run.assembly_flops = shell_assembly_flops(model, options.corotational);
  const double assembly_s = run.assembly.mean_ms() * 1e-3;
  if (assembly_s > 0) {
    run.quadrature_points_per_s = static_cast<double>(run.quadrature_points) / assembly_s;
    run.assembly_gflops = run.assembly_flops / assembly_s / 1e9;
  }
  const FactorReuseStatistics& stats = sim.solver_statistics();
  run.factorizations = reuse_factorization || !options.corotational ? stats.factorizations : steps;
  run.pcg_iterations = stats.iterations;
  run.factorize_ms = stats.factorize_ms;
  run.precondition_ms = stats.precondition_ms;
  run.displacement = sim.displacement();
  return run;
}

}  // namespace dgtex

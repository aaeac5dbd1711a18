#include "dgtex/scaling_benchmark.h"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <algorithm>
#include <exception>
#include <iomanip>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "dgtex/cut_manager.h"
#include "dgtex/factor_reusing_solver.h"
#include "dgtex/free_dof_system.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/scene_model.h"
#include "dgtex/scene_run.h"
#include "dgtex/sparse_cholesky.h"
#include "dgtex/stage_timer.h"
#include "dgtex/topology.h"
#include "thread_count_guard.h"

namespace dgtex {

namespace {

using Clock = std::chrono::steady_clock;


void check_threads(const std::vector<int>& threads) {
  if (threads.empty()) throw std::invalid_argument("thread list is empty; give at least one count, e.g. 1,2");
  for (int t : threads)
    if (t < 1 || t > 1024)
      throw std::invalid_argument("thread count " + std::to_string(t) + " is out of range, need 1..1024");
}

void check_repeats(int repeats) {
  if (repeats < 1) throw std::invalid_argument("repeats = " + std::to_string(repeats) + ", need >= 1");
}

// The time at which every cut of the scene is complete: the scene's end (dynamic) or 0.
double end_time(const Scene& scene) {
  return scene.analysis.is_dynamic() ? scene.analysis.time_step * scene.analysis.steps : 0.0;
}

// Best (smallest) wall time of `repeats` calls of `body` at each thread count, after one
// untimed call: the first call pays one-time work (first-touch pages, scratch built on
// first use) that the later ones reuse, so with --repeats 1 the 1-thread time held it alone
// (the assembly read 14x faster on 2 threads).
template <class Body>
std::vector<double> best_times(const std::vector<int>& threads, int repeats, Body&& body) {
  const detail::ThreadCountGuard restore;
  if (!threads.empty()) {
    omp_set_num_threads(threads.front());
    body();
  }
  std::vector<double> best;
  for (int t : threads) {
    omp_set_num_threads(t);
    double b = 1e300;
    for (int r = 0; r < repeats; ++r) b = std::min(b, body());
    best.push_back(b);
  }
  return best;
}

std::string scene_label(const Scene& scene) { return scene.source_name.empty() ? std::string("scene") : scene.source_name; }

}  // namespace

void check_scaling_scene(const Scene& scene, const std::string& family) {
  const std::string name = "scene '" + scene_label(scene) + "'";
  if (family == "enrichment_solve" || family == "enriched_assembly") {
    if (scene.cuts.empty())
      throw std::invalid_argument(name + " has no cuts; the " +
                                  (family == "enrichment_solve" ? "enrichment solve" : "enriched assembly") +
                                  " needs \"cuts\"");
  } else if (family == "factorization" || family == "scene_step" || family == "batch") {
    if (!scene.analysis.is_dynamic())
      throw std::invalid_argument(name + " is static; " +
                                  (family == "factorization" ? "the factorization needs a dynamic scene (its time step)"
                                   : family == "scene_step"  ? "whole steps need a dynamic scene"
                                                             : "the batch needs a dynamic scene"));
  } else {
    throw std::invalid_argument("check_scaling_scene: unknown family '" + family + "'");
  }
}

KernelScaling scale_enrichment_solve(const Scene& cut_scene, const std::vector<int>& threads, int repeats) {
  check_threads(threads);
  check_repeats(repeats);
  check_scaling_scene(cut_scene, "enrichment_solve");
  const Mesh mesh = build_scene_mesh(cut_scene);
  const Topology topology = build_topology(mesh);
  const double time = end_time(cut_scene);
  CutUpdateStats stats;
  KernelScaling k;
  k.family = "enrichment_solve";
  k.threads = threads;
  k.ms = best_times(threads, repeats, [&] {
    CutManager cuts(mesh, topology, cut_scene.cuts, cut_scene.enrichment);  // from scratch: nothing settled yet
    const Clock::time_point start = Clock::now();
    cuts.update(time);
    const double ms = ms_since(start);
    stats = cuts.last_update();
    return ms;
  });
  std::ostringstream w;
  w << scene_label(cut_scene) << ": cut update at t = " << time << " (" << stats.solves << " solves, " << stats.unknowns
    << " texel unknowns, T = " << cut_scene.enrichment.texture_resolution << ")";
  k.workload = w.str();
  return k;
}

KernelScaling scale_assembly(const Scene& scene, bool complete_cuts, const std::vector<int>& threads, int repeats) {
  check_threads(threads);
  check_repeats(repeats);
  const Mesh mesh = build_scene_mesh(scene);
  SceneModel built = build_scene_model(scene, mesh);
  ShellModel& model = *built.model;
  if (complete_cuts) {
    check_scaling_scene(scene, "enriched_assembly");
    const Topology topology = build_topology(mesh);
    CutManager cuts(mesh, topology, scene.cuts, scene.enrichment);
    cuts.update(end_time(scene));
    model.set_enrichments(cuts.functions());
  }
  // A smooth deformation of a few per cent of the shell's size, so that every point rotates.
  std::vector<double> current = model.rest_state();
  for (std::size_t i = 0; i < current.size(); ++i) current[i] += 1e-2 * std::sin(0.37 * static_cast<double>(i));
  std::vector<double> blocks, corrective, first_blocks;
  KernelScaling k;
  k.family = "assembly";
  k.threads = threads;
  k.ms = best_times(threads, repeats, [&] {
    const Clock::time_point start = Clock::now();
    model.assemble_stiffness(current.data(), blocks, &corrective);
    const double ms = ms_since(start);
    if (first_blocks.empty()) first_blocks = blocks;
    k.identical_across_threads = k.identical_across_threads && blocks == first_blocks;
    return ms;
  });
  std::ostringstream w;
  w << scene_label(scene) << ": corotated, " << mesh.num_elements() << " elements, " << model.num_quadrature_points()
    << " quadrature points";
  if (complete_cuts) w << ", " << model.enrichments().size() << " complete-cut enrichments";
  k.workload = w.str();
  return k;
}

KernelScaling scale_polar_decomposition(std::int64_t count, const std::vector<int>& threads, int repeats) {
  check_threads(threads);
  check_repeats(repeats);
  if (count < 1) throw std::invalid_argument("polar decomposition count = " + std::to_string(count) + ", need >= 1");
  // F = I + perturbation, drawn until det F > 0.1 (the corotated shell's case).
  std::mt19937_64 random(12345);
  std::uniform_real_distribution<double> uniform(-0.4, 0.4);
  std::vector<double> F(9 * static_cast<std::size_t>(count)), R(F.size()), first;
  for (std::int64_t m = 0; m < count; ++m) {
    double* f = &F[9 * m];
    for (;;) {
      for (int i = 0; i < 9; ++i) f[i] = (i % 4 == 0 ? 1.0 : 0.0) + uniform(random);
      const double det = f[0] * (f[4] * f[8] - f[5] * f[7]) - f[1] * (f[3] * f[8] - f[5] * f[6]) +
                         f[2] * (f[3] * f[7] - f[4] * f[6]);
      if (det > 0.1) break;
    }
  }
  KernelScaling k;
  k.family = "polar_decomposition";
  k.workload = std::to_string(count) + " random 3x3 matrices (det F > 0)";
  k.threads = threads;
  k.ms = best_times(threads, repeats, [&] {
    const Clock::time_point start = Clock::now();
    kernels::polar_decomposition_batch(count, F.data(), R.data());
    const double ms = ms_since(start);
    if (first.empty()) first = R;
    k.identical_across_threads = k.identical_across_threads && R == first;
    return ms;
  });
  return k;
}

KernelScaling scale_factorization(const Scene& scene, const std::vector<int>& threads, int repeats) {
  check_threads(threads);
  check_repeats(repeats);
  check_scaling_scene(scene, "factorization");
  const Mesh mesh = build_scene_mesh(scene);
  SceneModel built = build_scene_model(scene, mesh);
  const ShellModel& model = *built.model;
  // The matrix the corotated step factorises: FactorReusingSolver's element-local pattern,
  // or the whole pattern where the solver rules that one out by its dropped radius
  // (fracture's tri6 mesh) or falls back from it (not positive definite).
  std::vector<double> K, values;
  model.assemble_stiffness(nullptr, K, nullptr);
  const double dt = scene.analysis.time_step;
  const std::vector<char> element_local = element_local_blocks(model.mass_blocks());
  std::vector<char> free(built.fixed.size());
  for (std::size_t d = 0; d < free.size(); ++d) free[d] = !built.fixed[d];
  const double radius =
      element_local_dropped_radius(model.pattern(), element_local, free, model.mass_blocks(), {1.0, &K, dt * dt});
  const bool ruled_out = radius > FactorReuseOptions{}.element_local_max_dropped_radius;
  std::unique_ptr<FreeDofSystem> system;
  std::unique_ptr<SparseCholesky> cholesky;
  std::string pattern = "element-local";
  if (ruled_out) {
    std::ostringstream why;
    why << "whole pattern; the element-local one drops couplings of radius " << std::setprecision(2) << radius;
    pattern = why.str();
  }
  for (const std::vector<char>* blocks : {ruled_out ? nullptr : &element_local, static_cast<const std::vector<char>*>(nullptr)}) {
    system = std::make_unique<FreeDofSystem>(model.pattern(), built.fixed, blocks);
    system->gather(model.mass_blocks().data(), 1.0, K.data(), dt * dt, values);
    cholesky = std::make_unique<SparseCholesky>();
    cholesky->analyze(system->size(), system->column_start(), system->row_index());
    try {
      cholesky->factorize(values);
      break;
    } catch (const NotPositiveDefinite&) {
      if (!blocks) throw;  // the whole pattern too: a scene the solver cannot step either
      pattern = "whole pattern; the element-local one is not positive definite";
    }
  }
  KernelScaling k;
  k.family = "factorization";
  k.threads = threads;
  k.ms = best_times(threads, repeats, [&] {
    const Clock::time_point start = Clock::now();
    cholesky->factorize(values);
    return ms_since(start);
  });
  std::ostringstream w;
  w << scene_label(scene) << ": M + dt^2 K (" << pattern << "), " << system->size() << " free DOFs, nnz(L) "
    << cholesky->factor_nonzeros();
  k.workload = w.str();
  return k;
}

KernelScaling scale_scene_steps(const Scene& scene, int steps, const std::vector<int>& threads) {
  check_threads(threads);
  if (steps < 1) throw std::invalid_argument("scene steps = " + std::to_string(steps) + ", need >= 1");
  check_scaling_scene(scene, "scene_step");
  KernelScaling k;
  k.family = "scene_step";
  k.threads = threads;
  std::vector<double> first;
  const detail::ThreadCountGuard restore;
  for (int t : threads) {
    omp_set_num_threads(t);
    SceneRun run(scene);
    run.step();  // untimed: first factorisation, first enrichment step
    const Clock::time_point start = Clock::now();
    for (int s = 0; s < steps; ++s) run.step();
    k.ms.push_back(ms_since(start) / steps);
    if (first.empty()) first = run.displacement();
    k.identical_across_threads = k.identical_across_threads && run.displacement() == first;
  }
  k.workload = scene_label(scene) + ": " + std::to_string(steps) + " steps after 1 untimed (ms per step)";
  return k;
}

BatchThroughput measure_batch_throughput(const Scene& scene, int runs, int steps, int solo_threads) {
  if (runs < 1) throw std::invalid_argument("batch runs = " + std::to_string(runs) + ", need >= 1");
  if (steps < 1) throw std::invalid_argument("batch steps = " + std::to_string(steps) + ", need >= 1");
  if (solo_threads < 1) throw std::invalid_argument("solo threads = " + std::to_string(solo_threads) + ", need >= 1");
  check_scaling_scene(scene, "batch");
  auto simulate = [&] {
    SceneRun run(scene);
    for (int s = 0; s < steps; ++s) run.step();
    return run.displacement();
  };
  BatchThroughput b;
  b.scene = scene_label(scene);
  b.runs = runs;
  b.steps = steps;
  b.solo_threads = solo_threads;

  std::vector<std::vector<double>> results;
  const detail::ThreadCountGuard solo(solo_threads);
  Clock::time_point start = Clock::now();
  for (int r = 0; r < runs; ++r) results.push_back(simulate());
  b.solo_ms = ms_since(start);

  std::vector<std::vector<double>> batch(runs);
  std::vector<std::exception_ptr> errors(runs);
  std::vector<std::thread> workers;
  start = Clock::now();
  for (int r = 0; r < runs; ++r)
    workers.emplace_back([&, r] {
      try {
        omp_set_num_threads(1);  // this thread's own OpenMP setting
        batch[r] = simulate();
      } catch (...) {
        errors[r] = std::current_exception();
      }
    });
  for (std::thread& w : workers) w.join();
  b.batch_ms = ms_since(start);
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  const std::vector<double>& reference = results.front();
  double scale = 0;
  for (double x : reference) scale = std::max(scale, std::abs(x));
  auto compare = [&](const std::vector<double>& u) {
    b.identical = b.identical && u == reference;
    if (u.size() != reference.size()) {
      b.max_relative_difference = std::numeric_limits<double>::infinity();
      return;
    }
    for (std::size_t i = 0; i < u.size(); ++i)
      b.max_relative_difference = std::max(b.max_relative_difference, std::abs(u[i] - reference[i]) / std::max(scale, 1e-300));
  };
  for (const std::vector<double>& u : results) compare(u);
  for (const std::vector<double>& u : batch) compare(u);
  b.displacement = batch.front();
  return b;
}

}  // namespace dgtex

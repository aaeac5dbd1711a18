#include "dgtex/scene_run.h"

#include <algorithm>
#include <chrono>
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>

#include <omp.h>

#include "dgtex/basis_projection.h"
#include "dgtex/crease_enrichment.h"
#include "dgtex/kernels/threads_busy_beside.h"
#include "dgtex/model_error.h"
#include "dgtex/scene_model.h"
#include "dgtex/step_memory.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"
#include "cut_update_team.h"
#include "scene_model_parts.h"

namespace dgtex {

namespace {

void merge(StageTimings& into, const StageTimings& from) {
  for (const auto& [stage, stats] : from) {
    StageStatistics& s = into[stage];
    s.total_ms += stats.total_ms;
    s.max_ms = std::max(s.max_ms, stats.max_ms);
    s.count += stats.count;
  }
}

// The texel fields the scene's cuts and creases will hold, from the traced paths
// (cuts: nullptr without cuts).
TexelFields texel_fields(const Scene& scene, const Mesh& mesh, const CutManager* cuts,
                         const std::vector<TracedCrease>& creases) {
  TexelFields fields;
  fields.type = mesh.type;
  fields.resolution = scene.enrichment.texture_resolution;
  fields.graph_solves = mesh.type == ElementType::tri6 || scene.enrichment.solver == EnrichmentOptions::Solver::cholmod;
  if (cuts) fields.cuts = cuts->full_footprint();
  fields.creases = crease_footprint(creases);
  return fields;
}

}  // namespace

SceneRun::SceneRun(const Scene& scene, SceneRunOptions options)
    : scene_(scene), mesh_(build_scene_mesh(scene_)), topology_(build_topology(mesh_)), options_(options) {
  if (options_.cut_update_threads < 0)
    throw std::invalid_argument("SceneRun: SceneRunOptions::cut_update_threads is " +
                                std::to_string(options_.cut_update_threads) +
                                "; give 0 (balanced step by step) or a thread count of 1 or more");
  cut_update_team_ = std::make_unique<detail::CutUpdateTeam>(options_.cut_update_threads);
  // The malloc settings of the reservation below before the OpenMP threads allocate (the cut
  // tracing runs on them), so that they too take the heap it faults in.
  const bool enriched = !scene_.cuts.empty() || !scene_.creases.empty();
  const bool reserves = options_.reserve_step_memory && enriched;
  if (reserves) prepare_step_memory();
  SceneModel built = build_scene_model(scene_, mesh_);
  model_ = std::move(built.model);
  if (scene_.analysis.is_dynamic()) {
    dynamics_.time_step = scene_.analysis.time_step;
    dynamics_.corotational = scene_.analysis.corotational;
    dynamics_.mass_damping = scene_.analysis.damping.mass;
    dynamics_.stiffness_damping = scene_.analysis.damping.stiffness;
  }
  if (enriched) {
    {
      ScopedStage stage(timings_, "enrichment");
      if (!scene_.cuts.empty())
        cuts_ = std::make_unique<CutManager>(mesh_, topology_, scene_.cuts, scene_.enrichment);
      // Before the first field is allocated: a scene whose texel fields cannot fit is
      // refused with one line rather than killed by the system later.
      const std::vector<TracedCrease> creases =
          trace_creases(mesh_, topology_, scene_.creases, scene_.enrichment.texture_resolution);
      const TexelFields fields = texel_fields(scene_, mesh_, cuts_.get(), creases);
      const std::int64_t available = available_memory_bytes();
      check_texel_memory(fields, available, scene_.source_name.empty() ? "scene" : scene_.source_name);
      if (options_.before_texel_fields) options_.before_texel_fields(fields, available);
      if (reserves) {
        // Set-up, not enrichment: the time-0 update counts as the first step's (bench scenes).
        const auto reserve_start = std::chrono::steady_clock::now();
        try {
          const std::int64_t bytes = step_memory_bytes(fields, available);
          reserve_step_memory(bytes);
          reserved_step_memory_bytes_ = bytes;
        } catch (const std::bad_alloc&) {
          // Only a head start: without it the steps take their memory as they go.
        }
        stage.exclude(ms_since(reserve_start));
      }
      if (cuts_) cuts_->update(0.0);
      creases_ = build_crease_functions(mesh_, creases);
    }
    if (cuts_) model_->set_cut_edge_texels(cuts_->edge_walls().resolution(), cuts_->edge_walls().flags(mesh_.num_elements()));
    model_->set_enrichments(enrichment_functions());
    built.fixed = detail::fixed_dofs_of_valid_scene(scene_, *model_);
    built.external_force = detail::external_force_of_valid_scene(scene_, *model_);
  }
  simulation_ = std::make_unique<ShellSimulation>(*model_, std::move(built.fixed), std::move(built.external_force));
  simulation_->set_solver_options(options_.solver);
  // A dynamic scene may leave rigid modes free (a falling shell); a static one may not.
  if (!scene_.analysis.is_dynamic()) simulation_->check_statically_constrained();
}

SceneRun::~SceneRun() { discard_next_cut_update(); }

std::vector<EnrichmentFunction> SceneRun::enrichment_functions() const {
  std::vector<EnrichmentFunction> all;
  if (cuts_) all = cuts_->functions();
  all.insert(all.end(), creases_.begin(), creases_.end());  // static: after the cuts' functions
  return all;
}

void SceneRun::solve_static() { simulation_->solve_static(); }

void SceneRun::step() {
  if (!scene_.analysis.is_dynamic())
    throw std::logic_error("SceneRun::step: the scene's analysis is static; call solve_static, or give the scene a "
                           "dynamic analysis");
  if (!failed_step_.empty())
    throw std::logic_error("SceneRun::step: step " + std::to_string(steps_ + 1) + " failed (" + failed_step_ +
                           "); its cuts may have moved on without their basis, so the run cannot go on: start a new "
                           "SceneRun");
  const double next = time_ + dynamics_.time_step;
  const kernels::ScopedThreadsBusyBeside beside(&cut_update_threads_);
  last_cut_update_threads_ = 0;
  try {
    if (cuts_) {
      const bool changed = bring_cuts_to(next);
      // What the new basis needs from the cut manager, taken before its next update starts.
      std::vector<EnrichmentFunction> functions;
      std::vector<char> edge_flags;
      const int edge_resolution = cuts_->edge_walls().resolution();
      if (changed) {
        functions = enrichment_functions();
        edge_flags = cuts_->edge_walls().flags(mesh_.num_elements());
      }
      start_next_cut_update(next + dynamics_.time_step);
      if (changed) change_basis(std::move(functions), edge_resolution, std::move(edge_flags));
    }
    simulation_->step(dynamics_);
    if (next_cut_update_.valid()) {
      beside_update_ms_ = ms_since(next_cut_update_started_);  // the step's own work beside it
      next_cut_update_.wait();  // both done: the step is over
    }
  } catch (const std::exception& e) {
    discard_next_cut_update();
    failed_step_ = e.what();
    throw;
  } catch (...) {
    discard_next_cut_update();
    failed_step_ = "an exception of unknown type";
    throw;
  }
  time_ = next;
  ++steps_;
}

bool SceneRun::bring_cuts_to(double time) {
  if (next_cut_update_.valid()) {
    const double started_for = next_cut_update_time_;
    const CutUpdate done = next_cut_update_.get();  // rethrows the update's exception
    if (started_for == time) {
      timings_["enrichment"].add(done.ms);
      cut_update_team_->record(omp_get_max_threads(), done.ms, beside_update_ms_);
      return done.changed;
    }
  }
  ScopedStage stage(timings_, "enrichment");
  return cuts_->update(time);
}

void SceneRun::start_next_cut_update(double time) {
  // Not past the scene's last step, and not where this thread has one OpenMP thread only
  // (a batch of scenes with a thread each, or a 1-thread measurement). Not beside the first
  // step either: its first projection and shell step touch their memory for the first
  // time, and an update beside them made chad's first step 43 -> 58 ms. Nor once every cut
  // is complete: the update would change nothing (the static cuts of the accordion and
  // fracture from the start), and its thread would only hold the step's loops to one thread.
  if (!options_.overlap_cut_updates || steps_ == 0 || steps_ + 1 >= scene_.analysis.steps ||
      omp_get_max_threads() < 2 || cuts_->complete())
    return;
  next_cut_update_time_ = time;
  const int team = cut_update_team_->size(omp_get_max_threads());
  cut_update_threads_.store(team, std::memory_order_release);
  next_cut_update_started_ = std::chrono::steady_clock::now();
  try {
    next_cut_update_ = std::async(std::launch::async, [this, time, team] {
      omp_set_num_threads(team);  // the shell step has the other threads
      struct Done {
        std::atomic<int>& threads;
        ~Done() { threads.store(0, std::memory_order_release); }
      } done_with_the_thread{cut_update_threads_};
      const auto start = std::chrono::steady_clock::now();
      CutUpdate done;
      done.changed = cuts_->update(time);
      done.ms = ms_since(start);
      return done;
    });
    last_cut_update_threads_ = team;
  } catch (const std::system_error&) {
    // No thread to be had: the next step updates the cuts itself.
    cut_update_threads_.store(0, std::memory_order_release);
  }
}

void SceneRun::discard_next_cut_update() noexcept {
  if (!next_cut_update_.valid()) return;
  next_cut_update_.wait();
  next_cut_update_ = {};
}

void SceneRun::change_basis(std::vector<EnrichmentFunction> functions, int edge_resolution,
                            std::vector<char> edge_flags) {
  ScopedStage stage(timings_, "projection");
  // The new model is a copy with the new functions (set_enrichments rebuilds everything
  // that depends on them); the old one stays alive for the projection.
  auto next = std::make_unique<ShellModel>(*model_);
  next->set_cut_edge_texels(edge_resolution, std::move(edge_flags));
  // The new basis's values at its quadrature points: for this projection's moments, and kept
  // for the next one, which reads them where the two bases share points.
  next->keep_basis_values();
  next->set_enrichments(std::move(functions));
  std::vector<char> fixed = detail::fixed_dofs_of_valid_scene(scene_, *next);
  std::vector<double> force = detail::external_force_of_valid_scene(scene_, *next);
  auto simulation = std::make_unique<ShellSimulation>(*next, std::move(fixed), std::move(force));
  ProjectedState projected = project_onto_basis(*model_, simulation_->displacement(), simulation_->velocity(), *next,
                                                simulation->system());
  // Once an element-local preconditioner has failed (its matrix not positive definite, or
  // too weak), the next bases, much like this one, get the whole pattern from the start
  // instead of wasting an element-local factorisation each (chad and the slinky fell back
  // at most of their basis changes before they were found too small for it).
  FactorReuseOptions solver = options_.solver;
  if (solver_statistics().element_local_fallbacks > 0) solver.preconditioner_pattern = PreconditionerPattern::full;
  simulation->set_solver_options(solver);
  simulation->set_state(std::move(projected.displacement), std::move(projected.velocity));
  merge(timings_, simulation_->timings());
  replaced_solver_statistics_ = replaced_solver_statistics_ + simulation_->solver_statistics();
  simulation_ = std::move(simulation);  // before model_: the old simulation refers to it
  model_ = std::move(next);
  ++basis_changes_;
}

StageTimings SceneRun::timings() const {
  StageTimings all = timings_;
  merge(all, simulation_->timings());
  return all;
}

FactorReuseStatistics SceneRun::solver_statistics() const {
  return replaced_solver_statistics_ + simulation_->solver_statistics();
}

ShellState SceneRun::state() const {
  ShellState state;
  state.mesh = mesh_;
  const std::vector<double>& u = simulation_->displacement();
  state.displacement.assign(u.begin(), u.begin() + 3 * mesh_.num_nodes());
  state.time = time_;
  const int npe = mesh_.nodes_per_element();
  const auto& functions = model_->enrichments();
  for (int i = 0; i < static_cast<int>(functions.size()); ++i)
    for (const ElementTexture& texture : functions[i].elements) {
      ElementEnrichment e;
      e.element = texture.element;
      e.resolution = texture.tile.width;
      e.values.assign(texture.tile.values.begin(), texture.tile.values.end());
      e.node_values.assign(npe, 0.0f);
      e.dofs.assign(3 * npe, 0.0);
      for (int a = 0; a < npe; ++a) {
        double shift = 0;
        const int v = model_->enrichment_dofs(i, mesh_.element_nodes(texture.element)[a], &shift);
        if (v < 0) continue;  // node not enriched by this function: its DOFs are zero
        e.node_values[a] = static_cast<float>(shift);
        for (int c = 0; c < 3; ++c) e.dofs[3 * a + c] = u[3 * v + c];
      }
      state.enrichments.push_back(std::move(e));
    }
  return state;
}

}  // namespace dgtex

#pragma once
// One simulation of a scene from start to end, the way `dgtex run` (and the scene
// benchmarks) drive it: the mesh and shell model, the cuts and their enrichment functions
// (dgtex/cut_manager.h), the creases' functions (dgtex/crease_enrichment.h), and the
// solver state, advanced step by step.
//
// Each dynamic step first brings the cuts to the step's end time; when the enrichment
// functions change, the model takes the new basis and displacement and velocity are
// projected onto it (dgtex/basis_projection.h), then the shell steps. Stages timed per
// step: "enrichment" (cut update and Laplace solves), "projection" (only steps where the
// basis changed), "assembly" and "solve" (dgtex/shell_simulation.h). Each basis gets its
// own simulation; once one has given up its element-local preconditioner, the later ones
// start with the whole pattern (dgtex/factor_reusing_solver.h).
//
// Overlapped cut updates (SceneRunOptions::overlap_cut_updates, the default): the cuts
// follow their schedule, not the shell, so the next step's cut update can run while this
// step projects and steps the shell. It runs on a thread of its own beside this step's
// OpenMP work, and step() returns once both are done. Why: much of a
// cut scene's step runs on one thread (the multigrid's small levels, the texel Laplace's
// set-up, the model rebuild), so the other core was idle (chad, 30 steps on 2 cores:
// 27-29 -> 33-36 steps/s; examples/bench_scenes_history.md, session 13). Only where the
// calling thread has more than one OpenMP thread, from the second step on, while another
// step of the scene (analysis.steps) follows, while some cut has still to grow
// (CutManager::complete), and where a thread can be started (else the plain order). While
// the update runs with a team of its own (one thread on two; on more, balanced step by step
// against the step's own work: runtime/cut_update_team.h), this step's parallel loops take
// that many threads fewer (dgtex/kernels/threads_busy_beside.h). The results
// are bitwise those of the plain order (every kernel's result is independent of the thread
// count). Stage times then overlap: "enrichment" is the update's own wall time, counted in
// the step that uses it, and the other stages include the slowdown of sharing the cores.
// Run programs that link the library with OMP_WAIT_POLICY=passive (the `dgtex` tool sets it
// itself): under libgomp's default the step's idle OpenMP worker spins for milliseconds after
// each parallel loop, on the core the update needs (spiral1, 2 cores: the update's multigrid
// set-up took 5.9-6.5 ms a step spinning, 3.5-4.0 ms passive).
// Not thread-safe; each call uses all OpenMP threads itself (but the update's, above).
// SceneRun owns a copy of the Scene and the mesh, topology, model, cut manager and
// simulation built from it. Units: those of the scene (SI: m, kg, s, N).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "dgtex/cut_manager.h"
#include "dgtex/mesh.h"
#include "dgtex/scene.h"
#include "dgtex/shell_model.h"
#include "dgtex/shell_simulation.h"
#include "dgtex/shell_state.h"
#include "dgtex/stage_timer.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"

namespace dgtex {

namespace detail {
class CutUpdateTeam;
}

struct SceneRunOptions {
  bool overlap_cut_updates = true;  // the next step's cut update beside this step (above)
  // OpenMP threads of that update: 0 balances them step by step (above); n > 0 fixes n (at
  // most the step's threads less one). Results do not depend on it.
  int cut_update_threads = 0;
  // Called once in the set-up of a scene with cuts or creases, after the memory check has
  // passed and before any texel field is allocated, with the fields counted and the memory
  // available (-1: unknown); `dgtex run` prints texel_memory_caution from it.
  std::function<void(const TexelFields& fields, std::int64_t available_bytes)> before_texel_fields;
  // Then (after before_texel_fields) fault in the memory the first steps will take
  // (reserve_step_memory(step_memory_bytes(fields, available)), dgtex/step_memory.h):
  // process-wide malloc settings (made first thing in the set-up, prepare_step_memory, so
  // that the threads tracing the cuts share the heap reserved later), and a set-up longer by
  // ~1.4 us a reserved 4 KiB page (chad: 96 MiB, 33-36 ms more), for first steps without
  // first-touch page faults. Memory that cannot be had is left out (the steps then take
  // theirs as they go).
  bool reserve_step_memory = false;
  // The corotated step solver's options (dgtex/factor_reusing_solver.h), for the simulation
  // of every basis; once one has given up its element-local preconditioner, the later ones
  // take the whole pattern whatever these say.
  FactorReuseOptions solver;
};

class SceneRun {
 public:
  // Builds everything and brings the cuts to time 0. The run keeps a copy of `scene`
  // (SceneRun(load_scene(path)) is fine). A scene built in code is checked as a scene file
  // is (validate_scene).
  // Throws MeshError / SceneError (bad mesh or scene; also cuts and creases whose texel
  // fields cannot fit in the memory available, dgtex/texel_memory_estimate.h),
  // std::invalid_argument (a cut or crease the mesh cannot take, naming cuts[i] or
  // creases[i]; SceneRunOptions out of range: cut_update_threads < 0, solver options
  // FactorReusingSolver::set_options refuses; a malformed DGTEX_MEMORY_LIMIT_MB with cuts or
  // creases), ModelError (statically unconstrained model).
  explicit SceneRun(const Scene& scene, SceneRunOptions options = {});
  ~SceneRun();

  // Static analysis: solve K u = f with the current basis (the cuts at time 0 before any
  // step); it replaces the displacement. A dynamic scene is not refused (its loads' static
  // equilibrium). Throws what ShellSimulation::solve_static throws.
  void solve_static();
  // One dynamic step of the scene's time step; std::logic_error for a static scene, and
  // after a step that threw (its cut manager may have moved on without the new basis: a
  // retry went on with the old one). A failing step throws what the shell step
  // (ShellSimulation::step: ModelError, std::runtime_error) or the cut update
  // (CutManager::update) threw, std::bad_alloc when memory runs out; only a new SceneRun
  // can go on after it.
  void step();

  // The model and simulation of the current basis, and the displacement below: valid until
  // the next step(), since a step that changes the basis replaces them (hold none across it).
  const Mesh& mesh() const { return mesh_; }
  const ShellModel& model() const { return *model_; }
  const ShellSimulation& simulation() const { return *simulation_; }
  // Null without cuts. With overlapped cut updates it may already be at the next step's
  // end time (not after the scene's last step).
  const CutManager* cuts() const { return cuts_.get(); }
  double time() const { return time_; }
  int steps_taken() const { return steps_; }
  int basis_changes() const { return basis_changes_; }
  // Bytes its set-up reserved for the first steps (SceneRunOptions::reserve_step_memory);
  // 0 when it reserved none.
  std::int64_t reserved_step_memory_bytes() const { return reserved_step_memory_bytes_; }
  // OpenMP threads of the cut update that ran beside the last step (0: none ran beside it).
  int last_cut_update_threads() const { return last_cut_update_threads_; }
  // All stages so far (those of replaced simulations included).
  StageTimings timings() const;
  // The step solver's statistics so far, summed over the simulations of every basis (the
  // last_* fields: the latest solve's).
  FactorReuseStatistics solver_statistics() const;
  // The state for rendering and export: mesh, nodal displacement and, per enrichment
  // function and element of its Omega_i, the texture, node shifts and DOFs.
  ShellState state() const;
  // Displacement (standard and enriched DOFs), #dofs; the velocity is simulation().velocity().
  const std::vector<double>& displacement() const { return simulation_->displacement(); }

 private:
  // The result of one cut update.
  struct CutUpdate {
    bool changed = false;
    double ms = 0;  // its wall time
  };
  // The cut manager at `time`: the overlapped update started by the previous step, or now.
  bool bring_cuts_to(double time);
  // Starts the update to `time` beside the caller, where options_ and the scene allow.
  void start_next_cut_update(double time);
  // Waits for an update in flight and forgets it (the next step updates afresh).
  void discard_next_cut_update() noexcept;
  // The model takes the given functions and cut mesh-edge texels; the state is projected.
  void change_basis(std::vector<EnrichmentFunction> functions, int edge_resolution, std::vector<char> edge_flags);
  // The cuts' current functions followed by the creases' (fixed) ones.
  std::vector<EnrichmentFunction> enrichment_functions() const;

  const Scene scene_;
  Mesh mesh_;
  Topology topology_;  // the cut manager refers to it
  std::unique_ptr<ShellModel> model_;
  std::unique_ptr<CutManager> cuts_;
  std::vector<EnrichmentFunction> creases_;  // one per scene crease (crease_enrichment.h)
  std::unique_ptr<ShellSimulation> simulation_;
  DynamicsOptions dynamics_;
  StageTimings timings_;  // own stages and those of replaced simulations
  FactorReuseStatistics replaced_solver_statistics_;  // summed over replaced simulations
  double time_ = 0;
  int steps_ = 0;
  int basis_changes_ = 0;
  std::string failed_step_;  // what a step that threw said; the run cannot go on after it
  std::int64_t reserved_step_memory_bytes_ = 0;
  SceneRunOptions options_;
  // The next step's cut update while it runs beside a step (after cuts_: it refers to it,
  // so it is destroyed, i.e. waited for, first).
  std::future<CutUpdate> next_cut_update_;
  // Threads that update holds while it runs: the step's parallel loops leave them out
  // (kernels/threads_busy_beside.h).
  std::atomic<int> cut_update_threads_{0};
  double next_cut_update_time_ = 0;
  // The update's team, balanced against the step's own work beside it (runtime/
  // cut_update_team.h), and when it started and how long the step's own work took beside it.
  std::unique_ptr<detail::CutUpdateTeam> cut_update_team_;
  std::chrono::steady_clock::time_point next_cut_update_started_;
  double beside_update_ms_ = 0;
  int last_cut_update_threads_ = 0;
};

}  // namespace dgtex

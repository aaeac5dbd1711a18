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
// basis changed), "assembly" and "solve" (dgtex/shell_simulation.h).
// Not thread-safe; each call uses all OpenMP threads itself.
// SceneRun owns the mesh, topology, model, cut manager and simulation; it keeps a reference
// to the Scene (which must outlive it). Units: those of the scene (SI: m, kg, s, N).
#include <memory>
#include <vector>

#include "dgtex/cut_manager.h"
#include "dgtex/mesh.h"
#include "dgtex/scene.h"
#include "dgtex/shell_model.h"
#include "dgtex/shell_simulation.h"
#include "dgtex/shell_state.h"
#include "dgtex/stage_timer.h"
#include "dgtex/topology.h"

namespace dgtex {

class SceneRun {
 public:
  // Builds everything and brings the cuts to time 0; `scene` must outlive the run.
  // Throws MeshError / SceneError (bad mesh or scene), std::invalid_argument (a cut the
  // mesh cannot take, naming cuts[i]), ModelError (statically unconstrained model).
  explicit SceneRun(const Scene& scene);
  ~SceneRun();

  // Static analysis: solve K u = f with the cuts present at time 0.
  void solve_static();
  // One dynamic step of the scene's time step.
  void step();

  const Mesh& mesh() const { return mesh_; }
  const ShellModel& model() const { return *model_; }
  const ShellSimulation& simulation() const { return *simulation_; }
  const CutManager* cuts() const { return cuts_.get(); }  // null without cuts
  double time() const { return time_; }
  int steps_taken() const { return steps_; }
  int basis_changes() const { return basis_changes_; }
  // All stages so far (those of replaced simulations included).
  StageTimings timings() const;
  // The state for rendering and export: mesh, nodal displacement and, per enrichment
  // function and element of its Omega_i, the texture, node shifts and DOFs.
  ShellState state() const;
  // Displacement (standard and enriched DOFs) and velocity, #dofs each.
  const std::vector<double>& displacement() const { return simulation_->displacement(); }

 private:
  void change_basis();
  // The cuts' current functions followed by the creases' (fixed) ones.
  std::vector<EnrichmentFunction> enrichment_functions() const;

  const Scene& scene_;
  Mesh mesh_;
  Topology topology_;  // the cut manager refers to it
  std::unique_ptr<ShellModel> model_;
  std::unique_ptr<CutManager> cuts_;
  std::vector<EnrichmentFunction> creases_;  // one per scene crease (crease_enrichment.h)
  std::unique_ptr<ShellSimulation> simulation_;
  DynamicsOptions dynamics_;
  StageTimings timings_;  // own stages and those of replaced simulations
  double time_ = 0;
  int steps_ = 0;
  int basis_changes_ = 0;
};

}  // namespace dgtex

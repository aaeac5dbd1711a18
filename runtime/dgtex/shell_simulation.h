#pragma once
// Static and dynamic solution of a ShellModel with zero-displacement constraints.
//  - static:  K u = f (linear).
//  - dynamic: semi-implicit Euler (thesis eq. 4.12) with Rayleigh damping D = a M + b K:
//      (M + dt D + dt^2 K) v+ = M v + dt (f - K u),   u+ = u + dt v+,
//    optionally corotated per quadrature point (K -> R K R^T, f += R K (I - R^T) X0).
// The CHOLMOD analysis is reused while the pattern is unchanged; a linear dynamic run
// factorises once. A corotated run solves each step by conjugate gradients preconditioned
// with the factor of an earlier step's matrix and refactorises only when that slows down
// (FactorReusingSolver: same relative-residual bound as a direct solve, see there);
// reuse_factorization = false factorises every step instead (the reference path).
// Every stage's time is recorded ("assembly", "solve").
// ShellSimulation owns its state (u, v), free-DOF system and Cholesky factor and keeps a
// reference to the ShellModel (which must outlive it). Not thread-safe; each call uses all
// OpenMP threads. Simulations sharing one ShellModel must not run at the same time either,
// const calls (the energies) included: the assembly writes the model's scratch buffers.
// Units: those of the model (SI: m, m/s, s, N, kg).
#include <cstdint>
#include <string>
#include <vector>

#include "dgtex/factor_reusing_solver.h"
#include "dgtex/free_dof_system.h"
#include "dgtex/shell_model.h"
#include "dgtex/sparse_cholesky.h"
#include "dgtex/stage_timer.h"

namespace dgtex {

struct DynamicsOptions {
  double time_step = 1e-3;  // in the model's time unit (SI: s)
  bool corotational = false;
  double mass_damping = 0;       // a in D = a M + b K, per unit time (SI: 1/s)
  double stiffness_damping = 0;  // b, a time (SI: s)
  bool reuse_factorization = true;  // corotated: PCG with a lagged factor (see above)
};

class ShellSimulation {
 public:
  // fixed: #dofs flags; external_force: #dofs, finite (std::invalid_argument otherwise).
  // set_state, check_statically_constrained, solve_static, step and the energies throw
  // std::logic_error once the model's basis or material textures changed
  // (ShellModel::revision): build a new simulation for the new DOFs. The accessors then
  // still return the old basis's data.
  ShellSimulation(const ShellModel& model, std::vector<char> fixed, std::vector<double> external_force);
  // The model is kept by reference: a temporary one would dangle, a const one too.
  ShellSimulation(ShellModel&&, std::vector<char>, std::vector<double>) = delete;
  ShellSimulation(const ShellModel&&, std::vector<char>, std::vector<double>) = delete;

  // Throws ModelError naming a free rigid-body mode of the whole mesh if the constraints
  // (fixed DOFs, and clamped edges, which hold their normals) leave one. Geometric: it
  // assembles nothing.
  void check_statically_constrained();
  // Throws ModelError "stiffness not positive definite (penalty too low?)" when K is not,
  // and "singular to working precision" when a pivot is below 1e-12 of its diagonal entry
  // (a mechanism that rounding left positive, e.g. a piece a cut leaves hanging on a node).
  void solve_static();
  // std::invalid_argument unless options.time_step is positive and finite and the damping
  // coefficients finite and >= 0. A failed step throws ModelError when the step matrix is
  // not positive definite at rest (penalty too low), std::runtime_error when a corotated
  // step fails away from rest (its matrix not positive definite, a right-hand side that is
  // not finite, or no convergence even with a fresh factor: the run has likely diverged).
  // A step that throws leaves displacement, velocity and time as they were, so it may be
  // retried (a smaller time step); the steps after it then agree with a run that never
  // failed bitwise without reuse_factorization, and to within the solver's tolerance with
  // it (the failure may have replaced the reused factor).
  void step(const DynamicsOptions& options);

  const std::vector<double>& displacement() const { return u_; }
  const std::vector<double>& velocity() const { return v_; }
  // #dofs each, finite, else std::invalid_argument. The DOFs of the model's dependent nodes
  // (ShellModel::dependent_nodes, exact ties) are set from their sources.
  void set_state(std::vector<double> u, std::vector<double> v);
  double time() const { return time_; }
  const StageTimings& timings() const { return timings_; }
  const FreeDofSystem& system() const { return system_; }
  // Non-zeros of the factor in use: the PCG preconditioner's when it is element-local.
  std::int64_t factor_nonzeros() const {
    return solver_.element_local() && solver_.element_local_factor_nonzeros() > 0 ? solver_.element_local_factor_nonzeros()
                                                                                   : cholesky_.factor_nonzeros();
  }
  // Solver of the corotated steps: its tolerance and refactorisation policy, and counts.
  void set_solver_options(const FactorReuseOptions& options);
  const FactorReuseStatistics& solver_statistics() const { return solver_.statistics(); }
  // How far the element-local preconditioner is from the step matrix, once judged
  // (FactorReusingSolver::element_local_dropped_radius; NaN before).
  double element_local_dropped_radius() const { return solver_.element_local_dropped_radius(); }

  double kinetic_energy() const;
  double linear_elastic_energy() const;  // 1/2 u^T K u with the linear K

 private:
  // guess_ (and k_guess_ sized): the PCG's initial guess for the next velocity.
  void extrapolate_initial_guess();

  void check_model_unchanged(const char* function) const;

  const ShellModel& model_;
  std::uint64_t model_revision_;  // the model's revision() when this simulation was built
  std::vector<char> fixed_;
  std::vector<double> f_ext_;
  FreeDofSystem system_;
  SparseCholesky cholesky_;
  std::vector<double> u_, v_;
  double time_ = 0;
  StageTimings timings_;
  std::vector<double> linear_k_;  // cached linear stiffness blocks
  double factorised_dt_ = -1;     // linear dynamics: the dt whose matrix is factorised
  FactorReusingSolver solver_;
  // Buffers reused by every step (no allocation per step).
  std::vector<double> current_, corotated_k_, corrective_, mv_, ku_, rhs_full_, rhs_, v_new_, values_;
  std::vector<double> previous_v_, previous_previous_v_, guess_;  // velocities of the steps before, PCG start
  std::vector<double> k_guess_;             // K guess_
  std::vector<double> spread_pair_;         // u_ and guess_ spread for the fused products

  const std::vector<double>& linear_stiffness();
  std::string enrichment_hint(bool static_analysis) const;  // appended to "not positive definite" errors
  // Where a column of the factorised system lies: its node, component and elements.
  std::string unknown_location(int column) const;
  // Throws ModelError when a pivot of the static factor is rounding (a mechanism).
  void check_no_mechanism(const std::vector<double>& values) const;
};

}  // namespace dgtex

#pragma once
// Static and dynamic solution of a ShellModel with zero-displacement constraints.
//  - static:  K u = f (linear).
//  - dynamic: semi-implicit Euler (thesis eq. 4.12) with Rayleigh damping D = a M + b K:
//      (M + dt D + dt^2 K) v+ = M v + dt (f - K u),   u+ = u + dt v+,
//    optionally corotated per quadrature point (K -> R K R^T, f += R K (I - R^T) X0).
// The CHOLMOD analysis is reused while the pattern is unchanged; a linear dynamic run
// factorises once. Every stage's time is recorded ("assembly", "solve").
#include <vector>

#include "dgtex/free_dof_system.h"
#include "dgtex/shell_model.h"
#include "dgtex/sparse_cholesky.h"
#include "dgtex/stage_timer.h"

namespace dgtex {

struct DynamicsOptions {
  double time_step = 1e-3;
  bool corotational = false;
  double mass_damping = 0;       // a in D = a M + b K
  double stiffness_damping = 0;  // b
};

class ShellSimulation {
 public:
  // fixed: #dofs flags; external_force: #dofs.
  ShellSimulation(const ShellModel& model, std::vector<char> fixed, std::vector<double> external_force);

  // Throws ModelError naming a free rigid-body mode if the constraints (fixed DOFs and
  // clamped edges) leave one.
  void check_statically_constrained() const;
  // Throws ModelError "stiffness not positive definite (penalty too low?)" when K is not.
  void solve_static();
  void step(const DynamicsOptions& options);

  const std::vector<double>& displacement() const { return u_; }
  const std::vector<double>& velocity() const { return v_; }
  void set_state(std::vector<double> u, std::vector<double> v);
  double time() const { return time_; }
  const StageTimings& timings() const { return timings_; }
  const FreeDofSystem& system() const { return system_; }
  std::int64_t factor_nonzeros() const { return cholesky_.factor_nonzeros(); }

  double kinetic_energy() const;
  double linear_elastic_energy() const;  // 1/2 u^T K u with the linear K

 private:
  const ShellModel& model_;
  std::vector<char> fixed_;
  std::vector<double> f_ext_;
  FreeDofSystem system_;
  SparseCholesky cholesky_;
  std::vector<double> u_, v_;
  double time_ = 0;
  StageTimings timings_;
  std::vector<double> linear_k_;  // cached linear stiffness blocks
  double factorised_dt_ = -1;     // linear dynamics: the dt whose matrix is factorised

  const std::vector<double>& linear_stiffness();
};

}  // namespace dgtex

#pragma once
// Carrying a state across a change of the enriched basis (a cut advanced, a new cut
// segment started). The thesis swaps the enrichment functions between steps and keeps the
// DOF values, which makes the shell pop (§5.7 names it as a limitation); dgtex instead
// projects displacement and velocity onto the new basis in the mass-matrix (L2) norm:
//   M_new x_new = int rho h N_new (field of x_old) dA,
// with the fixed DOFs of the new basis held at zero. A field the new basis can represent
// (e.g. one that was already in the old one where nothing changed) is kept exactly, and
// the kinetic energy never grows: the projection is orthogonal in the M inner product.
// Pure function: reads the models and the old state, returns the new state (keeps
// nothing). Units: those of the model (SI: m, m/s).
#include <vector>

#include "dgtex/free_dof_system.h"
#include "dgtex/shell_model.h"

namespace dgtex {

struct ProjectedState {
  std::vector<double> displacement;  // #dofs of the new model
  std::vector<double> velocity;
};

// old_* are #dofs vectors of old_model (old_velocity may be empty: at rest); fixed flags
// the new model's held DOFs (#dofs of new_model). Both models share the mesh. Throws
// std::invalid_argument for other sizes (naming the argument), NotPositiveDefinite if the
// new mass matrix is singular on the free DOFs (an enriched function with no support).
ProjectedState project_onto_basis(const ShellModel& old_model, const std::vector<double>& old_displacement,
                                  const std::vector<double>& old_velocity, const ShellModel& new_model,
                                  const std::vector<char>& fixed);
// The same with the new model's free-DOF system already built (new_model.pattern() without
// the held DOFs, as a ShellSimulation of the new model holds it: system()), which it
// would otherwise build again.
ProjectedState project_onto_basis(const ShellModel& old_model, const std::vector<double>& old_displacement,
                                  const std::vector<double>& old_velocity, const ShellModel& new_model,
                                  const FreeDofSystem& new_system);

}  // namespace dgtex

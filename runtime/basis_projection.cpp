#include "dgtex/basis_projection.h"

#include "dgtex/free_dof_system.h"
#include "dgtex/sparse_cholesky.h"
#include "api_argument_checks.h"

namespace dgtex {

ProjectedState project_onto_basis(const ShellModel& old_model, const std::vector<double>& old_displacement,
                                  const std::vector<double>& old_velocity, const ShellModel& new_model,
                                  const std::vector<char>& fixed) {
  detail::check_size("project_onto_basis", "fixed", fixed.size(), "new_model.num_dofs()", new_model.num_dofs());
  return project_onto_basis(old_model, old_displacement, old_velocity, new_model,
                            FreeDofSystem(new_model.pattern(), fixed, nullptr, &new_model.dependent_nodes()));
}

ProjectedState project_onto_basis(const ShellModel& old_model, const std::vector<double>& old_displacement,
                                  const std::vector<double>& old_velocity, const ShellModel& new_model,
                                  const FreeDofSystem& new_system) {
  const char* function = "project_onto_basis";
  detail::check_size(function, "old_displacement", old_displacement.size(), "old_model.num_dofs()",
                     old_model.num_dofs());
  if (!old_velocity.empty())
    detail::check_size(function, "old_velocity", old_velocity.size(), "old_model.num_dofs()", old_model.num_dofs());
  detail::check_size(function, "new_system.num_dofs()", new_system.num_dofs(), "new_model.num_dofs()",
                     new_model.num_dofs());
  std::vector<double> values;
  new_system.gather(new_model.mass_blocks().data(), 1.0, nullptr, 0.0, values);
  SparseCholesky mass;
  mass.analyze(new_system.size(), new_system.column_start(), new_system.row_index());
  mass.factorize(values);

  // Moments of displacement and velocity in one pass over the quadrature points.
  std::vector<const std::vector<double>*> fields = {&old_displacement};
  if (!old_velocity.empty()) fields.push_back(&old_velocity);
  const std::vector<std::vector<double>> moments = new_model.moments_of_fields(old_model, fields);
  auto project = [&](const std::vector<double>& moment) {
    std::vector<double> rhs, reduced, solution;
    new_system.restrict_vector(moment, rhs);
    mass.solve(rhs, reduced);
    new_system.expand_vector(reduced, solution);
    return solution;
  };
  ProjectedState state;
  state.displacement = project(moments[0]);
  state.velocity = old_velocity.empty() ? std::vector<double>(new_model.num_dofs(), 0.0) : project(moments[1]);
  return state;
}

}  // namespace dgtex

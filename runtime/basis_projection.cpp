#include "dgtex/basis_projection.h"

#include "dgtex/free_dof_system.h"
#include "dgtex/sparse_cholesky.h"

namespace dgtex {

namespace {

std::vector<double> moments_of(const ShellModel& old_model, const std::vector<double>& values,
                               const ShellModel& new_model) {
  return new_model.mass_weighted_moments([&](int element, const double xi[2], double out[3]) {
    old_model.interpolate(values, element, xi, out);
  });
}

}  // namespace

ProjectedState project_onto_basis(const ShellModel& old_model, const std::vector<double>& old_displacement,
                                  const std::vector<double>& old_velocity, const ShellModel& new_model,
                                  const std::vector<char>& fixed) {
  const FreeDofSystem system(new_model.pattern(), fixed);
  std::vector<double> values;
  system.gather(new_model.mass_blocks().data(), 1.0, nullptr, 0.0, values);
  SparseCholesky mass;
  mass.analyze(system.size(), system.column_start(), system.row_index());
  mass.factorize(values);

  auto project = [&](const std::vector<double>& old_values) {
    std::vector<double> rhs, reduced, solution;
    system.restrict_vector(moments_of(old_model, old_values, new_model), rhs);
    mass.solve(rhs, reduced);
    system.expand_vector(reduced, solution);
    return solution;
  };
  ProjectedState state;
  state.displacement = project(old_displacement);
  state.velocity = old_velocity.empty() ? std::vector<double>(new_model.num_dofs(), 0.0) : project(old_velocity);
  return state;
}

}  // namespace dgtex

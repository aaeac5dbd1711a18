#pragma once
// The unit square plate under a uniform load q = -1 on n x n elements, held on all four
// sides (clamped, or simply supported), solved statically: the centre deflection that the
// plate tests compare with Timoshenko and Navier, and the failure-mode tests with itself.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dgtex/shell_simulation.h"
#include "shell_test_support.h"

namespace dgtex::testing_support {

inline double square_plate_centre_deflection(ElementType type, int n, double penalty, bool clamped,
                                             const Material& m = {}) {
  const double a = 1.0;
  const Mesh mesh = make_rectangle(a, a, n, n, type);
  auto on_boundary = [a](const double* x) {
    return std::abs(x[0]) < 1e-9 || std::abs(x[0] - a) < 1e-9 || std::abs(x[1]) < 1e-9 || std::abs(x[1] - a) < 1e-9;
  };
  auto model = make_model(mesh, m, penalty, clamped ? NodePredicate(on_boundary) : nullptr);
  std::vector<char> fixed;
  fix_nodes(mesh, on_boundary, true, true, true, fixed);
  std::vector<double> f(model->num_dofs(), 0.0);
  const double force[3] = {0, 0, -1.0};
  model->add_area_force(force, f);
  ShellSimulation sim(*model, fixed, f);
  sim.solve_static();
  // The generator's centre node (even divisions) sits at (a/2, a/2).
  for (int k = 0; k < mesh.num_nodes(); ++k)
    if (std::abs(mesh.node(k)[0] - a / 2) < 1e-9 && std::abs(mesh.node(k)[1] - a / 2) < 1e-9)
      return sim.displacement()[3 * k + 2];
  ADD_FAILURE() << "no centre node";
  return 0;
}

}  // namespace dgtex::testing_support

// Dynamics of the DG shell: free fall, corotation under rigid rotation, and the energy
// dissipation of the semi-implicit Euler integrator.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "dgtex/shell_simulation.h"
#include "shell_test_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

TEST(Dynamics, UnconstrainedShellFallsWithGravity) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_cylinder(0.5, 1.0, -45, 45, 3, 2, type);
    auto model = make_model(mesh, Material{}, 1.0);
    std::vector<double> f(model->num_dofs(), 0.0);
    const double g[3] = {0, 0, -9.81};
    model->add_gravity(g, f);
    ShellSimulation sim(*model, std::vector<char>(model->num_dofs(), 0), f);
    // The corotated steps are solved by PCG to a relative residual: set it far below the
    // 1e-9 asserted here, so that the assertion tests the dynamics, not the solver's bound.
    FactorReuseOptions solver;
    solver.relative_tolerance = 1e-13;
    sim.set_solver_options(solver);
    DynamicsOptions options;
    options.time_step = 1e-3;
    for (bool corotational : {false, true}) {
      options.corotational = corotational;
      sim.set_state(std::vector<double>(model->num_dofs(), 0.0), std::vector<double>(model->num_dofs(), 0.0));
      const int steps = 20;
      for (int s = 0; s < steps; ++s) sim.step(options);
      // Every node moves with the same velocity g t: a rigid translation has no strain.
      for (int n = 0; n < mesh.num_nodes(); ++n) {
        EXPECT_NEAR(sim.velocity()[3 * n + 2], -9.81 * steps * options.time_step, 1e-9);
        EXPECT_NEAR(sim.velocity()[3 * n + 0], 0.0, 1e-9);
      }
    }
  }
}

TEST(Dynamics, CorotationGivesNoForceUnderRigidRotation) {
  const Mesh mesh = make_rectangle(1, 0.5, 4, 2, ElementType::quad8);
  auto model = make_model(mesh, Material{}, 1.0, [](const double* x) { return x[0] < 1e-9; });
  const double angle = 1.0;  // radians, about the y axis through the origin
  const double c = std::cos(angle), s = std::sin(angle);
  std::vector<double> current(mesh.positions), u(model->num_dofs());
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double* x = mesh.node(n);
    current[3 * n + 0] = c * x[0] + s * x[2];
    current[3 * n + 2] = -s * x[0] + c * x[2];
    for (int k = 0; k < 3; ++k) u[3 * n + k] = current[3 * n + k] - x[k];
  }
  auto elastic_force = [&](bool corotational) {
    std::vector<double> K, corrective, Ku(model->num_dofs());
    model->assemble_stiffness(corotational ? current.data() : nullptr, K, &corrective);
    block_multiply(model->pattern(), K.data(), u.data(), Ku.data());
    double worst = 0, kmax = 0;
    for (int d = 0; d < model->num_dofs(); ++d) worst = std::max(worst, std::abs(Ku[d] - corrective[d]));
    for (double v : K) kmax = std::max(kmax, std::abs(v));
    return worst / kmax;  // force relative to the stiffness scale (u is O(1))
  };
  const double corotated = elastic_force(true), linear = elastic_force(false);
  std::printf("rigid rotation by 1 rad: |f| / max|K| corotated %.3e, linear %.3e\n", corotated, linear);
  EXPECT_LT(corotated, 1e-12);
  EXPECT_GT(linear, 1e-2);
}

TEST(Dynamics, FreeVibrationLosesEnergyAsTheIntegratorPredicts) {
  // Lowest mode of a clamped strip: M- and K-orthogonality decouple it, so the discrete
  // system follows the scalar recurrence of semi-implicit Euler for x'' = -w^2 x:
  //   v+ = (v - dt w^2 x) / (1 + dt^2 w^2),  x+ = x + dt v+,
  // whose energy decays by a factor between 1/(1 + w^2 dt^2) and 1 per step.
  const Mesh mesh = make_rectangle(1, 0.2, 4, 1, ElementType::quad8);
  Material m;
  auto at_root = [](const double* x) { return x[0] < 1e-9; };
  auto model = make_model(mesh, m, 1.0, at_root);
  std::vector<char> fixed;
  fix_nodes(mesh, at_root, true, true, true, fixed);
  ShellSimulation sim(*model, fixed, std::vector<double>(model->num_dofs(), 0.0));
  std::vector<double> K;
  model->assemble_stiffness(nullptr, K, nullptr);
  const int n = model->num_dofs();
  Eigen::MatrixXd Kd = Eigen::MatrixXd::Zero(n, n), Md = Eigen::MatrixXd::Zero(n, n);
  const BlockAssembly& p = model->pattern();
  for (int r = 0; r < p.num_nodes(); ++r)
    for (std::int64_t k = p.row_start()[r]; k < p.row_start()[r + 1]; ++k)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          Kd(3 * r + i, 3 * p.column()[k] + j) = K[k * 9 + i * 3 + j];
          Md(3 * r + i, 3 * p.column()[k] + j) = model->mass_blocks()[k * 9 + i * 3 + j];
        }
  std::vector<int> free;
  for (int d = 0; d < n; ++d)
    if (!fixed[d]) free.push_back(d);
  Eigen::MatrixXd Kf(free.size(), free.size()), Mf(free.size(), free.size());
  for (size_t i = 0; i < free.size(); ++i)
    for (size_t j = 0; j < free.size(); ++j) Kf(i, j) = Kd(free[i], free[j]), Mf(i, j) = Md(free[i], free[j]);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kf, Mf);
  const double omega2 = eig.eigenvalues()(0);
  const Eigen::VectorXd mode = eig.eigenvectors().col(0);  // M-normalised
  std::vector<double> u(n, 0.0);
  const double amplitude = 1e-3;
  for (size_t i = 0; i < free.size(); ++i) u[free[i]] = amplitude * mode(i);
  sim.set_state(u, std::vector<double>(n, 0.0));

  DynamicsOptions options;
  const double period = 2 * M_PI / std::sqrt(omega2);
  options.time_step = period / 50;
  double x = amplitude, v = 0;
  const double a = options.time_step * options.time_step * omega2;
  for (int s = 0; s < 100; ++s) {
    const double before = sim.kinetic_energy() + sim.linear_elastic_energy();
    sim.step(options);
    v = (v - options.time_step * omega2 * x) / (1 + a);
    x += options.time_step * v;
    const double energy = sim.kinetic_energy() + sim.linear_elastic_energy();
    const double predicted = 0.5 * (v * v + omega2 * x * x);
    ASSERT_NEAR(energy / predicted, 1.0, 1e-8) << "step " << s;
    EXPECT_LE(energy, before * (1 + 1e-12));
    EXPECT_GE(energy, before / (1 + a) * (1 - 1e-12));
  }
  std::printf("free vibration: w^2 dt^2 = %.4f, energy after 2 periods %.4f of the initial (predicted %.4f)\n", a,
              (sim.kinetic_energy() + sim.linear_elastic_energy()) / (0.5 * omega2 * amplitude * amplitude),
              0.5 * (v * v + omega2 * x * x) / (0.5 * omega2 * amplitude * amplitude));
}

}  // namespace

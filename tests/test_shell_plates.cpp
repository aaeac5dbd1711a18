// Validation of the DG Kirchhoff-Love plate against classical solutions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/model_error.h"
#include "dgtex/shell_simulation.h"
#include "shell_test_support.h"
#include "square_plate_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

const double kPi = 3.14159265358979323846;

// Navier series for the centre deflection of a simply supported a x b plate under q.
double navier_centre_deflection(double a, double b, double q, double D) {
  double w = 0;
  for (int m = 1; m < 400; m += 2)
    for (int n = 1; n < 400; n += 2) {
      const double sign = ((m + n) / 2 - 1) % 2 == 0 ? 1.0 : -1.0;  // sin(m pi/2) sin(n pi/2)
      const double s = m * m / (a * a) + n * n / (b * b);
      w += sign / (m * n * s * s);
    }
  return 16 * q / (std::pow(kPi, 6) * D) * w;
}

struct PlateCase {
  ElementType type;
  const char* name;
};

class Plates : public ::testing::TestWithParam<PlateCase> {};

// Penalties about twice the definiteness threshold (0.35-0.4, see test_shell_definiteness):
// larger ones over-stiffen the plate (the C1 penalty locks quadratic elements).
double solve_plate(ElementType type, int n, bool clamped, double* D_out, double penalty) {
  const Material m;
  *D_out = kernels::bending_rigidity(m.E, m.nu, m.h);
  return square_plate_centre_deflection(type, n, penalty, clamped, m);
}

TEST_P(Plates, ClampedSquarePlateMatchesTimoshenko) {
  double D;
  // quad8 on 16x16 at eta 0.8; tri6 needs 24x24 at eta 0.6 for the same accuracy class.
  const bool quad = GetParam().type == ElementType::quad8;
  const int n = quad ? 16 : 24;
  const double w = solve_plate(GetParam().type, n, true, &D, quad ? 0.8 : 0.6);
  const double reference = -0.00126532 * 1.0 / D;  // Timoshenko: 0.00126 q a^4 / D (nu = 0.3)
  std::printf("clamped plate %s %dx%d: w = %.6e, reference %.6e, error %.3f%%\n", GetParam().name, n, n, w, reference,
              100 * std::abs(w / reference - 1));
  EXPECT_NEAR(w / reference, 1.0, quad ? 0.01 : 0.015);
}

TEST_P(Plates, SimplySupportedPlateConvergesToNavier) {
  double D = 0;
  double errors[3];
  const int sizes[3] = {4, 8, 16};
  double reference = 0;
  for (int i = 0; i < 3; ++i) {
    const double w = solve_plate(GetParam().type, sizes[i], false, &D, 0.8);
    reference = navier_centre_deflection(1, 1, -1, D);
    errors[i] = std::abs(w / reference - 1);
    std::printf("simply supported %s %dx%d: w = %.6e, Navier %.6e, rel. error %.3e\n", GetParam().name, sizes[i],
                sizes[i], w, reference, errors[i]);
  }
  const double rate = std::log2(errors[1] / errors[2]);
  std::printf("observed convergence rate (8 -> 16): %.2f\n", rate);
  // Finest-mesh bounds: quad8 0.5%, tri6 2% (tri6 converges from further away, rate ~1.9).
  EXPECT_LT(errors[2], GetParam().type == ElementType::quad8 ? 0.005 : 0.02);
  EXPECT_LT(errors[2], errors[1]);
  EXPECT_GT(rate, 1.5);
}

INSTANTIATE_TEST_SUITE_P(Elements, Plates,
                         ::testing::Values(PlateCase{ElementType::quad8, "quad8"}, PlateCase{ElementType::tri6, "tri6"}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(Cantilever, TipLoadMatchesBeamTheory) {
  // A strip clamped at x = 0 with a uniform line load at x = L; nu = 0 makes plate and
  // beam theory agree exactly (no anticlastic coupling).
  const double L = 1.0, b = 0.1, P = -1e-3;
  Material m;
  m.nu = 0.0;
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_rectangle(L, b, 10, 1, type);
    auto at_root = [](const double* x) { return std::abs(x[0]) < 1e-9; };
    auto model = make_model(mesh, m, 0.8, at_root);
    std::vector<char> fixed;
    fix_nodes(mesh, at_root, true, true, true, fixed);
    std::vector<double> f(model->num_dofs(), 0.0);
    // Consistent nodal loads of a uniform line load on the tip edge (one quadratic edge):
    // 1/6, 4/6, 1/6 of the total.
    for (int n = 0; n < mesh.num_nodes(); ++n) {
      const double* x = mesh.node(n);
      if (std::abs(x[0] - L) > 1e-9) continue;
      const double share = std::abs(x[1] - b / 2) < 1e-9 ? 4.0 / 6 : 1.0 / 6;
      f[3 * n + 2] += share * P;
    }
    ShellSimulation sim(*model, fixed, f);
    // The fixed root line leaves the rotation about it to the clamp, which the check counts
    // from the clamped edges' normals: it assembles nothing; the solve assembles once.
    sim.check_statically_constrained();
    EXPECT_EQ(sim.timings().count("assembly"), 0u);
    sim.solve_static();
    EXPECT_EQ(sim.timings().at("assembly").count, 1);
    const double I = b * m.h * m.h * m.h / 12;
    const double reference = P * L * L * L / (3 * m.E * I);
    double tip = 0;
    int count = 0;
    for (int n = 0; n < mesh.num_nodes(); ++n)
      if (std::abs(mesh.node(n)[0] - L) < 1e-9) tip += sim.displacement()[3 * n + 2], ++count;
    tip /= count;
    std::printf("cantilever %s: tip %.6e, PL^3/3EI %.6e, error %.3f%%\n", type == ElementType::quad8 ? "quad8" : "tri6",
                tip, reference, 100 * std::abs(tip / reference - 1));
    EXPECT_NEAR(tip / reference, 1.0, 0.01);
  }
}

// The rigid modes are sized by the mesh: a plate held on all four sides read as free at
// sizes 1e-9 and 1e10 (the rotations' columns scaled with the length, against a fixed
// threshold); one held side still leaves the rotation about it.
TEST(PlateConstraints, TheRigidModeCheckDoesNotDependOnTheLengthUnit) {
  for (double a : {1e-9, 1.0, 1e10}) {
    const Mesh mesh = make_rectangle(a, a, 4, 4, ElementType::quad8);
    const auto model = make_model(mesh, Material{}, 0.8);
    auto on_side = [a](const double* x) {
      return std::abs(x[0]) < 1e-9 * a || std::abs(x[0] - a) < 1e-9 * a || std::abs(x[1]) < 1e-9 * a ||
             std::abs(x[1] - a) < 1e-9 * a;
    };
    std::vector<char> fixed;
    fix_nodes(mesh, on_side, true, true, true, fixed);
    ShellSimulation held(*model, fixed, std::vector<double>(model->num_dofs(), 0.0));
    EXPECT_NO_THROW(held.check_statically_constrained()) << a;
    std::vector<char> one_side;
    fix_nodes(mesh, [a](const double* x) { return std::abs(x[0]) < 1e-9 * a; }, true, true, true, one_side);
    ShellSimulation hinged(*model, one_side, std::vector<double>(model->num_dofs(), 0.0));
    EXPECT_THROW(hinged.check_statically_constrained(), ModelError) << a;
  }
}

// A clamp holds its edge's normal whatever the shell's thickness. The check weighed the
// stiffness's energy of the free motions against its largest entry: a cantilever 1 mm
// thick (membrane terms ~(h / element size)^-2 times its clamp's bending terms) was refused
// as unconstrained. The tip still follows beam theory down to h = 1e-5 L; without the clamp
// the strip hinges about its root, without the fixed root it translates.
TEST(PlateConstraints, AThinClampedCantileverIsHeld) {
  const double L = 1.0, b = 0.1;
  const Mesh mesh = make_rectangle(L, b, 10, 1, ElementType::quad8);
  auto at_root = [](const double* x) { return std::abs(x[0]) < 1e-9; };
  std::vector<char> root, none;
  fix_nodes(mesh, at_root, true, true, true, root);
  for (double h : {1e-2, 1e-3, 1e-4, 1e-5}) {
    Material m;
    m.nu = 0.0;
    m.h = h;
    const auto clamped = make_model(mesh, m, 0.8, at_root);
    const double P = -1e-3 * m.E * b * h * h * h;  // a tip deflection of 0.004 L
    std::vector<double> f(clamped->num_dofs(), 0.0);
    for (int n = 0; n < mesh.num_nodes(); ++n) {
      const double* x = mesh.node(n);
      if (std::abs(x[0] - L) < 1e-9) f[3 * n + 2] += (std::abs(x[1] - b / 2) < 1e-9 ? 4.0 / 6 : 1.0 / 6) * P;
    }
    ShellSimulation sim(*clamped, root, f);
    ASSERT_NO_THROW(sim.check_statically_constrained()) << "h " << h;
    sim.solve_static();
    double tip = 0;
    int count = 0;
    for (int n = 0; n < mesh.num_nodes(); ++n)
      if (std::abs(mesh.node(n)[0] - L) < 1e-9) tip += sim.displacement()[3 * n + 2], ++count;
    const double reference = P * L * L * L / (3 * m.E * b * h * h * h / 12);
    EXPECT_NEAR(tip / count / reference, 1.0, 0.01) << "h " << h;

    const auto hinged = make_model(mesh, m, 0.8);
    ShellSimulation hinge(*hinged, root, f);
    EXPECT_THROW(hinge.check_statically_constrained(), ModelError) << "h " << h;
    none.assign(clamped->num_dofs(), 0);
    ShellSimulation loose(*clamped, none, f);
    EXPECT_THROW(loose.check_statically_constrained(), ModelError) << "h " << h;
  }
}

}  // namespace

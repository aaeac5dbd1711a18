// Plate sweep of dgtex bench accuracy: a simply supported unit square plate (E 1e6, nu 0.3,
// h 0.01) under uniform load q = -1 on n x n quad8 / tri6 meshes, centre deflection against
// the Navier series, timed as the whole static solve (constraint check, assembly,
// factorisation, solve).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/shell_model.h"
#include "dgtex/shell_simulation.h"
#include "dgtex/topology.h"

namespace dgtex {

double navier_plate_centre_deflection(double a, double b, double q, double D, int terms) {
  const double pi = 3.14159265358979323846;
  double sum = 0;
  for (int m = 1; m <= terms; m += 2)
    for (int n = 1; n <= terms; n += 2) {
      // sin(m pi / 2) sin(n pi / 2) = +-1 for odd m, n.
      const double sign = ((m + n) / 2 - 1) % 2 == 0 ? 1.0 : -1.0;
      const double s = m * m / (a * a) + n * n / (b * b);
      sum += sign / (m * n * s * s);
    }
  return 16 * q / (std::pow(pi, 6) * D) * sum;
}

namespace {

struct PlateSolve {
  double centre_deflection = 0;
  double ms = 0;                          // solve_static, chosen clock
  double assembly_ms = 0, solve_ms = 0;  // its stages (wall clock)
  int dofs = 0;
};

PlateSolve solve_simply_supported_plate(ElementType type, int n, double penalty, AccuracyClock clock) {
  const double a = 1.0, E = 1e6, nu = 0.3, h = 0.01, rho = 1000;
  const Mesh mesh = make_rectangle(a, a, n, n, type);
  const Topology topology = build_topology(mesh);
  ShellModelOptions options;
  options.penalty = penalty;
  const ShellModel model(mesh, topology, std::vector<kernels::ShellSection>(mesh.num_elements(), {E, nu, h, rho}), {},
                         options);
  auto on_boundary = [a](const double* x) {
    return std::abs(x[0]) < 1e-9 || std::abs(x[0] - a) < 1e-9 || std::abs(x[1]) < 1e-9 || std::abs(x[1] - a) < 1e-9;
  };
  std::vector<char> fixed(model.num_dofs(), 0);
  int centre = -1;
  for (int node = 0; node < mesh.num_nodes(); ++node) {
    const double* x = mesh.node(node);
    if (on_boundary(x)) fixed[3 * node] = fixed[3 * node + 1] = fixed[3 * node + 2] = 1;
    if (std::abs(x[0] - a / 2) < 1e-9 && std::abs(x[1] - a / 2) < 1e-9) centre = node;
  }
  if (centre < 0) throw std::logic_error("plate accuracy: no node at the plate centre for n = " + std::to_string(n));
  std::vector<double> f(model.num_dofs(), 0.0);
  const double q[3] = {0, 0, -1.0};
  model.add_area_force(q, f);
  ShellSimulation simulation(model, fixed, f);
  const double start = accuracy_clock_ms(clock);
  simulation.solve_static();
  PlateSolve out;
  out.ms = accuracy_clock_ms(clock) - start;
  out.centre_deflection = simulation.displacement()[3 * centre + 2];
  const StageTimings& timings = simulation.timings();
  if (timings.count("assembly")) out.assembly_ms = timings.at("assembly").total_ms;
  if (timings.count("solve")) out.solve_ms = timings.at("solve").total_ms;
  out.dofs = simulation.system().size();
  return out;
}

}  // namespace

void check_plate_accuracy_options(const PlateAccuracyOptions& options) {
  // Memory grows ~160 KB per element (system, factor; measured: n = 64 0.63 GB, 128 2.6 GB),
  // so n = 256 takes ~10 GB and 512 outgrew a 23 GB machine; larger n failed with a bare
  // std::bad_alloc.
  constexpr int max_divisions = 256;
  for (int n : options.divisions)
    if (n < 2 || n % 2 || n > max_divisions)
      throw std::invalid_argument("plate divisions: n = " + std::to_string(n) + "; need an even n in 2.." +
                                  std::to_string(max_divisions) + " (a node at the plate centre)");
}

AccuracyChart run_plate_accuracy(const PlateAccuracyOptions& options, const AccuracyProgress& progress) {
  check_plate_accuracy_options(options);
  AccuracyChart chart;
  chart.name = "plate";
  chart.title = "simply supported square plate, uniform load";
  chart.time_label = "static solve: check, assembly, factorisation, solve (" + accuracy_clock_name(options.clock) + " ms)";
  chart.error_label = "relative error of the centre deflection vs the Navier series";
  const double D = kernels::bending_rigidity(1e6, 0.3, 0.01);
  const double reference = navier_plate_centre_deflection(1, 1, -1, D);
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const std::string series = kernels::element_type_name(type);
    for (int n : options.divisions) {
      PlateSolve best;
      best.ms = std::numeric_limits<double>::infinity();
      for (int r = 0; r < std::max(1, options.repeat); ++r) {
        const PlateSolve s = solve_simply_supported_plate(type, n, options.penalty, options.clock);
        if (s.ms < best.ms) best = s;
      }
      AccuracyPoint p;
      p.series = series;
      p.label = "n=" + std::to_string(n);
      p.ms = best.ms;
      p.error = std::abs(best.centre_deflection / reference - 1);
      p.extra = {{"n", n}, {"free_dofs", best.dofs}, {"assembly_wall_ms", best.assembly_ms}, {"solve_wall_ms", best.solve_ms}, {"centre_deflection", best.centre_deflection},
                 {"navier", reference}};
      chart.points.push_back(p);
      if (progress) {
        char line[160];
        std::snprintf(line, sizeof line, "plate %s %2dx%-2d: %8.2f ms, error %.3e (%d free DOFs)", series.c_str(), n, n,
                      p.ms, p.error, best.dofs);
        progress(line);
      }
    }
  }
  return chart;
}

}  // namespace dgtex

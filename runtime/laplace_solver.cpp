#include "dgtex/laplace_solver.h"

#include <stdexcept>

#include "dgtex/laplace_direct.h"

namespace dgtex {

LaplaceSolver parse_laplace_solver(const std::string& name) {
  if (name == "multigrid") return LaplaceSolver::multigrid;
  if (name == "cholmod") return LaplaceSolver::cholmod;
  throw std::invalid_argument("unknown Laplace solver '" + name + "'; valid: multigrid, cholmod");
}

std::string laplace_solver_name(LaplaceSolver solver) {
  return solver == LaplaceSolver::multigrid ? "multigrid" : "cholmod";
}

LaplaceSolveStats solve_laplace(kernels::TexelTile& tile, LaplaceSolver solver, const LaplaceMultigridOptions& options) {
  if (solver == LaplaceSolver::cholmod) return solve_laplace_direct(tile);
  return solve_laplace_multigrid(tile, options);
}

}  // namespace dgtex

#include "dgtex/shell_simulation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "dgtex/cut_path.h"
#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/shape_functions.h"
#include "dgtex/model_error.h"
#include "dgtex/side_by_side.h"
#include "api_argument_checks.h"

namespace dgtex {

namespace {

// The constructor's #dofs vectors, checked before the members built from them.
template <class T>
std::vector<T> checked_size(const char* argument, std::vector<T> values, int dofs) {
  detail::check_size("ShellSimulation", argument, values.size(), "model.num_dofs()", dofs);
  if constexpr (std::is_same_v<T, double>) detail::check_finite("ShellSimulation", argument, values.data(), values.size());
  return values;
}

// After the penalty in "not positive definite" errors. OBJ fuzzing (session 68): one quad8
// of a 4 x 4 plate narrowed at one end to 1/5 of its opposite edge failed at penalty 0.8 and
// ran at 2, to 1/25 needed 20, to 1/250 failed at 20; every one passed validate_mesh.
constexpr const char* kDistortionHint =
    ", whose threshold (0.35-0.40 on regular elements) grows with their distortion: an edge much shorter than the "
    "opposite one needs a larger penalty or a better mesh";

// Far above the definiteness threshold a factorisation fails for the opposite reason: the
// penalty terms drown the rest of the stiffness in round-off (a dynamic plate at penalty
// 1e14, fuzzing in session 71, read "penalty too low?").
constexpr double kRoundOffPenalty = 1e6;
std::string penalty_problem(const char* matrix, double penalty) {
  if (penalty > kRoundOffPenalty)
    return std::string(matrix) + " not positive definite (penalty too high? at penalty = " +
           detail::short_number(penalty) +
           " its terms drown the rest of the stiffness in round-off; 0.8-1 is recommended)";
  return std::string(matrix) + " not positive definite (penalty too low?): penalty = " + detail::short_number(penalty) +
         kDistortionHint;
}

}  // namespace

ShellSimulation::ShellSimulation(const ShellModel& model, std::vector<char> fixed, std::vector<double> external_force)
    : model_(model),
      model_revision_(model.revision()),
      fixed_(checked_size("fixed", std::move(fixed), model.num_dofs())),
      f_ext_(checked_size("external_force", std::move(external_force), model.num_dofs())),
      system_(model.pattern(), fixed_, nullptr, &model.dependent_nodes()),
      solver_(model.pattern(), system_, model.mass_blocks()) {
  u_.assign(model.num_dofs(), 0.0);
  v_.assign(model.num_dofs(), 0.0);
  for (int d = 0; d < model.num_dofs(); ++d)
    if (fixed_[d]) f_ext_[d] = 0;
}

const std::vector<double>& ShellSimulation::linear_stiffness() {
  if (linear_k_.empty()) {
    ScopedStage stage(timings_, "assembly");
    model_.assemble_stiffness(nullptr, linear_k_, nullptr);
  }
  return linear_k_;
}

void ShellSimulation::check_model_unchanged(const char* function) const {
  if (model_.revision() != model_revision_)
    throw std::logic_error(std::string(function) +
                           ": the model's basis or material textures changed after this simulation was built "
                           "(set_enrichments, set_material_textures); build a new ShellSimulation (and carry the "
                           "state over, as SceneRun does by projection)");
}

void ShellSimulation::set_state(std::vector<double> u, std::vector<double> v) {
  check_model_unchanged("ShellSimulation::set_state");
  detail::check_size("ShellSimulation::set_state", "u", u.size(), "model.num_dofs()", model_.num_dofs());
  detail::check_size("ShellSimulation::set_state", "v", v.size(), "model.num_dofs()", model_.num_dofs());
  detail::check_finite("ShellSimulation::set_state", "u", u.data(), u.size());
  detail::check_finite("ShellSimulation::set_state", "v", v.data(), v.size());
  u_ = std::move(u);
  v_ = std::move(v);
  system_.distribute(u_);  // the exactly tied DOFs follow their sources (ShellModel::dependent_nodes)
  system_.distribute(v_);
  previous_v_.clear();
  previous_previous_v_.clear();
}

std::string ShellSimulation::enrichment_hint(bool static_analysis) const {
  if (model_.num_enriched_dofs() == 0) return "";
  // Exact dependencies between cuts' functions are removed by the cut manager
  // (enrichment_span.h); what remains are near dependencies: slivers between cuts that
  // almost touch, or a cut passing a node at a fraction of a texel. In statics, a piece cut
  // loose is a mechanism, whose pivot rounding may leave negative (check_no_mechanism).
  return std::string("; with cuts, also check for ") +
         (static_analysis ? "a piece that a cut separates from every support, and for " : "") +
         "cuts that almost touch each other or a node (slivers narrower than a texel)";
}

std::string ShellSimulation::unknown_location(int column) const {
  if (column < 0 || column >= system_.size()) return "";
  const Mesh& mesh = model_.mesh();
  const int dof = system_.dof_of_unknown(column);
  int node = dof / 3;
  std::string what = std::string("the failing column is the ") + "xyz"[dof % 3] + " unknown of node ";
  if (node >= mesh.num_nodes()) {  // an enriched node: its function and mesh node
    what = std::string("the failing column is the ") + "xyz"[dof % 3] + " unknown of enrichment function " +
           std::to_string(model_.virtual_node_function(node)) + " at node ";
    node = model_.virtual_node_mesh_node(node);
  }
  const double* x = mesh.node(node);
  what += std::to_string(node) + " at " + detail::short_point(x) + ", in element";
  std::vector<int> elements;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const int* nodes = mesh.element_nodes(e);
    if (std::find(nodes, nodes + mesh.nodes_per_element(), node) != nodes + mesh.nodes_per_element()) elements.push_back(e);
  }
  what += elements.size() == 1 ? " " : "s ";
  for (std::size_t k = 0; k < elements.size() && k < 8; ++k) what += (k ? ", " : "") + std::to_string(elements[k]);
  if (elements.size() > 8) what += ", ...";
  return "; " + what;
}

void ShellSimulation::check_statically_constrained() {
  check_model_unchanged("ShellSimulation::check_statically_constrained");
  const Mesh& mesh = model_.mesh();
  const int n = mesh.num_nodes();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) centre += Eigen::Map<const Eigen::Vector3d>(mesh.node(i));
  centre /= n;
  // Rigid modes: 3 translations, 3 rotations about the centroid (standard DOFs; the
  // enriched DOFs of a rigid motion are zero). The rotations are divided by the nodes' RMS
  // distance from the centroid, so that all six are of size 1 whatever the length unit:
  // a clamped plate of size 1e-9 or 1e10 read as unconstrained against the fixed threshold.
  double squared_radius = 0;
  for (int i = 0; i < n; ++i) squared_radius += (Eigen::Map<const Eigen::Vector3d>(mesh.node(i)) - centre).squaredNorm();
  const double radius = std::sqrt(squared_radius / n);
  // What holds them: each fixed DOF (the six modes' values there), and each clamped edge, which
  // holds its normal n fixed in space (shell_edge_kernel.cpp) and so every rotation w with
  // w x n != 0: rows (e_c' x n)_c over the rotation modes, scaled like them by the radius.
  // Geometric, so a thin shell's clamp counts whatever its bending stiffness (a test of the
  // stiffness's energy against its largest entry refused a cantilever 1 mm thick, whose
  // membrane terms outweigh the clamp's bending terms by ~(h / element size)^2).
  std::vector<Eigen::Matrix<double, 1, 6>> rows;
  for (int d = 0; d < 3 * n; ++d) {
    if (!fixed_[d]) continue;
    const Eigen::Vector3d x = (Eigen::Map<const Eigen::Vector3d>(mesh.node(d / 3)) - centre) / radius;
    Eigen::Matrix<double, 1, 6> row = Eigen::Matrix<double, 1, 6>::Zero();
    row(d % 3) = 1;
    for (int axis = 0; axis < 3; ++axis) row(3 + axis) = Eigen::Vector3d::Unit(axis).cross(x)(d % 3);
    rows.push_back(row);
  }
  for (int k = 0; k < model_.num_clamped_edges(); ++k) {
    const auto [element, local_edge] = model_.clamped_edge(k);
    double xi[2], dxi[2];
    kernels::local_edge_point(mesh.type, local_edge, 0.0, xi, dxi);
    Vec3 position, normal;
    element_surface_point(mesh, element, xi, position, normal);
    const Eigen::Vector3d unit_normal(normal.data());
    if (!(unit_normal.norm() > 0)) continue;
    for (int c = 0; c < 3; ++c) {
      Eigen::Matrix<double, 1, 6> row = Eigen::Matrix<double, 1, 6>::Zero();
      for (int axis = 0; axis < 3; ++axis) row(3 + axis) = Eigen::Vector3d::Unit(axis).cross(unit_normal)(c);
      rows.push_back(row);
    }
  }
  Eigen::MatrixXd held = Eigen::MatrixXd::Zero(std::max<std::size_t>(rows.size(), 1), 6);
  for (std::size_t r = 0; r < rows.size(); ++r) held.row(r) = rows[r];
  // Rigid motions that nothing holds: the null space of `held`.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(held, Eigen::ComputeFullV);
  const double scale = std::max(1.0, svd.singularValues()(0));
  std::vector<int> free_modes;
  for (int k = 0; k < 6; ++k)
    if (k >= svd.singularValues().size() || svd.singularValues()(k) <= 1e-9 * scale) free_modes.push_back(k);
  if (free_modes.empty()) return;
  const Eigen::VectorXd w = svd.matrixV().col(free_modes[0]);
  int dominant = 0;
  w.cwiseAbs().maxCoeff(&dominant);
  static const char* names[6] = {"translation along x", "translation along y", "translation along z",
                                 "rotation about x",    "rotation about y",    "rotation about z"};
  throw ModelError("boundary: the model is statically unconstrained: " + std::to_string(free_modes.size()) +
                   " rigid-body mode(s) left free (e.g. " + names[dominant] +
                   "); fix more displacement components or clamp an edge");
}

void ShellSimulation::check_no_mechanism(const std::vector<double>& values) const {
  // A mechanism makes K singular, but rounding may leave its pivot positive: a tri6 plate
  // whose cut along element edges left a piece hanging on one held node (free to turn
  // about it) solved to displacements of 1e10 with exit 0 until session 72. Its pivot was
  // 4.9e-16 of its diagonal entry, rounding; the smallest of the test suite's and the
  // example scenes' static solves are 9.4e-8 of theirs (bending of thin plates, ~(h/L)^2).
  constexpr double kMechanismPivotRatio = 1e-12;
  const std::vector<double> pivots = cholesky_.pivots();
  const std::vector<int>& column_start = system_.column_start();
  const std::vector<int>& row_index = system_.row_index();
  double smallest = std::numeric_limits<double>::infinity();
  int column = -1;
  for (int j = 0; j < system_.size(); ++j)
    for (int k = column_start[j]; k < column_start[j + 1]; ++k)
      if (row_index[k] == j && pivots[j] < smallest * values[k]) {
        smallest = pivots[j] / values[k];
        column = j;
      }
  if (!(smallest < kMechanismPivotRatio)) return;
  throw ModelError("boundary: the stiffness is singular to working precision (a pivot " + detail::short_number(smallest) +
                   " times its diagonal entry, below " + detail::short_number(kMechanismPivotRatio) +
                   "): part of the model is free to move, e.g. a piece that a cut separates from every support or "
                   "leaves hanging on one held node, free to turn about it" +
                   unknown_location(column) + "; hold that part, or run it as a dynamic analysis");
}

void ShellSimulation::solve_static() {
  check_model_unchanged("ShellSimulation::solve_static");
  check_statically_constrained();
  const std::vector<double>& K = linear_stiffness();
  std::vector<double> values, rhs, x;
  {
    ScopedStage stage(timings_, "solve");
    system_.gather(K.data(), 1.0, nullptr, 0.0, values);
    if (!cholesky_.analyzed()) cholesky_.analyze(system_.size(), system_.column_start(), system_.row_index());
    try {
      solver_.invalidate();
      cholesky_.factorize(values);
    } catch (const NotPositiveDefinite& e) {
      throw ModelError(penalty_problem("stiffness", model_.options().penalty) + "; " + e.what() +
                       unknown_location(e.column()) + enrichment_hint(true));
    }
    check_no_mechanism(values);
    system_.restrict_vector(f_ext_, rhs);
    cholesky_.solve(rhs, x);
    system_.expand_vector(x, u_);
  }
}

void ShellSimulation::extrapolate_initial_guess() {
  // The velocity extrapolated quadratically from the last three steps (linearly from two, v
  // alone right after set_state). Linear starts PCG ~10x closer than v itself; quadratic
  // saves another 4-9 % of the iterations on the cylinder scene (100 steps: 786 instead of
  // 821; 30 steps: 173 instead of 190).
  const int ndofs = model_.num_dofs();
  guess_ = v_;
  if (previous_previous_v_.size() == v_.size())
    for (int d = 0; d < ndofs; ++d) guess_[d] = 3 * v_[d] - 3 * previous_v_[d] + previous_previous_v_[d];
  else if (previous_v_.size() == v_.size())
    for (int d = 0; d < ndofs; ++d) guess_[d] = 2 * v_[d] - previous_v_[d];
  for (int d = 0; d < ndofs; ++d)
    if (fixed_[d]) guess_[d] = 0;  // as the solver would set them
  k_guess_.resize(ndofs);
}

void ShellSimulation::set_solver_options(const FactorReuseOptions& options) { solver_.set_options(options); }

void ShellSimulation::step(const DynamicsOptions& o) {
  check_model_unchanged("ShellSimulation::step");
  const double dt = o.time_step;
  // At most the scene file's largest magnitude: dt^2 K of 1e300 overflowed, and the failed
  // factorisation read "penalty too low?".
  if (!(dt > 0 && dt <= 1e30))
    throw std::invalid_argument("ShellSimulation::step: time_step " + detail::short_number(dt) +
                                " is not a positive time up to 1e30");
  // Negative damping read as "not positive definite (penalty too low?)" once 1 + dt a <= 0.
  for (const auto& [name, value] : {std::pair{"mass_damping", o.mass_damping}, {"stiffness_damping", o.stiffness_damping}})
    if (!(value >= 0 && std::isfinite(value)))
      throw std::invalid_argument(std::string("ShellSimulation::step: ") + name + " " + detail::short_number(value) +
                                  "; expected a finite number >= 0");
  const int ndofs = model_.num_dofs();
  corrective_.clear();
  const std::vector<double>* K = nullptr;
  double factorization_wait_ms = 0;  // solver time spent beside the assembly, beyond it
  const bool reuse = o.corotational && o.reuse_factorization;
  ku_.resize(ndofs);
  // With factor reuse, K u and K times the PCG's initial guess (the right-hand side and the
  // initial residual), formed in the assembly's pass over K where the model can
  // (ShellModel::fuses_stiffness_products): its rows are still in the cache that summed them
  // and the assembly's threads are awake. The accordion: 76-99 us for the pair as a pass of
  // its own after the assembly (one thread), 7-52 us more assembly fused (README, "Solver
  // strategy of the corotated dynamic step").
  const bool fused_products = reuse && model_.fuses_stiffness_products();
  if (o.corotational) {
    const std::vector<double>& rest = model_.rest_state();  // enriched DOFs rest at 0
    current_.resize(ndofs);
    for (int d = 0; d < ndofs; ++d) current_[d] = rest[d] + u_[d];
    const auto assemble = [&] {
      if (!fused_products) {
        model_.assemble_stiffness(current_.data(), corotated_k_, &corrective_);
        return;
      }
      extrapolate_initial_guess();
      const std::size_t spread_size = 9 * static_cast<std::size_t>(model_.pattern().num_nodes());
      spread_pair_.resize(2 * spread_size);
      kernels::spread_block_vector(model_.pattern().num_nodes(), u_.data(), spread_pair_.data());
      kernels::spread_block_vector(model_.pattern().num_nodes(), guess_.data(), spread_pair_.data() + spread_size);
      model_.assemble_stiffness_and_products(
          current_.data(), corotated_k_, &corrective_,
          {spread_pair_.data(), spread_pair_.data() + spread_size, ku_.data(), k_guess_.data()});
    };
    if (o.reuse_factorization && solver_.factorization_pending() && !solver_.dense_factorization_pending()) {
      // The pending factorisation (serial CHOLMOD) on one thread, the assembly on the others.
      const SideBySideTimes t = run_side_by_side([&] { solver_.factorize_pending(); }, assemble);
      timings_["assembly"].add(t.second_ms);
      factorization_wait_ms = t.total_ms - t.second_ms;
    } else {
      // A pending dense factor (at most 512 unknowns, kernels::dense_cholesky_factor: ~1 ms
      // for the accordion's 450) is factorised first, in turn: beside it the assembly would run on
      // one thread (the accordion's 6 -> 10 ms), a gain only where the factorisation takes
      // longer than the assembly saves on the other threads (run_side_by_side).
      const auto start = std::chrono::steady_clock::now();
      if (o.reuse_factorization) solver_.factorize_pending();
      factorization_wait_ms = ms_since(start);
      ScopedStage stage(timings_, "assembly");
      assemble();
    }
    K = &corotated_k_;
  } else {
    K = &linear_stiffness();
  }
  ScopedStage stage(timings_, "solve", factorization_wait_ms);
  const std::vector<double>& M = model_.mass_blocks();
  const double mass_scale = 1 + dt * o.mass_damping;
  const double stiffness_scale = dt * o.stiffness_damping + dt * dt;
  mv_.resize(ndofs);
  rhs_full_.resize(ndofs);
  solver_.multiply_mass(v_, mv_);  // M's scalar diagonal: 1/9 of the traffic
  if (reuse && !fused_products) {
    // K u and K times the guess share one pass over K.
    extrapolate_initial_guess();
    block_multiply_pair(model_.pattern(), K->data(), u_.data(), guess_.data(), ku_.data(), k_guess_.data());
  } else if (!reuse) {
    block_multiply(model_.pattern(), K->data(), u_.data(), ku_.data());
  }
  for (int d = 0; d < ndofs; ++d) {
    const double correction = corrective_.empty() ? 0.0 : corrective_[d];
    rhs_full_[d] = mv_[d] + dt * (f_ext_[d] + correction - ku_[d]);
  }
  try {
    if (reuse) {
      // A = (1 + dt a) M + (dt b + dt^2) K, never formed (ScaledBlockSum).
      const ScaledBlockSum A{mass_scale, K, stiffness_scale};
      previous_previous_v_.swap(previous_v_);
      previous_v_ = v_;
      solver_.solve(A, rhs_full_, guess_, cholesky_, &k_guess_);
      v_.swap(guess_);
      factorised_dt_ = -1;
    } else {
      if (o.corotational || factorised_dt_ != dt) {
        system_.gather(M.data(), mass_scale, K->data(), stiffness_scale, values_);
        if (!cholesky_.analyzed()) cholesky_.analyze(system_.size(), system_.column_start(), system_.row_index());
        cholesky_.factorize(values_);
        factorised_dt_ = o.corotational ? -1 : dt;
        solver_.invalidate();  // the factor no longer belongs to the solver's sequence
      }
      system_.restrict_vector(rhs_full_, rhs_);
      cholesky_.solve(rhs_, v_new_);
      previous_v_ = v_;
      system_.expand_vector(v_new_, v_);
    }
  } catch (const NotPositiveDefinite& e) {
    // Away from rest (after steps, or from a state carried over a basis change) the deformed
    // state is the likelier cause of a corotated failure (a load 1e5 times gravity on chad
    // failed at its 36th step whatever the penalty): a failed run, not bad input.
    const auto away_from_rest = [](const std::vector<double>& x) {
      return std::any_of(x.begin(), x.end(), [](double value) { return value != 0; });
    };
    if (o.corotational && (away_from_rest(u_) || away_from_rest(v_)))
      throw std::runtime_error("dynamic system matrix not positive definite in the deformed state: the run has "
                               "likely diverged (a smaller time step or smaller loads?), or the penalty = " +
                               detail::short_number(model_.options().penalty) + " is too low for it; " + e.what() +
                               unknown_location(e.column()) + enrichment_hint(false));
    throw ModelError(penalty_problem("dynamic system matrix", model_.options().penalty) + "; " +
                     e.what() + unknown_location(e.column()) + enrichment_hint(false));
  }
  for (int d = 0; d < ndofs; ++d) u_[d] += dt * v_[d];
  time_ += dt;
}

double ShellSimulation::kinetic_energy() const {
  check_model_unchanged("ShellSimulation::kinetic_energy");
  std::vector<double> Mv(model_.num_dofs());
  block_multiply(model_.pattern(), model_.mass_blocks().data(), v_.data(), Mv.data());
  double e = 0;
  for (int d = 0; d < model_.num_dofs(); ++d) e += 0.5 * v_[d] * Mv[d];
  return e;
}

double ShellSimulation::linear_elastic_energy() const {
  check_model_unchanged("ShellSimulation::linear_elastic_energy");
  std::vector<double> K, Ku(model_.num_dofs());
  model_.assemble_stiffness(nullptr, K, nullptr);
  block_multiply(model_.pattern(), K.data(), u_.data(), Ku.data());
  double e = 0;
  for (int d = 0; d < model_.num_dofs(); ++d) e += 0.5 * u_[d] * Ku[d];
  return e;
}

}  // namespace dgtex

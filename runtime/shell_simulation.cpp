#include "dgtex/shell_simulation.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "dgtex/model_error.h"

namespace dgtex {

ShellSimulation::ShellSimulation(const ShellModel& model, std::vector<char> fixed, std::vector<double> external_force)
    : model_(model), fixed_(std::move(fixed)), f_ext_(std::move(external_force)), system_(model.pattern(), fixed_) {
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

void ShellSimulation::set_state(std::vector<double> u, std::vector<double> v) {
  u_ = std::move(u);
  v_ = std::move(v);
}

void ShellSimulation::check_statically_constrained() const {
  const Mesh& mesh = model_.mesh();
  const int n = mesh.num_nodes();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) centre += Eigen::Map<const Eigen::Vector3d>(mesh.node(i));
  centre /= n;
  // Rigid modes: 3 translations, 3 rotations about the centroid.
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(3 * n, 6);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = Eigen::Map<const Eigen::Vector3d>(mesh.node(i)) - centre;
    for (int c = 0; c < 3; ++c) {
      modes(3 * i + c, c) = 1;
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(c);
      modes.block<3, 1>(3 * i, 3 + c) = axis.cross(x);
    }
  }
  int nfixed = 0;
  for (char f : fixed_) nfixed += f != 0;
  Eigen::MatrixXd held(std::max(nfixed, 1), 6);
  held.setZero();
  for (int d = 0, r = 0; d < 3 * n; ++d)
    if (fixed_[d]) held.row(r++) = modes.row(d);
  // Rigid motions that no fixed DOF sees: the null space of `held`.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(held, Eigen::ComputeFullV);
  const double scale = std::max(1.0, svd.singularValues()(0));
  std::vector<int> free_modes;
  for (int k = 0; k < 6; ++k)
    if (k >= svd.singularValues().size() || svd.singularValues()(k) <= 1e-9 * scale) free_modes.push_back(k);
  if (free_modes.empty()) return;
  Eigen::MatrixXd motions(3 * n, free_modes.size());
  for (size_t k = 0; k < free_modes.size(); ++k) motions.col(k) = modes * svd.matrixV().col(free_modes[k]);
  // Clamped edges may still hold them: check the energy the stiffness gives these motions.
  std::vector<double> K;
  model_.assemble_stiffness(nullptr, K, nullptr);
  double kmax = 0;
  for (double value : K) kmax = std::max(kmax, std::abs(value));
  Eigen::MatrixXd KW(3 * n, free_modes.size());
  for (size_t k = 0; k < free_modes.size(); ++k) block_multiply(model_.pattern(), K.data(), motions.col(k).data(), KW.col(k).data());
  const Eigen::MatrixXd energy = motions.transpose() * KW;
  const Eigen::MatrixXd norm = motions.transpose() * motions;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(energy, norm);
  if (eig.eigenvalues()(0) > 1e-8 * kmax) return;
  const Eigen::VectorXd w = svd.matrixV().col(free_modes[0]);
  int dominant = 0;
  w.cwiseAbs().maxCoeff(&dominant);
  static const char* names[6] = {"translation along x", "translation along y", "translation along z",
                                 "rotation about x",    "rotation about y",    "rotation about z"};
  throw ModelError("boundary: the model is statically unconstrained: " + std::to_string(free_modes.size()) +
                   " rigid-body mode(s) left free (e.g. " + names[dominant] +
                   "); fix more displacement components or clamp an edge");
}

void ShellSimulation::solve_static() {
  check_statically_constrained();
  const std::vector<double>& K = linear_stiffness();
  std::vector<double> values, rhs, x;
  {
    ScopedStage stage(timings_, "solve");
    system_.gather(K.data(), 1.0, nullptr, 0.0, values);
    if (!cholesky_.analyzed()) cholesky_.analyze(system_.size(), system_.column_start(), system_.row_index());
    try {
      cholesky_.factorize(values);
    } catch (const NotPositiveDefinite& e) {
      throw ModelError("stiffness not positive definite (penalty too low?): penalty = " +
                       std::to_string(model_.options().penalty) + "; " + e.what());
    }
    system_.restrict_vector(f_ext_, rhs);
    cholesky_.solve(rhs, x);
    system_.expand_vector(x, u_);
  }
}

void ShellSimulation::step(const DynamicsOptions& o) {
  const double dt = o.time_step;
  const int ndofs = model_.num_dofs();
  std::vector<double> corotated_k, corrective;
  const std::vector<double>* K = nullptr;
  {
    if (o.corotational) {
      ScopedStage stage(timings_, "assembly");
      std::vector<double> current(model_.mesh().positions);
      for (int d = 0; d < ndofs; ++d) current[d] += u_[d];
      model_.assemble_stiffness(current.data(), corotated_k, &corrective);
      K = &corotated_k;
    } else {
      K = &linear_stiffness();
    }
  }
  ScopedStage stage(timings_, "solve");
  const std::vector<double>& M = model_.mass_blocks();
  const double mass_scale = 1 + dt * o.mass_damping;
  const double stiffness_scale = dt * o.stiffness_damping + dt * dt;
  if (o.corotational || factorised_dt_ != dt) {
    std::vector<double> values;
    system_.gather(M.data(), mass_scale, K->data(), stiffness_scale, values);
    if (!cholesky_.analyzed()) cholesky_.analyze(system_.size(), system_.column_start(), system_.row_index());
    try {
      cholesky_.factorize(values);
    } catch (const NotPositiveDefinite& e) {
      throw ModelError("dynamic system matrix not positive definite (penalty too low?): penalty = " +
                       std::to_string(model_.options().penalty) + "; " + e.what());
    }
    factorised_dt_ = o.corotational ? -1 : dt;
  }
  std::vector<double> Mv(ndofs), Ku(ndofs), rhs_full(ndofs), rhs, v_new;
  block_multiply(model_.pattern(), M.data(), v_.data(), Mv.data());
  block_multiply(model_.pattern(), K->data(), u_.data(), Ku.data());
  for (int d = 0; d < ndofs; ++d) {
    const double correction = corrective.empty() ? 0.0 : corrective[d];
    rhs_full[d] = Mv[d] + dt * (f_ext_[d] + correction - Ku[d]);
  }
  system_.restrict_vector(rhs_full, rhs);
  cholesky_.solve(rhs, v_new);
  system_.expand_vector(v_new, v_);
  for (int d = 0; d < ndofs; ++d) u_[d] += dt * v_[d];
  time_ += dt;
}

double ShellSimulation::kinetic_energy() const {
  std::vector<double> Mv(model_.num_dofs());
  block_multiply(model_.pattern(), model_.mass_blocks().data(), v_.data(), Mv.data());
  double e = 0;
  for (int d = 0; d < model_.num_dofs(); ++d) e += 0.5 * v_[d] * Mv[d];
  return e;
}

double ShellSimulation::linear_elastic_energy() const {
  std::vector<double> K, Ku(model_.num_dofs());
  model_.assemble_stiffness(nullptr, K, nullptr);
  block_multiply(model_.pattern(), K.data(), u_.data(), Ku.data());
  double e = 0;
  for (int d = 0; d < model_.num_dofs(); ++d) e += 0.5 * u_[d] * Ku[d];
  return e;
}

}  // namespace dgtex

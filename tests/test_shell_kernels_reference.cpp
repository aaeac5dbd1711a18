// The optimised shell stiffness kernels and the Newton polar decomposition against their
// plain serial reference forms (round-off agreement), and their parallel forms against the
// serial ones (bitwise), on a deformed closed cylinder with large rotations.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <random>
#include <vector>

#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/kernels/shell_edge_kernel.h"
#include "dgtex/kernels/shell_element_kernel.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/mesh_validation.h"
#include "dgtex/topology.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using kernels::ElementType;
using kernels::Execution;

namespace {

using testing_support::max_abs;
using testing_support::max_difference;

struct DeformedCylinder {
  Mesh mesh;
  std::vector<kernels::ShellSection> sections;
  std::vector<double> current;
  std::vector<int> edges;  // interior edges, then 4 boundary (clamped) edges
  std::vector<double> edge_size;

  explicit DeformedCylinder(ElementType type) : mesh(make_cylinder(0.5, 1.0, 0, 360, 8, 4, type)) {
    sections.assign(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
    current = mesh.positions;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> noise(-0.02, 0.02);
    for (int n = 0; n < mesh.num_nodes(); ++n) {  // twist about the axis (up to 0.9 rad) plus noise
      const double* x = mesh.node(n);
      const double a = 0.9 * x[1];
      current[3 * n + 0] = std::cos(a) * x[0] - std::sin(a) * x[2] + noise(rng);
      current[3 * n + 1] = x[1] + noise(rng);
      current[3 * n + 2] = std::sin(a) * x[0] + std::cos(a) * x[2] + noise(rng);
    }
    const Topology topology = build_topology(mesh);
    for (const MeshEdge& e : topology.interior_edges) {
      edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, e.minus_element, e.minus_local_edge});
      edge_size.push_back(0.1);
    }
    for (size_t k = 0; k < 4; ++k) {
      const MeshEdge& e = topology.boundary_edges.at(k);
      edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, -1, -1});
      edge_size.push_back(0.1);
    }
  }
  kernels::ElementBatch element_batch() const {
    return {mesh.type, mesh.num_elements(), mesh.elements.data(), mesh.positions.data(), sections.data()};
  }
  kernels::EdgeBatch edge_batch() const {
    return {mesh.type, static_cast<std::int64_t>(edge_size.size()), edges.data(), edge_size.data(), 10.0, 3,
            mesh.elements.data(), mesh.positions.data(), sections.data(), false};
  }
};

class Kernels : public ::testing::TestWithParam<ElementType> {};

TEST_P(Kernels, ElementStiffnessMatchesReference) {
  const DeformedCylinder c(GetParam());
  const kernels::ElementBatch batch = c.element_batch();
  const int npe = c.mesh.nodes_per_element(), nq = kernels::element_quadrature(c.mesh.type).count;
  std::vector<double> F(batch.count * nq * 9), R(F.size());
  kernels::shell_element_deformation_gradients(batch, c.current.data(), F.data());
  kernels::polar_decomposition_batch(batch.count * nq, F.data(), R.data());
  for (const double* rotations : {static_cast<const double*>(nullptr), static_cast<const double*>(R.data())}) {
    std::vector<double> K(batch.count * npe * npe * 9), Kref(K.size()), Kpar(K.size());
    std::vector<double> f(batch.count * npe * 3), fref(f.size()), fpar(f.size());
    double* force = rotations ? f.data() : nullptr;
    kernels::shell_element_stiffness(batch, rotations, K.data(), force, Execution::serial);
    kernels::shell_element_stiffness_reference(batch, rotations, Kref.data(), rotations ? fref.data() : nullptr);
    const test::ThreadCountGuard set_threads(3);
    kernels::shell_element_stiffness(batch, rotations, Kpar.data(), rotations ? fpar.data() : nullptr, Execution::parallel);
    EXPECT_LE(max_difference(K, Kref), 1e-13 * max_abs(Kref)) << (rotations ? "corotated" : "linear");
    EXPECT_EQ(K, Kpar);
    if (rotations) {
      EXPECT_LE(max_difference(f, fref), 1e-12 * max_abs(fref));
      EXPECT_GT(max_abs(fref), 0.0);
      EXPECT_EQ(f, fpar);
    }
  }
}

TEST_P(Kernels, EdgeStiffnessMatchesReference) {
  const DeformedCylinder c(GetParam());
  const kernels::EdgeBatch batch = c.edge_batch();
  const int nb = 2 * c.mesh.nodes_per_element();
  std::vector<double> R(batch.count * 3 * 9);
  kernels::shell_edge_rotations(batch, c.current.data(), R.data());
  for (const double* rotations : {static_cast<const double*>(nullptr), static_cast<const double*>(R.data())}) {
    std::vector<double> K(batch.count * nb * nb * 9), Kref(K.size()), Kpar(K.size());
    std::vector<double> f(batch.count * nb * 3), fref(f.size()), fpar(f.size());
    kernels::shell_edge_stiffness(batch, rotations, K.data(), rotations ? f.data() : nullptr, Execution::serial);
    kernels::shell_edge_stiffness_reference(batch, rotations, Kref.data(), rotations ? fref.data() : nullptr);
    const test::ThreadCountGuard set_threads(3);
    kernels::shell_edge_stiffness(batch, rotations, Kpar.data(), rotations ? fpar.data() : nullptr, Execution::parallel);
    EXPECT_LE(max_difference(K, Kref), 1e-13 * max_abs(Kref)) << (rotations ? "corotated" : "linear");
    EXPECT_EQ(K, Kpar);
    if (rotations) {
      // The corrective force is a difference of nearly equal terms: compare on the scale of
      // its summands (|K| times the rest coordinates, O(1) here).
      EXPECT_LE(max_difference(f, fref), 1e-12 * max_abs(Kref));
      EXPECT_EQ(f, fpar);
    }
  }
}

// The geometry, mass and load kernels and the batched polar decomposition: their parallel
// forms are the serial ones bitwise at 1-4 threads, and the mass and load weights sum to
// rho h times the area and to the area (the partition of unity) on the curved elements.
TEST_P(Kernels, GeometryMassAndLoadKernelsAreTheSerialOnesAtEveryThreadCount) {
  const DeformedCylinder c(GetParam());
  const kernels::ElementBatch elements = c.element_batch();
  const kernels::EdgeBatch edges = c.edge_batch();
  const int npe = c.mesh.nodes_per_element(), nq = kernels::element_quadrature(c.mesh.type).count;
  struct Results {
    std::vector<double> F, R, mass, area_weights, mass_weights, edge_rotations;
  };
  auto run = [&](Execution execution) {
    Results r;
    r.F.resize(elements.count * nq * 9);
    r.R.resize(r.F.size());
    r.mass.resize(elements.count * npe * npe);
    r.area_weights.resize(elements.count * npe);
    r.mass_weights.resize(r.area_weights.size());
    r.edge_rotations.resize(edges.count * 3 * 9);
    kernels::shell_element_deformation_gradients(elements, c.current.data(), r.F.data(), execution);
    kernels::polar_decomposition_batch(elements.count * nq, r.F.data(), r.R.data(), execution);
    kernels::shell_element_mass(elements, r.mass.data(), execution);
    kernels::shell_element_load_weights(elements, r.area_weights.data(), r.mass_weights.data(), execution);
    kernels::shell_edge_rotations(edges, c.current.data(), r.edge_rotations.data(), execution);
    return r;
  };
  const Results serial = run(Execution::serial);
  for (int threads : {1, 2, 3, 4}) {
    const Results parallel = test::with_threads(threads, [&] { return run(Execution::parallel); });
    EXPECT_EQ(parallel.F, serial.F) << threads;
    EXPECT_EQ(parallel.R, serial.R) << threads;
    EXPECT_EQ(parallel.mass, serial.mass) << threads;
    EXPECT_EQ(parallel.area_weights, serial.area_weights) << threads;
    EXPECT_EQ(parallel.mass_weights, serial.mass_weights) << threads;
    EXPECT_EQ(parallel.edge_rotations, serial.edge_rotations) << threads;
  }
  const kernels::ShellSection& section = c.sections[0];
  for (int e = 0; e < elements.count; ++e) {
    const double area = element_area(c.mesh, e);
    double mass = 0, weights = 0, mass_weights = 0;
    for (int k = 0; k < npe * npe; ++k) mass += serial.mass[e * npe * npe + k];
    for (int a = 0; a < npe; ++a) weights += serial.area_weights[e * npe + a], mass_weights += serial.mass_weights[e * npe + a];
    EXPECT_NEAR(weights, area, 1e-14 * area) << e;
    EXPECT_NEAR(mass_weights, section.density * section.thickness * area, 1e-12 * mass_weights) << e;
    EXPECT_NEAR(mass, section.density * section.thickness * area, 1e-12 * mass) << e;
  }
}

INSTANTIATE_TEST_SUITE_P(Elements, Kernels, ::testing::Values(ElementType::quad8, ElementType::tri6),
                         [](const auto& info) { return std::string(info.param == ElementType::quad8 ? "quad8" : "tri6"); });

TEST(PolarDecomposition, NewtonMatchesSvdReferenceAndIsAProperRotation) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  int cases = 0;
  for (double stretch : {1e-4, 1e-2, 0.3, 2.0}) {
    for (int k = 0; k < 200; ++k) {
      // F = Q (I + stretch * random), Q a random rotation (from a normalised quaternion).
      double q[4] = {unit(rng), unit(rng), unit(rng), unit(rng)};
      const double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      for (double& v : q) v /= qn;
      const double w = q[0], x = q[1], y = q[2], z = q[3];
      const double Q[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                           2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                           2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
      double S[9], F[9];
      for (int i = 0; i < 9; ++i) S[i] = (i % 4 == 0 ? 1.0 : 0.0) + stretch * unit(rng);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) F[i * 3 + j] = Q[i * 3 + 0] * S[0 * 3 + j] + Q[i * 3 + 1] * S[1 * 3 + j] + Q[i * 3 + 2] * S[2 * 3 + j];
      double R[9], Rref[9];
      kernels::polar_rotation(F, R);
      kernels::polar_rotation_reference(F, Rref);
      double diff = 0;
      for (int i = 0; i < 9; ++i) diff = std::max(diff, std::abs(R[i] - Rref[i]));
      // Near-singular F (large random stretch) makes the polar factor itself ill-conditioned.
      const double det = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
      if (std::abs(det) > 1e-3) {
        EXPECT_LE(diff, 1e-12) << "stretch " << stretch << " case " << k;
      }
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const double rrT = R[i * 3 + 0] * R[j * 3 + 0] + R[i * 3 + 1] * R[j * 3 + 1] + R[i * 3 + 2] * R[j * 3 + 2];
          EXPECT_NEAR(rrT, i == j ? 1.0 : 0.0, 1e-13);
        }
      const double detR = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) + R[2] * (R[3] * R[7] - R[4] * R[6]);
      EXPECT_NEAR(detR, 1.0, 1e-13);
      ++cases;
    }
  }
  // Inverted F (det < 0) goes through the SVD: still a proper rotation, equal to the reference.
  const double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, -0.5};
  double R[9], Rref[9];
  kernels::polar_rotation(F, R);
  kernels::polar_rotation_reference(F, Rref);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(R[i], Rref[i]);
  EXPECT_EQ(cases, 800);
}

}  // namespace

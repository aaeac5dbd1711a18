// Planar enriched elements (enriched_element_kernel.h): the unrotated stiffness sums
// separate membrane (in-plane) and bending (normal) rows there, and rotation clusters store
// 5 planes of rest sums instead of 9. Checked on one cut quad8 lying flat (with edges
// curved in its plane, so each point's frame differs), turned into a tilted plane, and
// warped out of its plane (which must take the general path): the frame,
// the linear stiffness and the clustered corotated stiffness against the per-point
// references, K of the tilted element against the flat one turned, and the rest layout.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <vector>

#include "dgtex/kernels/enriched_rotation_clusters.h"
#include "cut_element_fixture.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

using testing_support::CutQuad8Element;
using testing_support::max_abs;
using testing_support::max_difference;

// A rotation about the axis (1, 2, 3) by 0.7 rad (row-major).
std::vector<double> tilt() {
  const double axis[3] = {1 / std::sqrt(14.0), 2 / std::sqrt(14.0), 3 / std::sqrt(14.0)};
  const double c = std::cos(0.7), s = std::sin(0.7);
  std::vector<double> Q(9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Q[i * 3 + j] = (i == j ? c : 0) + (1 - c) * axis[i] * axis[j];
  Q[1] -= s * axis[2], Q[2] += s * axis[1], Q[3] += s * axis[2], Q[5] -= s * axis[0], Q[6] -= s * axis[1], Q[7] += s * axis[0];
  return Q;
}

// Moves two midside nodes within the element's plane (z = 0): curved edges, so the rest
// tangent a1, and each point's frame, turn from point to point.
void curve_in_plane(CutQuad8Element& one) {
  one.mesh.positions[3 * one.mesh.element_nodes(0)[4] + 1] += 0.06;
  one.mesh.positions[3 * one.mesh.element_nodes(0)[5] + 0] -= 0.08;
}

void turn_nodes(CutQuad8Element& one, const std::vector<double>& Q) {
  for (int n = 0; n < one.mesh.num_nodes(); ++n) {
    double* x = &one.mesh.positions[3 * n];
    const double p[3] = {x[0], x[1], x[2]};
    for (int i = 0; i < 3; ++i) x[i] = Q[i * 3] * p[0] + Q[i * 3 + 1] * p[1] + Q[i * 3 + 2] * p[2];
  }
}

std::vector<double> linear_stiffness(const CutQuad8Element& one, bool reference) {
  const int W = one.batch.width;
  std::vector<double> K(static_cast<std::size_t>(W) * W * 9), f(3 * W);
  if (reference)
    kernels::enriched_element_stiffness_reference(one.batch, one.quadrature(), nullptr, K.data(), f.data());
  else
    kernels::enriched_element_stiffness(one.batch, one.quadrature(), nullptr, K.data(), f.data());
  return K;
}

// Clustered corotated K and forces (blocks of 16 texels) and their serial reference, for
// the element deformed by a bend about its xi2 axis, the enriched DOFs opened.
struct ClusteredPair {
  std::vector<double> K, f, Kref, fref;
  std::int64_t stride = 0;
};

ClusteredPair clustered(const CutQuad8Element& one) {
  const int W = one.batch.width;
  const int nodes = one.mesh.num_nodes() + static_cast<int>(one.nodes.size());
  std::vector<double> current(3 * static_cast<std::size_t>(nodes), 0.0);
  for (int n = 0; n < nodes; ++n)
    for (int i = 0; i < 3; ++i) {
      if (n < one.mesh.num_nodes()) {
        const double* X = one.mesh.node(n);
        current[3 * n + i] = X[i] + (i == 2 ? 0.3 * X[0] * X[0] : 0.0);
      } else {
        current[3 * n + i] = 0.01 * std::sin(1.3 * n + i);
      }
    }
  const kernels::EnrichedRotationClusters clusters =
      kernels::enriched_rotation_clusters(one.batch, one.quadrature(), 16, 16);
  ClusteredPair out;
  out.stride = kernels::enriched_cluster_rest_stride(one.batch, 0);
  std::vector<double> rest(static_cast<std::size_t>(kernels::enriched_cluster_rest_size(one.batch, clusters)));
  std::vector<double> R(9 * clusters.count());
  kernels::enriched_cluster_rest_stiffness(one.batch, one.quadrature(), clusters, rest.data());
  kernels::enriched_cluster_rotations(one.batch, clusters, rest.data(), current.data(), R.data());
  out.K.resize(static_cast<std::size_t>(W) * W * 9), out.f.resize(3 * W);
  out.Kref.resize(out.K.size()), out.fref.resize(out.f.size());
  kernels::enriched_element_clustered_stiffness(one.batch, clusters, rest.data(), R.data(), out.K.data(), out.f.data());
  kernels::enriched_element_clustered_stiffness_reference(one.batch, one.quadrature(), clusters, current.data(),
                                                          out.Kref.data(), out.fref.data());
  return out;
}

}  // namespace

TEST(PlanarEnrichedElements, FrameOfFlatTiltedAndWarpedElements) {
  CutQuad8Element one(1, 1);
  double E[9];
  ASSERT_TRUE(kernels::enriched_element_planar_frame(one.batch, 0, E));
  EXPECT_NEAR(std::abs(E[8]), 1.0, 1e-15);  // the flat rectangle's normal is +-z
  const std::vector<double> Q = tilt();
  turn_nodes(one, Q);
  ASSERT_TRUE(kernels::enriched_element_planar_frame(one.batch, 0, E));
  for (int f = 0; f < 3; ++f)
    for (int g = 0; g < 3; ++g) {
      const double dot = E[3 * f] * E[3 * g] + E[3 * f + 1] * E[3 * g + 1] + E[3 * f + 2] * E[3 * g + 2];
      EXPECT_NEAR(dot, f == g ? 1.0 : 0.0, 1e-14) << f << ", " << g;  // orthonormal
    }
  const double turned_z[3] = {Q[2], Q[5], Q[8]};
  EXPECT_NEAR(std::abs(E[6] * turned_z[0] + E[7] * turned_z[1] + E[8] * turned_z[2]), 1.0, 1e-14);
  // A midside node 1e-6 of the element's size off the plane: not planar.
  double* x = &one.mesh.positions[3 * one.mesh.element_nodes(0)[5]];
  for (int i = 0; i < 3; ++i) x[i] += 1e-6 * turned_z[i];
  EXPECT_FALSE(kernels::enriched_element_planar_frame(one.batch, 0, E));
}

TEST(PlanarEnrichedElements, LinearStiffnessAgreesWithTheReferenceFlatTiltedAndWarped) {
  // One complete and two partial cuts; the fast form's flat-texture grouping allows 1e-9.
  CutQuad8Element one(1, 2);
  curve_in_plane(one);
  const std::vector<double> flat = linear_stiffness(one, false);
  EXPECT_LE(max_difference(flat, linear_stiffness(one, true)), 1e-9 * max_abs(flat));
  const std::vector<double> Q = tilt();
  turn_nodes(one, Q);
  const std::vector<double> tilted = linear_stiffness(one, false);
  EXPECT_LE(max_difference(tilted, linear_stiffness(one, true)), 1e-9 * max_abs(tilted));
  // Turning the element turns every block: K_tilted(a, c) = Q K_flat(a, c) Q^T.
  std::vector<double> turned(flat.size());
  for (std::size_t b = 0; b < flat.size() / 9; ++b)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double sum = 0;
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) sum += Q[i * 3 + k] * flat[9 * b + k * 3 + l] * Q[j * 3 + l];
        turned[9 * b + i * 3 + j] = sum;
      }
  EXPECT_LE(max_difference(tilted, turned), 1e-12 * max_abs(flat));
  // Bitwise independent of the thread count on the planar path too.
  for (int threads : {1, 2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    EXPECT_EQ(linear_stiffness(one, false), tilted) << threads << " threads";
  }
  // Warped out of its plane (every midside node lifted): the general path, same reference.
  for (int a = 4; a < 8; ++a) one.mesh.positions[3 * one.mesh.element_nodes(0)[a] + 2] += 0.05 * (a % 2 ? 1 : -1);
  double E[9];
  ASSERT_FALSE(kernels::enriched_element_planar_frame(one.batch, 0, E));
  const std::vector<double> warped = linear_stiffness(one, false);
  EXPECT_LE(max_difference(warped, linear_stiffness(one, true)), 1e-9 * max_abs(warped));
}

TEST(PlanarEnrichedElements, ClusterRestSumsTakeFivePlanesWhenPlanar) {
  CutQuad8Element one(1, 2);
  const int W = one.batch.width;
  const std::int64_t packed = kernels::enriched_cluster_packed_blocks(W);
  curve_in_plane(one);
  turn_nodes(one, tilt());
  ASSERT_EQ(kernels::enriched_cluster_rest_planes(one.batch, 0), 5);
  const ClusteredPair tilted = clustered(one);
  EXPECT_EQ(tilted.stride, 5 * packed + 2 * W);
  EXPECT_LE(max_difference(tilted.K, tilted.Kref), 1e-9 * max_abs(tilted.Kref));
  ASSERT_GT(max_abs(tilted.fref), 0.0);
  EXPECT_LE(max_difference(tilted.f, tilted.fref), 1e-9 * max_abs(tilted.fref));
  for (int a = 4; a < 8; ++a) one.mesh.positions[3 * one.mesh.element_nodes(0)[a] + 2] += 0.05 * (a % 2 ? 1 : -1);
  ASSERT_EQ(kernels::enriched_cluster_rest_planes(one.batch, 0), 9);
  const ClusteredPair warped = clustered(one);
  EXPECT_EQ(warped.stride, 9 * packed + 2 * W);
  EXPECT_LE(max_difference(warped.K, warped.Kref), 1e-9 * max_abs(warped.Kref));
  EXPECT_LE(max_difference(warped.f, warped.fref), 1e-9 * max_abs(warped.fref));
}

// A batch may hold planar and curved elements (a cut running from a flat part of a shell
// into a curved one): each element's rest data has its own planes and its own width. The
// second element is a copy of the cut one on nodes of its own, beside it, warped out of its
// plane and enriched by the first two of its three functions only (a narrower basis).
TEST(PlanarEnrichedElements, PlanarAndCurvedElementsShareABatch) {
  CutQuad8Element one(1, 2);
  Mesh& mesh = one.mesh;
  const int first_nodes = mesh.num_nodes();
  for (int a = 0; a < 8; ++a) {
    const double* x = mesh.node(mesh.element_nodes(0)[a]);
    const double lift = a >= 4 ? 0.05 * (a % 2 ? 1 : -1) : 0.0;
    mesh.positions.insert(mesh.positions.end(), {x[0] + 2.0, x[1], x[2] + lift});
    mesh.elements.push_back(first_nodes + a);
  }
  const int functions[2] = {3, 2};
  std::vector<int> element{0, 1}, start{0}, virtual_nodes;
  std::vector<kernels::TextureView> views;
  std::vector<double> shifts;
  int v = mesh.num_nodes();
  for (int e = 0; e < 2; ++e) {
    for (int k = 0; k < functions[e]; ++k) {
      views.push_back(one.views[k]);
      for (int a = 0; a < 8; ++a) virtual_nodes.push_back(v++), shifts.push_back(one.shifts[8 * k + a]);
    }
    start.push_back(static_cast<int>(views.size()));
  }
  const std::vector<kernels::ShellSection> sections(2, one.sections[0]);
  const int W = 8 * (1 + functions[0]);
  const kernels::EnrichedElementBatch batch{ElementType::quad8, 2,     element.data(), mesh.elements.data(),
                                            mesh.positions.data(), sections.data(), CutQuad8Element::T, W,
                                            start.data(),          views.data(),    virtual_nodes.data(),
                                            shifts.data()};
  std::vector<std::int64_t> qp_start;
  std::vector<double> qp;
  kernels::enriched_element_quadrature(batch, kernels::EnrichedQuadratureOptions{}, qp_start, qp);
  const kernels::EnrichedQuadrature quad{qp_start.data(), qp.data()};
  ASSERT_EQ(kernels::enriched_cluster_rest_planes(batch, 0), 5);
  ASSERT_EQ(kernels::enriched_cluster_rest_planes(batch, 1), 9);
  EXPECT_EQ(kernels::enriched_cluster_rest_stride(batch, 1),
            9 * kernels::enriched_cluster_packed_blocks(24) + 2 * 24);

  // Bent about the xi2 axis, the enriched DOFs opened.
  std::vector<double> current(3 * static_cast<std::size_t>(v));
  for (int n = 0; n < v; ++n)
    for (int i = 0; i < 3; ++i)
      current[3 * n + i] = n >= mesh.num_nodes()  ? 0.01 * std::sin(1.3 * n + i)
                           : i == 2               ? mesh.positions[3 * n + 2] + 0.1 * std::pow(mesh.positions[3 * n], 2)
                                                  : mesh.positions[3 * n + i];
  const kernels::EnrichedRotationClusters clusters = kernels::enriched_rotation_clusters(batch, quad, 16, 16);
  auto clustered_stiffness = [&](std::vector<double>& K, std::vector<double>& f) {
    std::vector<double> rest(static_cast<std::size_t>(kernels::enriched_cluster_rest_size(batch, clusters)));
    std::vector<double> R(9 * clusters.count());
    kernels::enriched_cluster_rest_stiffness(batch, quad, clusters, rest.data());
    kernels::enriched_cluster_rotations(batch, clusters, rest.data(), current.data(), R.data());
    K.assign(2 * static_cast<std::size_t>(W) * W * 9, -1.0), f.assign(2 * 3 * W, -1.0);
    kernels::enriched_element_clustered_stiffness(batch, clusters, rest.data(), R.data(), K.data(), f.data());
  };
  std::vector<double> K, f, Kref(2 * static_cast<std::size_t>(W) * W * 9), fref(2 * 3 * W);
  clustered_stiffness(K, f);
  kernels::enriched_element_clustered_stiffness_reference(batch, quad, clusters, current.data(), Kref.data(),
                                                          fref.data());
  EXPECT_LE(max_difference(K, Kref), 1e-9 * max_abs(Kref));
  EXPECT_LE(max_difference(f, fref), 1e-9 * max_abs(fref));
  // The curved element's slots beyond its 24 functions are 0.
  for (int a = 0; a < W; ++a)
    for (int c = 24; c < W; ++c)
      for (int i = 0; i < 9; ++i) {
        ASSERT_EQ(K[((static_cast<std::size_t>(W) + a) * W + c) * 9 + i], 0.0);
        ASSERT_EQ(K[((static_cast<std::size_t>(W) + c) * W + a) * 9 + i], 0.0);
      }
  // The linear stiffness of the two, each in its own form, against the reference too.
  std::vector<double> linear(Kref.size()), linear_ref(Kref.size()), unused_forces(fref.size());
  kernels::enriched_element_stiffness(batch, quad, nullptr, linear.data(), nullptr);
  kernels::enriched_element_stiffness_reference(batch, quad, nullptr, linear_ref.data(), unused_forces.data());
  EXPECT_LE(max_difference(linear, linear_ref), 1e-9 * max_abs(linear_ref));
  for (int threads : {1, 2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    std::vector<double> K_threads, f_threads;
    clustered_stiffness(K_threads, f_threads);
    EXPECT_EQ(K_threads, K) << threads << " threads";
    EXPECT_EQ(f_threads, f) << threads << " threads";
  }
}
